//! Frames to Arrow record batches: the schema of `hwfoc_io::write::arrow` (names, types,
//! nullability, units of docs/RECORD-SCHEMA.md, from the column table), each column's array made at
//! once from a block of frames.

use arrow_array::{RecordBatch, new_null_array};
use arrow_schema::SchemaRef;
use hwfoc::Settings;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::{Data, Frame};
use hwfoc_io::Handler;
use hwfoc_io::InputError;
use hwfoc_io::Selection;
use hwfoc_io::record::{Column, Visitor, columns};
use hwfoc_io::write::arrow::ArrowValue;

/// Data frames as received, column by column: what a batch is made from.
#[derive(Debug, Default)]
pub struct Frames {
    /// Receive time of each frame's first byte; NaN where the input has no times (a receive
    /// time is never NaN).
    pub t: Vec<f64>,
    /// Whether any frame has a time.
    pub timed: bool,
    /// ESC of each frame.
    pub esc: Vec<u8>,
    /// The frames.
    pub frames: Vec<Data>,
}

impl Frames {
    /// Room for `n` frames.
    pub fn with_capacity(n: usize) -> Frames {
        Frames {
            t: Vec::with_capacity(n),
            timed: false,
            esc: Vec::with_capacity(n),
            frames: Vec::with_capacity(n),
        }
    }

    /// Adds a frame.
    #[inline]
    pub fn push(&mut self, t: Option<f64>, esc: u8, frame: &Data) {
        self.timed |= t.is_some();
        self.t.push(t.unwrap_or(f64::NAN));
        self.esc.push(esc);
        self.frames.push(*frame);
    }

    /// Adds HW-FOC frames of ESC `esc` without receive times (a raw input's run).
    #[inline]
    pub fn extend_untimed(&mut self, esc: u8, frames: &[DataFrame]) {
        let n = self.len() + frames.len();
        self.t.resize(n, f64::NAN);
        self.esc.resize(n, esc);
        self.frames.extend(frames.iter().map(|&f| Data::HwFoc(f)));
    }

    /// Empties it, keeping its room (a buffer used again is not faulted in again).
    pub fn clear(&mut self) {
        self.t.clear();
        self.esc.clear();
        self.frames.clear();
        self.timed = false;
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The record batch of these frames under `settings`, with schema `schema` (the record
    /// schema, with or without key-value metadata): each column's array from all the frames,
    /// by code generic over the column, as the library's writers make theirs.
    pub fn to_batch(&self, schema: SchemaRef, settings: &Settings) -> RecordBatch {
        self.slice_to_batch(0..self.len(), schema, settings)
    }

    /// The record batch of frames `rows` (a range within `0..len()`), as [`Frames::to_batch`].
    pub fn slice_to_batch(
        &self,
        rows: std::ops::Range<usize>,
        schema: SchemaRef,
        settings: &Settings,
    ) -> RecordBatch {
        struct Arrays<'a> {
            frames: &'a Frames,
            rows: std::ops::Range<usize>,
            settings: &'a Settings,
            /// Whether every frame of `rows` is HW-FOC (looked at once, not per column).
            hwfoc_only: bool,
            arrays: Vec<arrow_array::ArrayRef>,
        }
        impl Visitor for Arrays<'_> {
            fn column<C: Column>(&mut self) {
                let f = self.frames;
                let s = self.settings;
                let rows = self.rows.clone();
                // Without times `t_s` is all null: an array of nulls is zeroed memory the
                // allocator hands out untouched, not a value written per row.
                if C::NAME == "t_s" && !f.timed {
                    let nulls = new_null_array(&<C::Value as ArrowValue>::data_type(), rows.len());
                    self.arrays.push(nulls);
                    return;
                }
                let (t, esc, frames) = (&f.t[rows.clone()], &f.esc[rows.clone()], &f.frames[rows]);
                let rows = t.iter().zip(esc).zip(frames);
                let array = if self.hwfoc_only {
                    // HW-FOC frames only (a raw file's): each value read by field, without a
                    // match on the protocol per value (as the Parquet export reads them).
                    <C::Value as ArrowValue>::array(rows.map(|((&t, &esc), frame)| {
                        let frame = Data::HwFoc(frame.to_hwfoc().unwrap_or_default());
                        C::from_frame((!t.is_nan()).then_some(t), esc, &frame, s)
                    }))
                } else {
                    <C::Value as ArrowValue>::array(rows.map(|((&t, &esc), frame)| {
                        C::from_frame((!t.is_nan()).then_some(t), esc, frame, s)
                    }))
                };
                self.arrays.push(array);
            }
        }
        let hwfoc_only = self.frames[rows.clone()]
            .iter()
            .all(|f| matches!(f, Data::HwFoc(_)));
        let mut arrays = Arrays {
            frames: self,
            hwfoc_only,
            rows,
            settings,
            arrays: Vec::with_capacity(columns::COUNT),
        };
        columns::visit(&mut arrays);
        // Each array has its field's type and nullability (both come from the column's value
        // type, as in `hwfoc_io::write::arrow`), and all have the same length.
        RecordBatch::try_new(schema, arrays.arrays).expect("the arrays follow the schema")
    }
}

