//! `hwfoc.scan`: record batches of inputs of any size in bounded memory. A thread reads and
//! decodes the inputs (incrementally, as the command does: 64 KiB at a time for a raw file)
//! and converts each block of frames into a record batch, handing them over a channel of
//! `QUEUE` batches; the iterator waits for the next with the interpreter's lock released.

use crate::{CURRENT_SCALE, GEAR_RATIO, POLE_PAIRS};
use std::sync::Mutex;
use std::sync::mpsc::{Receiver, RecvTimeoutError, sync_channel};
use std::time::Duration;

use arrow_array::RecordBatch;
use arrow_pyarrow::ToPyArrow;
use pyo3::prelude::*;

use crate::records::{Collect, Stop};
use crate::source::Spec;
use crate::{Notes, Options, errors, open_all, stop_error, warn_notices};

/// Record batches made but not yet taken, at most.
const QUEUE: usize = 2;

/// How often a wait for the next batch looks for Ctrl-C.
const POLL: Duration = Duration::from_millis(100);

/// What the decoding thread hands over.
enum Msg {
    /// Every input opened (and its format detected).
    Opened,
    /// The next record batch.
    Batch(RecordBatch),
    /// An input failed; the batches of what came before it were sent first.
    Failed(Stop),
    /// The inputs are read: the warnings `read` gives too (an ESC whose bytes held no frame).
    Warnings(Vec<String>),
    /// No input held a data frame: `read`'s error, after the warnings.
    Nothing(String),
}

/// An iterator of `pyarrow.RecordBatch`: see `hwfoc.scan`.
#[pyclass(module = "hwfoc")]
pub struct Scan {
    rx: Mutex<Option<Receiver<Msg>>>,
    /// The inputs' notices, issued as warnings before the batch or error that follows them.
    notes: Notes,
}

/// Reads and decodes `specs` on this thread, sending batches of at most `rows` records.
fn produce(
    specs: Vec<Spec>,
    options: Options,
    schema: arrow_schema::SchemaRef,
    rows: usize,
    tx: std::sync::mpsc::SyncSender<Msg>,
    notes: Notes,
) {
    let inputs = match open_all(specs, &notes) {
        Ok(inputs) => inputs,
        Err(e) => {
            let _ = tx.send(Msg::Failed(Stop::Input(e)));
            return;
        }
    };
    if tx.send(Msg::Opened).is_err() {
        return;
    }
    let mut sources = crate::sources(inputs, options.settings, (options.protocol, options.join));
    if options.selection.window.is_limited()
        && let Err(e) = sources.require_timing()
    {
        let _ = tx.send(Msg::Failed(Stop::Input(e)));
        return;
    }
    let settings = options.settings;
    // A block converted is filled again (its memory is not faulted in again).
    let (spare_tx, spare_rx) = std::sync::mpsc::channel();
    let mut collect = Collect::new(options.selection.clone(), rows, |frames| {
        let mut from = 0;
        while from < frames.len() {
            let to = (from + rows).min(frames.len());
            let batch = frames.slice_to_batch(from..to, schema.clone(), &settings);
            tx.send(Msg::Batch(batch)).map_err(|_| Stop::Abandoned)?;
            from = to;
        }
        let _ = spare_tx.send(frames);
        Ok(())
    })
    .reuse(spare_rx);
    // On an input error the frames decoded before it are still handed over, then the error.
    let result = sources.run(&mut collect);
    let flushed = collect.flush();
    let empty_window = crate::empty_window(&collect, &options, &sources);
    drop(collect);
    match result.and(flushed) {
        Err(stop) => {
            let _ = tx.send(Msg::Failed(stop));
        }
        Ok(()) => {
            let mut warnings = crate::no_frames(&sources);
            warnings.extend(empty_window);
            let _ = tx.send(Msg::Warnings(warnings));
            if let Some(nothing) = crate::nothing_decoded(&sources) {
                let _ = tx.send(Msg::Nothing(nothing));
            }
        }
    }
}

