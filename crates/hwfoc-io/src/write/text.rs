//! The text writer: JSON Lines or CSV, through the encodings of [`crate::record`].
//!
//! Formatting numbers is most of the work, so two threads format, each a slice of rows at a
//! time, and a third writes their text in order: this thread hands the slices out in turn to
//! the formatters and the writer takes their text in the same turn, so the output is in input
//! order without any sorting. Queues between them hold one slice each, so memory stays bounded
//! (a slice of [`SLICE_ROWS`] rows is about 2 MB of JSON).

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use hwfoc::Settings;
use hwfoc::telemetry::Data;

use crate::settings;
use hwfoc_records::record::{Record, TextEncoder};

use super::{Chunk, EscTable, Provenance, Sink, ToWriter, WriteError};

/// Rows formatted at a time by one formatter.
const SLICE_ROWS: usize = 8192;

/// Text smaller than this is gathered before it is written.
const GATHER: usize = 1 << 16;

/// Number of formatting threads.
const FORMATTERS: usize = 2;

/// What a formatter hands to the writer: the text of a slice, and whether to flush after it.
type Text = (Vec<u8>, bool);

/// Writes the chunks received on `rx` as CSV (`csv`) or JSON Lines, returning each chunk on
/// `spare` for reuse. Returns at the end message, or when the sender goes away, with everything
/// written and flushed; or at the first write error.
pub(super) fn write(
    csv: bool,
    sink: Sink,
    provenance: &Provenance,
    rx: Receiver<ToWriter>,
    spare: SyncSender<Chunk>,
) -> Result<(), WriteError> {
    let header = header(csv, provenance);
    let settings = provenance.settings;
    let iso = csv && provenance.csv_time_iso;
    std::thread::scope(|s| {
        let mut slices = Vec::new();
        let mut texts = Vec::new();
        for _ in 0..FORMATTERS {
            let (slice_tx, slice_rx) = sync_channel::<Chunk>(1);
            let (text_tx, text_rx) = sync_channel::<Text>(1);
            slices.push(slice_tx);
            texts.push(text_rx);
            s.spawn(move || {
                // Rows under the export's settings (the usual case: all of them).
                let mut encoder = TextEncoder::cached();
                // Rows under their ESC's settings, once a slice carries a table of them.
                let mut by_settings: Option<Encoders> = None;
                for slice in slice_rx {
                    let mut text = Vec::with_capacity(slice.len() * if csv { 110 } else { 260 });
                    let rows = slice
                        .t
                        .iter()
                        .zip(&slice.esc)
                        .zip((0..slice.len()).map(|i| slice.frame(i)));
                    match slice.settings.as_deref() {
                        None => {
                            for ((&t, &esc), frame) in rows {
                                let t = (!t.is_nan()).then_some(t);
                                let record = Record::new(t, esc, &frame, &settings);
                                encode(&mut encoder, (csv, iso), &record, &frame, &mut text);
                            }
                        }
                        Some(table) => {
                            let encoders = by_settings.get_or_insert_with(Encoders::default);
                            let slots = encoders.slots(table);
                            for ((&t, &esc), frame) in rows {
                                let t = (!t.is_nan()).then_some(t);
                                let settings = &table[usize::from(esc)];
                                let record = Record::new(t, esc, &frame, settings);
                                let encoder = encoders.get(slots[usize::from(esc)]);
                                encode(encoder, (csv, iso), &record, &frame, &mut text);
                            }
                        }
                    }
                    if text_tx.send((text, slice.flush)).is_err() {
                        // The writer has stopped (a write error): nothing more to do.
                        return;
                    }
                }
            });
        }
        let writer = s.spawn(move || write_in_turn(sink, header, texts));
        // Hand out the rows in slices, to the formatters in turn.
        let mut turn = 0;
        'rows: for msg in rx {
            let mut chunk = match msg {
                ToWriter::Rows(chunk) => chunk,
                ToWriter::End(_) => break,
            };
            let n = chunk.len();
            let mut start = 0;
            while start < n || (n == 0 && chunk.flush) {
                let end = n.min(start + SLICE_ROWS);
                let slice = chunk.slice(start..end, chunk.flush && end == n);
                if slices[turn].send(slice).is_err() {
                    break 'rows;
                }
                turn = (turn + 1) % FORMATTERS;
                if end == n {
                    break;
                }
                start = end;
            }
            chunk.clear();
            // The command may have stopped listening; the chunk is then simply dropped.
            let _ = spare.try_send(chunk);
        }
        // No more slices: the formatters finish theirs and stop, and so does the writer.
        drop(slices);
        writer.join().unwrap_or_else(|_| {
            Err(WriteError::Write {
                output: "the output".to_string(),
                source: std::io::Error::other("the writer thread failed"),
            })
        })
    })
}