/// Why a run of inputs stopped: an input, or the reader of the batches having gone away.
#[derive(Debug)]
pub enum Stop {
    /// An input could not be read.
    Input(InputError),
    /// Nobody wants the records any more (the iterator was dropped).
    Abandoned,
}

impl From<InputError> for Stop {
    fn from(e: InputError) -> Self {
        Stop::Input(e)
    }
}

/// Room for a block of `rows` frames: a block is handed on at the end of the input batch that
/// fills it, so one batch more (a 64 KiB read holds at most 2731 data frames; a recording's
/// packet or a CSV block, less) fits without the vectors growing (a copy of all of it).
pub fn block_capacity(rows: usize) -> usize {
    rows.min(1 << 20) + (64 << 10)
}

/// A [`Handler`] gathering the selected data frames in blocks of `rows` frames, handing each
/// full block to `full` (at the end of an input batch, as the export does). A block comes from
/// `spare` when one is there (blocks handed back once converted), else it is new.
pub struct Collect<F> {
    selection: Selection,
    /// Data frames selected, and the earliest and latest time of the selected ESCs' frames,
    /// in the window or not (as the export counts them).
    kept: u64,
    span: Option<(f64, f64)>,
    rows: usize,
    frames: Frames,
    full: F,
    spare: Option<std::sync::mpsc::Receiver<Frames>>,
}

impl<F: FnMut(Frames) -> Result<(), Stop>> Collect<F> {
    /// Gathers the frames of `selection` in blocks of about `rows`.
    pub fn new(selection: Selection, rows: usize, full: F) -> Self {
        Collect {
            selection,
            kept: 0,
            span: None,
            rows,
            frames: Frames::with_capacity(block_capacity(rows)),
            full,
            spare: None,
        }
    }

    /// Takes the blocks for the next frames from `spare` when there are some.
    pub fn reuse(mut self, spare: std::sync::mpsc::Receiver<Frames>) -> Self {
        self.spare = Some(spare);
        self
    }

    /// The warning for a time window that selected no frame though the selected ESCs had
    /// some (the command's wording), with `filter` the selection's text and `wall` whether the
    /// times are the wall clock's.
    pub fn empty_window(&self, filter: &str, wall: bool) -> Option<String> {
        match (self.selection.window.is_limited(), self.kept, self.span) {
            (true, 0, Some((first, last))) => {
                Some(hwfoc_io::no_frame_in_window(filter, first, last, wall))
            }
            _ => None,
        }
    }

    /// Hands on the frames gathered so far, if any.
    pub fn flush(&mut self) -> Result<(), Stop> {
        if self.frames.is_empty() {
            return Ok(());
        }
        let reused = self.spare.as_ref().and_then(|s| s.try_recv().ok());
        let next = match reused {
            Some(mut frames) => {
                frames.clear();
                frames
            }
            None => Frames::with_capacity(block_capacity(self.rows)),
        };
        let frames = std::mem::replace(&mut self.frames, next);
        (self.full)(frames)
    }
}

impl<F: FnMut(Frames) -> Result<(), Stop>> Handler for Collect<F> {
    type Error = Stop;

    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &Frame, _: &Settings) {
        if let Frame::Data(frame) = frame {
            if let Some(t) = t.filter(|_| self.selection.esc(esc)) {
                let (first, last) = self.span.get_or_insert((t, t));
                *first = first.min(t);
                *last = last.max(t);
            }
            if self.selection.contains(esc, t) {
                self.frames.push(t, esc, frame);
                self.kept += 1;
            }
        }
    }

    /// A raw input's HW-FOC frames come a run at a time, as the summary takes them: the
    /// decoder's bulk path, without a call per frame (issue 31: `hwfoc.read` took each frame
    /// through [`Handler::frame`], at 23 times the pure-Python decoder's speed).
    const TAKES_RUNS: bool = true;

    #[inline]
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], _: &Settings) {
        // No receive time: no span to widen, and the selection is the same for the whole run.
        if self.selection.contains(esc, None) {
            self.frames.extend_untimed(esc, frames);
            self.kept += frames.len() as u64;
        }
    }

    fn end_batch(&mut self, _live: bool) -> Result<(), Stop> {
        if self.frames.len() >= self.rows {
            self.flush()?;
        }
        Ok(())
    }
}
