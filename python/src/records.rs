//! Frames to Arrow record batches: the schema of `hwfoc_io::write::arrow` (names, types,
//! nullability, units of docs/RECORD-SCHEMA.md, from the column table), each column's array made at
//! once from a block of frames.

use arrow_array::{ArrayRef, RecordBatch, make_array, new_null_array};
use arrow_buffer::{Buffer, NullBuffer};
use arrow_data::ArrayData;
use arrow_schema::{DataType, SchemaRef};
use hwfoc::Settings;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::{AnyFrame, Data};
use hwfoc_io::Handler;
use hwfoc_io::InputError;
use hwfoc_io::Selection;
use hwfoc_io::record::{Column, DataFrames, FrameSlice, Visitor, columns};
use hwfoc_io::write::arrow::ArrowValue;

/// Data frames as received, column by column: what a batch is made from.
///
/// A raw input's frames are HW-FOC frames without receive times: while every frame of the
/// block is, the frames are kept as the codec's (`hwfoc`, a copy of the decoder's runs) and no
/// time is stored, so that each column is converted straight from the fields (issue 31).
#[derive(Debug, Default)]
pub struct Frames {
    /// Receive time of each frame's first byte, NaN where the frame has none (a receive time
    /// is never NaN); empty while no frame has a time.
    t: Vec<f64>,
    /// ESC of each frame.
    esc: Vec<u8>,
    /// The frames (HW-FOC's as the codec's while all are).
    frames: DataFrames,
}

impl Frames {
    /// Room for `n` frames (of HW-FOC without times: other frames' room is made when they come).
    pub fn with_capacity(n: usize) -> Frames {
        Frames {
            esc: Vec::with_capacity(n),
            frames: DataFrames::with_capacity(n),
            ..Frames::default()
        }
    }

    /// Adds a frame.
    #[inline]
    pub fn push(&mut self, t: Option<f64>, esc: u8, frame: &Data) {
        if let Some(t) = t {
            // The frames before had no time.
            self.t.resize(self.len(), f64::NAN);
            self.t.push(t);
        } else if !self.t.is_empty() {
            self.t.push(f64::NAN);
        }
        self.esc.push(esc);
        self.frames.push(frame);
    }

    /// Adds HW-FOC frames of ESC `esc` without receive times (a raw input's run).
    #[inline]
    pub fn extend_untimed(&mut self, esc: u8, frames: &[DataFrame]) {
        let n = self.len() + frames.len();
        if !self.t.is_empty() {
            self.t.resize(n, f64::NAN);
        }
        self.esc.resize(n, esc);
        self.frames.extend_hwfoc(frames);
    }

    /// Empties it, keeping its room (a buffer used again is not faulted in again).
    pub fn clear(&mut self) {
        self.t.clear();
        self.esc.clear();
        self.frames.clear();
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.esc.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.esc.is_empty()
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
        let esc = &self.esc[rows.clone()];
        let times = (!self.t.is_empty()).then(|| &self.t[rows.clone()]);
        let mut arrays = Arrays {
            settings,
            arrays: Vec::with_capacity(columns::COUNT),
        };
        // HW-FOC frames (a raw file's) are converted as such: each value read by field, without
        // a match on the protocol per value (as the Parquet export reads them).
        match self.frames.slice(rows) {
            FrameSlice::HwFoc(frames) => {
                let frames = frames.iter().map(|&f| Data::HwFoc(f));
                match times {
                    None => arrays.visit(Untimed(esc.len()), esc, frames),
                    Some(t) => arrays.visit(Timed(t), esc, frames),
                }
            }
            FrameSlice::Any(frames) => {
                let frames = frames.iter().copied();
                match times {
                    None => arrays.visit(Untimed(esc.len()), esc, frames),
                    Some(t) => arrays.visit(Timed(t), esc, frames),
                }
            }
        }
        // Each array has its field's type and nullability (both come from the column's value
        // type, as in `hwfoc_io::write::arrow`), and all have the same length.
        RecordBatch::try_new(schema, arrays.arrays).expect("the arrays follow the schema")
    }
}