/// Appends the text of `record`, the record of `frame`, as CSV (`csv`; with `iso`, its time as
/// an ISO 8601 date) or JSON.
#[inline(always)]
fn encode(
    encoder: &mut TextEncoder,
    (csv, iso): (bool, bool),
    record: &Record,
    frame: &Data,
    out: &mut Vec<u8>,
) {
    if csv {
        let start = out.len();
        encoder.csv_frame(record, frame, out);
        if iso && let Some(t) = record.t_s {
            iso_time(t, start, out);
        }
    } else {
        encoder.json_frame(record, frame, out);
    }
}

/// Replaces the CSV row at `start` of `out`'s first field, its `t_s`, by the ISO 8601 date of
/// `t_s` (`--time iso`): out of the usual rows' way.
#[cold]
fn iso_time(t_s: f64, start: usize, out: &mut Vec<u8>) {
    let end = out[start..]
        .iter()
        .position(|&b| b == b',')
        .map_or(start, |n| start + n);
    out.splice(start..end, crate::time::iso8601_us(t_s).into_bytes());
}

/// The most sets of settings a formatter keeps cached encoders for (about 1 MB each); rows of
/// ESCs under further sets are written by an encoder without caches (the same text, slower).
pub(super) const CACHED_SETTINGS: usize = 8;

/// A formatter's text encoders for rows under their ESC's settings: a cached one per set of
/// settings (a cache holds the text of values converted under one set), made as sets are
/// met, and one without caches.
#[derive(Default)]
struct Encoders {
    list: Vec<(Settings, TextEncoder)>,
    plain: TextEncoder,
}

impl Encoders {
    /// Which encoder writes the rows of each ESC under `table`: an index in `list`, or
    /// `usize::MAX` for the plain encoder. Encoders are made for settings first seen here.
    fn slots(&mut self, table: &EscTable) -> [usize; 256] {
        let mut slots = [usize::MAX; 256];
        for (slot, settings) in slots.iter_mut().zip(table) {
            *slot = match self.list.iter().position(|(s, _)| s == settings) {
                Some(i) => i,
                None if self.list.len() < CACHED_SETTINGS => {
                    self.list.push((*settings, TextEncoder::cached()));
                    self.list.len() - 1
                }
                None => usize::MAX,
            };
        }
        slots
    }

    /// The encoder in `slot` (see [`Encoders::slots`]).
    #[inline]
    fn get(&mut self, slot: usize) -> &mut TextEncoder {
        match self.list.get_mut(slot) {
            Some((_, encoder)) => encoder,
            None => &mut self.plain,
        }
    }
}

/// The CSV header row (after the settings comment when asked for: the default settings, then
/// those set by port or ESC, as `esc.2.pole_pairs=14`), or nothing for JSON Lines.
fn header(csv: bool, provenance: &Provenance) -> Vec<u8> {
    let mut text = Vec::new();
    if !csv {
        return text;
    }
    if provenance.csv_comment {
        let mut comment = String::from("# hwfoc decode:");
        for (name, value) in settings::fields(&provenance.settings) {
            comment.push_str(&format!(" {name}={value}"));
        }
        for (entry, patch) in &provenance.overrides {
            for (name, value) in patch.fields() {
                comment.push_str(&format!(" {entry}.{name}={value}"));
            }
        }
        comment.push_str(&format!(" input={}", provenance.inputs.join(" ")));
        if !provenance.filter.is_empty() {
            comment.push_str(&format!(" filter={}", provenance.filter));
        }
        comment.push('\n');
        text.extend_from_slice(comment.as_bytes());
    }
    let at = text.len();
    Record::write_csv_header(&mut text);
    if provenance.csv_time_iso {
        // The first column holds dates: named `time`, not `t_s` (seconds).
        text.splice(at..at + "t_s".len(), *b"time");
    }
    text
}

/// Writes the header, then the formatters' text, taking from each formatter in turn (the
/// order the slices were handed out in), until the formatter whose turn it is has stopped.
fn write_in_turn(
    mut sink: Sink,
    header: Vec<u8>,
    texts: Vec<Receiver<Text>>,
) -> Result<(), WriteError> {
    let mut pending = header;
    let mut turn = 0;
    while let Ok((text, flush)) = texts[turn].recv() {
        turn = (turn + 1) % texts.len();
        if pending.is_empty() && text.len() >= GATHER {
            sink.writer.write_all(&text).map_err(|e| sink.error(e))?;
        } else {
            // Small pieces (live input, the header) are gathered into bigger writes.
            pending.extend_from_slice(&text);
            if flush || pending.len() >= GATHER {
                sink.writer.write_all(&pending).map_err(|e| sink.error(e))?;
                pending.clear();
            }
        }
        if flush {
            sink.writer.flush().map_err(|e| sink.error(e))?;
        }
    }
    sink.writer.write_all(&pending).map_err(|e| sink.error(e))?;
    sink.writer.flush().map_err(|e| sink.error(e))
}