/// The records of `sources` (as `read` takes them) as `pyarrow.RecordBatch`es of at most
/// `batch_rows` rows, in bounded memory: read and decoded on a thread of its own, at most two
/// batches ahead. Errors opening the inputs are raised at once, later ones by the iterator after
/// the batches before them.
#[pyfunction]
#[pyo3(signature = (sources, *, batch_rows=crate::args::Rows(65536), esc=None, start=None, end=None, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, protocol=None, join=false), text_signature = "(sources, *, batch_rows=65536, esc=None, start=None, end=None, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None, protocol=None, join=False)")]
#[allow(clippy::too_many_arguments)]
pub fn scan(
    py: Python<'_>,
    sources: &Bound<'_, PyAny>,
    batch_rows: crate::args::Rows,
    esc: Option<&Bound<'_, PyAny>>,
    start: Option<&Bound<'_, PyAny>>,
    end: Option<&Bound<'_, PyAny>>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<crate::FormatSettings<'_>>,
    protocol: Option<&str>,
    join: bool,
) -> PyResult<Scan> {
    let batch_rows = batch_rows.0;
    let settings = crate::settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    let options = Options::new(esc, start, end, settings)?
        .forced(protocol)?
        .joined(join);
    let specs = crate::source::specs(sources)?;
    // The batches' metadata: the ESCs are known only at the end, so `escs` is not in it.
    let schema = options.provenance(&specs).schema(None);
    let (tx, rx) = sync_channel(QUEUE);
    let notes = Notes::default();
    let thread_notes = Notes::clone(&notes);
    std::thread::Builder::new()
        .name("hwfoc scan".to_string())
        .spawn(move || produce(specs, options, schema, batch_rows, tx, thread_notes))
        .map_err(|e| {
            errors::HwfocError::new_err(format!("cannot start the decoding thread: {e}"))
        })?;
    let scan = Scan {
        rx: Mutex::new(Some(rx)),
        notes,
    };
    // Errors opening the inputs are raised here, as `read` raises them.
    let msg = scan.wait(py);
    warn_notices(py, &scan.notes)?;
    match msg? {
        Some(Msg::Opened) | None => Ok(scan),
        Some(Msg::Failed(stop)) => Err(stop_error(stop)),
        Some(Msg::Batch(_) | Msg::Warnings(_) | Msg::Nothing(_)) => {
            Err(errors::HwfocError::new_err(
                "the decoding thread sent records before opening the inputs",
            ))
        }
    }
}

impl Scan {
    /// The next message, waiting with the lock released and answering Ctrl-C; `None` once the
    /// thread has ended.
    fn wait(&self, py: Python<'_>) -> PyResult<Option<Msg>> {
        loop {
            let got = py.detach(|| {
                let guard = self.rx.lock().ok()?;
                let rx = guard.as_ref()?;
                Some(rx.recv_timeout(POLL))
            });
            match got {
                None | Some(Err(RecvTimeoutError::Disconnected)) => {
                    self.drop_channel();
                    return Ok(None);
                }
                Some(Ok(msg)) => return Ok(Some(msg)),
                Some(Err(RecvTimeoutError::Timeout)) => py.check_signals()?,
            }
        }
    }

    /// Drops the channel: the thread stops at its next batch.
    fn drop_channel(&self) {
        if let Ok(mut rx) = self.rx.lock() {
            *rx = None;
        }
    }
}

#[pymethods]
impl Scan {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        loop {
            let msg = self.wait(py);
            warn_notices(py, &self.notes)?;
            match msg {
                Ok(None) => return Ok(None),
                Ok(Some(Msg::Batch(batch))) => return Ok(Some(batch.to_pyarrow(py)?.unbind())),
                Ok(Some(Msg::Opened)) => continue,
                Ok(Some(Msg::Warnings(warnings))) => {
                    for warning in &warnings {
                        errors::warn(py, &py.get_type::<errors::HwfocWarning>(), warning)?;
                    }
                    continue;
                }
                Ok(Some(Msg::Nothing(nothing))) => {
                    self.drop_channel();
                    return Err(errors::InputError::new_err(nothing));
                }
                Ok(Some(Msg::Failed(stop))) => {
                    self.drop_channel();
                    return Err(stop_error(stop));
                }
                Err(e) => {
                    // Ctrl-C: the scan ends with it.
                    self.drop_channel();
                    return Err(e);
                }
            }
        }
    }

    /// Stops the decoding thread; the iterator then ends.
    fn close(&self) {
        self.drop_channel();
    }
}