/// The receive times of a block's rows, as an iterator of them.
trait Times: Copy {
    /// The times, `None` where a frame has none.
    fn times(self) -> impl ExactSizeIterator<Item = Option<f64>> + Clone;
}

/// Rows without times (that many).
#[derive(Clone, Copy)]
struct Untimed(usize);

impl Times for Untimed {
    #[inline(always)]
    fn times(self) -> impl ExactSizeIterator<Item = Option<f64>> + Clone {
        // A range mapped, not `repeat_n`: a range has random access, so that each column's
        // zip of times, ESCs and frames is a loop over one index, not three iterators stepped.
        (0..self.0).map(|_| None)
    }
}

/// Rows with the times of a slice (NaN: none).
#[derive(Clone, Copy)]
struct Timed<'a>(&'a [f64]);

impl Times for Timed<'_> {
    #[inline(always)]
    fn times(self) -> impl ExactSizeIterator<Item = Option<f64>> + Clone {
        self.0.iter().map(|&t| (!t.is_nan()).then_some(t))
    }
}

/// An array of `len` nulls of type `data_type` whose values are zeroed memory the allocator hands
/// out untouched (fresh pages, not faulted in unless read): `new_null_array` writes its zeros,
/// since a buffer aligned to 64 bytes is not `calloc`'s (half a table of HW-FOC frames is such
/// columns: the system time of its fresh pages).
fn null_array(data_type: &DataType, len: usize) -> ArrayRef {
    let Some(width) = data_type.primitive_width() else {
        return new_null_array(data_type, len);
    };
    // Words of 8 bytes: aligned for every primitive type, and within `calloc`'s alignment.
    let values = Buffer::from_vec(vec![0u64; (len * width).div_ceil(8)]);
    let data = ArrayData::builder(data_type.clone())
        .len(len)
        .add_buffer(values)
        .nulls(Some(NullBuffer::new_null(len)))
        .build()
        .expect("zeroed values of the type's width, all null");
    make_array(data)
}

/// The arrays of a batch, made a column at a time.
struct Arrays<'a> {
    settings: &'a Settings,
    arrays: Vec<ArrayRef>,
}

impl Arrays<'_> {
    /// Every column's array of rows of times `t`, ESCs `esc` and frames `frames`.
    fn visit<T, F>(&mut self, t: T, esc: &[u8], frames: F)
    where
        T: Times,
        F: ExactSizeIterator<Item = Data> + Clone,
    {
        struct Columns<'a, 'b, T, F> {
            arrays: &'a mut Arrays<'b>,
            t: T,
            esc: &'a [u8],
            frames: F,
        }
        impl<T: Times, F: ExactSizeIterator<Item = Data> + Clone> Visitor for Columns<'_, '_, T, F> {
            fn column<C: Column>(&mut self) {
                let s = self.arrays.settings;
                let values = self
                    .t
                    .times()
                    .zip(self.esc)
                    .zip(self.frames.clone())
                    .map(|((t, &esc), frame)| C::from_frame(t, esc, &frame, s));
                // A column null in every row (`t_s` of a raw file, HW5's quantities in HW-FOC)
                // is made without a value written per row. Where the frames cannot carry the
                // value, this check is no work at all.
                let array = if C::NULLABLE && values.clone().all(|v| v.is_null()) {
                    null_array(&<C::Value as ArrowValue>::data_type(), values.len())
                } else {
                    <C::Value as ArrowValue>::array(values)
                };
                self.arrays.arrays.push(array);
            }
        }
        columns::visit(&mut Columns {
            arrays: self,
            t,
            esc,
            frames,
        });
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
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, _: &Settings) {
        if let AnyFrame::Data(frame) = frame {
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
