//! `hwfoc._hwfoc`, the extension module of the `hwfoc` Python package: the project's library
//! crates (`hwfoc`, `hwfoc-io`) behind a few functions and classes. Records reach Python as
//! Arrow record batches through the Arrow C Data Interface (`arrow-pyarrow`): no Python object
//! per row. Decoding runs with the interpreter's lock released; every error becomes an
//! exception of `hwfoc` (see `errors.rs`) whose message is the one the `hwfoc` command prints.

mod args;
mod can;
mod check;
mod errors;
mod interrupt;
mod live;
mod records;
mod scan;
mod source;

use std::collections::BTreeMap;
use std::sync::mpsc::{self, sync_channel};
use std::sync::{Arc, Mutex};

use arrow_array::RecordBatch;
use arrow_pyarrow::{IntoPyArrow, Table};
use hwfoc::protocol::SettingError;
use hwfoc::{Protocol, Settings};
use hwfoc_io::Notice;
use hwfoc_io::Sources;
use hwfoc_io::summary::{Summary, esc_label, no_frames as no_frames_text};
use hwfoc_io::time::Time;
use hwfoc_io::write::Provenance;
use hwfoc_io::write::arrow::schema;
use hwfoc_io::write::metadata::escs_json;
use hwfoc_io::{Input, InputError};
use hwfoc_io::{Selection, Window, filter_text};
use interrupt::Interruptible;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

use records::{Collect, Frames, Stop};
use source::Spec;

/// The defaults of every function's common settings arguments (`current_scale`, `pole_pairs`,
/// `gear_ratio`), those of the library: Python has them as `hwfoc.DEFAULT_CURRENT_SCALE`,
/// `DEFAULT_POLE_PAIRS` and `DEFAULT_GEAR_RATIO` (and the formats' own settings' defaults as
/// `DEFAULT_SETTINGS`, from their descriptions).
pub(crate) const CURRENT_SCALE: f32 = Settings::DEFAULT.current_scale;
/// See [`CURRENT_SCALE`].
pub(crate) const POLE_PAIRS: u16 = Settings::DEFAULT.pole_pairs;
/// See [`CURRENT_SCALE`].
pub(crate) const GEAR_RATIO: f32 = Settings::DEFAULT.gear_ratio;

/// `settings=`: the formats' own settings, by the keys of their descriptions
/// ([`Protocol::settings`]), each value as the command's `--set KEY=VALUE` takes it (a value
/// that is not a `str` by its `str()`).
pub(crate) type FormatSettings<'py> = BTreeMap<String, Bound<'py, PyAny>>;

/// Rows per record batch of `read`'s table: blocks converted side by side on the workers. A
/// block of frames this size (under 2 MiB: 29 bytes a frame) stays in a core's L2 cache while
/// each column is made from it: with 2^18 rows a call took 20 % more CPU time.
const READ_ROWS: usize = 1 << 16;

/// Blocks of frames waiting for a worker, at most (bounds the frames held before conversion).
const READ_QUEUE: usize = 4;

/// What the caller asked for, checked: settings, the selection, and its text for the metadata.
#[derive(Debug, Clone)]
pub(crate) struct Options {
    pub settings: Settings,
    pub selection: Selection,
    pub filter: String,
    /// The one protocol read, when forced.
    pub protocol: Option<Protocol>,
    /// Whether the recordings given are read as one (`join=True`, the command's `--join`).
    pub join: bool,
}

impl Options {
    pub fn new(
        esc: Option<&Bound<'_, PyAny>>,
        start: Option<&Bound<'_, PyAny>>,
        end: Option<&Bound<'_, PyAny>>,
        settings: Settings,
    ) -> PyResult<Options> {
        let escs = escs_arg(esc)?;
        let from = time_arg("start", start)?;
        let to = time_arg("end", end)?;
        let window = Window::new(from, to).map_err(errors::window)?;
        Ok(Options {
            settings,
            selection: Selection::new(&escs, window),
            filter: filter_text(&escs, from.map(Time::Seconds), to.map(Time::Seconds)),
            protocol: None,
            join: false,
        })
    }

    /// These options, reading the protocol named `protocol` only (`protocol=`: see
    /// [`protocol_arg`]).
    pub fn forced(self, protocol: Option<&str>) -> PyResult<Options> {
        Ok(Options {
            protocol: protocol_arg(protocol)?,
            ..self
        })
    }

    /// The options with the recordings joined as one, or not (`join=`).
    pub fn joined(self, join: bool) -> Options {
        Options { join, ..self }
    }

    fn provenance(&self, specs: &[Spec]) -> Provenance {
        Provenance::new(
            self.settings,
            specs.iter().map(|s| s.name().to_string()).collect(),
            self.filter.clone(),
        )
    }
}

/// The conversion settings of a call, checked: `current_scale`, `pole_pairs` and `gear_ratio`
/// out of range are a `SettingsError` worded as the command's; in `settings` (see
/// [`FormatSettings`]), a key no format's description has is a `SettingsError` listing the
/// keys, and a value the setting does not take a `ValueError` naming the key.
pub(crate) fn settings_arg(
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    formats: Option<FormatSettings<'_>>,
) -> PyResult<Settings> {
    let mut settings =
        Settings::new(current_scale, pole_pairs.0, gear_ratio).map_err(errors::settings)?;
    for (key, value) in formats.unwrap_or_default() {
        let value = value.str()?.to_string();
        Protocol::apply_setting(&mut settings, &key, &value).map_err(|e| match e {
            SettingError::UnknownKey => {
                errors::SettingsError::new_err(format!("settings: {key:?}: {e}"))
            }
            SettingError::Value { key, reason } => {
                PyValueError::new_err(format!("{key}: {value:?}: {reason}"))
            }
        })?;
    }
    Ok(settings)
}

/// `esc=`: an ESC index or a list of them.
fn escs_arg(esc: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<u8>> {
    let Some(esc) = esc.filter(|e| !e.is_none()) else {
        return Ok(Vec::new());
    };
    let escs: Vec<i64> = match esc.extract::<i64>() {
        Ok(one) => vec![one],
        Err(_) => esc.extract::<Vec<i64>>().map_err(|_| {
            PyTypeError::new_err("esc: give an ESC index (0 to 255) or a list of them")
        })?,
    };
    escs.into_iter()
        .map(|e| {
            u8::try_from(e).map_err(|_| {
                PyValueError::new_err(format!("esc: {e} is not an ESC index (0 to 255)"))
            })
        })
        .collect()
}

/// `protocol=`: a protocol's name (`hw-foc`, `datalink`, `hw-can`: [`Protocol::name`], as the
/// command's `--protocol`), or `None` for every protocol; another name is a `ValueError` naming
/// the names.
pub(crate) fn protocol_arg(name: Option<&str>) -> PyResult<Option<Protocol>> {
    let Some(name) = name else {
        return Ok(None);
    };
    Protocol::from_name(name).map(Some).ok_or_else(|| {
        let names: Vec<String> = Protocol::ALL
            .iter()
            .map(|p| format!("{:?}", p.name()))
            .collect();
        PyValueError::new_err(format!(
            "protocol: {name:?} is not a protocol: give one of {} (or None for every one)",
            names.join(", ")
        ))
    })
}

/// `baud=`: the baud rate given, else that of the serial protocol forced, else the default, as
/// the command's `--baud` (0 is refused as [`args::Baud`] is converted).
pub(crate) fn baud_arg(baud: Option<args::Baud>, protocol: Option<Protocol>) -> u32 {
    baud.map(|b| b.0)
        .or(protocol.and_then(Protocol::serial_baud_rate))
        .unwrap_or(hwfoc_ports::serial::DEFAULT_BAUD)
}

/// The inputs read with `settings`, of `protocol` only when one is forced, the recordings
/// read as one with `join` (see [`Sources::join_recordings`]).
pub(crate) fn sources(
    inputs: Vec<Input>,
    settings: Settings,
    (protocol, join): (Option<Protocol>, bool),
) -> Sources {
    let mut sources = Sources::new(inputs, settings);
    if let Some(protocol) = protocol {
        sources.force_protocol(protocol);
    }
    if join {
        sources.join_recordings();
    }
    sources
}

/// `start=`/`end=`: seconds as `t_s` has them (a number), or a `datetime` (its Unix time).
/// A `datetime` whose Unix time Python cannot compute (`datetime.min` in a time zone east of
/// UTC) is a `ValueError` naming the argument.
fn time_arg(name: &str, t: Option<&Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    let Some(t) = t.filter(|t| !t.is_none()) else {
        return Ok(None);
    };
    if let Ok(s) = t.extract::<f64>() {
        return Ok(Some(s));
    }
    if t.hasattr("timestamp")? {
        return t
            .call_method0("timestamp")
            .and_then(|s| s.extract::<f64>())
            .map(Some)
            .map_err(|e| {
                PyValueError::new_err(format!(
                    "{name}: {t} has no Unix time ({e}): give a datetime between the years 1 \
                     and 9999 that Python can convert, or seconds"
                ))
            });
    }
    Err(PyTypeError::new_err(
        "start/end: give seconds (a number, as in t_s) or a datetime",
    ))
}

/// Opens every input, in order (all before any is read, as the command does).
pub(crate) fn open_all(specs: Vec<Spec>, notes: &Notes) -> Result<Vec<Input>, InputError> {
    specs
        .into_iter()
        .map(|spec| {
            let mut input = spec.open()?;
            let notes = Arc::clone(notes);
            input.set_notices(move |n| {
                if let Ok(mut notes) = notes.lock() {
                    notes.push(n);
                }
            });
            Ok(input)
        })
        .collect()
}

/// The notices of the inputs being read (damage and notes in a recording, a port lost), kept
/// for the thread holding the interpreter to issue as warnings: the command prints them on
/// standard error, which a Python caller cannot catch or filter.
pub(crate) type Notes = Arc<Mutex<Vec<Notice>>>;

/// Issues the notices gathered so far as warnings (`PortWarning` for ports, `HwfocWarning`
/// for the rest), with the command's text after `hwfoc: warning: ` (or `note: `).
pub(crate) fn warn_notices(py: Python<'_>, notes: &Notes) -> PyResult<()> {
    let taken = match notes.lock() {
        Ok(mut notes) => std::mem::take(&mut *notes),
        Err(_) => return Ok(()),
    };
    for notice in taken {
        warn_notice(py, notice)?;
    }
    Ok(())
}

/// Issues one notice as a warning: `PortWarning` for a port lost or back, `HwfocWarning` for
/// the rest.
pub(crate) fn warn_notice(py: Python<'_>, notice: Notice) -> PyResult<()> {
    let text = notice.to_string();
    match notice {
        Notice::PortLost { .. } | Notice::PortBack { .. } => {
            errors::warn(py, &py.get_type::<errors::PortWarning>(), &text)
        }
        _ => errors::warn(py, &py.get_type::<errors::HwfocWarning>(), &text),
    }
}

/// What `read` made: the record batches (with the schema without metadata), the ESCs found as
/// JSON, and the command's warnings.
struct Decoded {
    batches: Vec<RecordBatch>,
    escs: String,
    warnings: Vec<String>,
    /// The error when no input held a data frame ([`nothing_decoded`]).
    nothing: Option<String>,
}

/// The warnings `hwfoc decode` prints: a CAN bus's records of protocols other than the one
/// forced, left out ([`hwfoc_io::summary::left_out`]); ESCs whose bytes held no frame (not a
/// hub's or a CAN bus's stream: its ESCs are its channels, and a place on the bus without
/// records is no wire without frames).
pub(crate) fn no_frames(sources: &Sources) -> Vec<String> {
    let left_out = hwfoc_io::summary::left_out(sources)
        .into_iter()
        .map(|n| n.to_string());
    let none = (0..sources.escs().len())
        .filter(|&i| {
            let stats = sources.escs()[i].stream.stats();
            stats.bytes() > 0 && stats.frames() == 0 && !sources.is_hub(i)
        })
        .map(|i| format!("{}: {}", esc_label(sources, i), no_frames_text(sources, i)));
    left_out.chain(none).collect()
}

/// The command's error when no input held a data frame (`hwfoc decode` and `hwfoc summary`
/// exit 1 with it, after their warnings), raised as `InputError`: its text.
pub(crate) fn nothing_decoded(sources: &Sources) -> Option<String> {
    sources.nothing_decoded().map(|e| e.to_string())
}

/// The command's warning for a time window that held no frame, if `collect`'s did not.
pub(crate) fn empty_window<F>(
    collect: &Collect<F>,
    options: &Options,
    sources: &Sources,
) -> Option<String>
where
    F: FnMut(records::Frames) -> Result<(), Stop>,
{
    let wall = sources.clock() == Some(hwfoc_io::time::Clock::Wall);
    collect.empty_window(&options.filter, wall)
}

/// Decodes `specs` whole. Decoding runs on this thread, converting on worker threads.
fn decode_all(specs: Vec<Spec>, options: &Options, notes: &Notes) -> Result<Decoded, Stop> {
    let forced = (options.protocol, options.join);
    let mut sources = sources(open_all(specs, notes)?, options.settings, forced);
    if options.selection.window.is_limited() {
        sources.require_timing()?;
    }
    let schema = Arc::new(schema());
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().clamp(1, 4));
    let (tx, rx) = sync_channel::<(usize, Frames)>(READ_QUEUE);
    let rx = Mutex::new(rx);
    let (done_tx, done_rx) = mpsc::channel::<(usize, RecordBatch)>();
    // Blocks converted go back to the decoding thread, to be filled again.
    let (spare_tx, spare_rx) = mpsc::channel::<Frames>();
    let settings = options.settings;
    let result = std::thread::scope(|s| {
        for _ in 0..workers {
            let done = done_tx.clone();
            let spare = spare_tx.clone();
            let (rx, schema) = (&rx, schema.clone());
            s.spawn(move || {
                loop {
                    let job = match rx.lock() {
                        Ok(rx) => rx.recv(),
                        Err(_) => break,
                    };
                    let Ok((index, frames)) = job else { break };
                    let batch = frames.to_batch(schema.clone(), &settings);
                    if done.send((index, batch)).is_err() {
                        break;
                    }
                    let _ = spare.send(frames);
                }
            });
        }
        let mut next = 0;
        let collect = Collect::new(options.selection.clone(), READ_ROWS, |frames| {
            tx.send((next, frames)).map_err(|_| Stop::Abandoned)?;
            next += 1;
            Ok(())
        })
        .reuse(spare_rx);
        let mut collect = Interruptible::new(collect);
        let result = sources
            .run(&mut collect)
            .and_then(|()| collect.inner.flush());
        let empty = empty_window(&collect.inner, options, &sources);
        drop(collect);
        drop(tx);
        result.map(|()| empty)
    });
    drop(done_tx);
    let empty_window = result?;
    let mut batches: Vec<(usize, RecordBatch)> = done_rx.into_iter().collect();
    batches.sort_unstable_by_key(|(i, _)| *i);
    Ok(Decoded {
        batches: batches.into_iter().map(|(_, b)| b).collect(),
        escs: escs_json(&sources),
        warnings: no_frames(&sources)
            .into_iter()
            .chain(empty_window)
            .collect(),
        nothing: nothing_decoded(&sources),
    })
}

/// The exception of a run that stopped.
pub(crate) fn stop_error(stop: Stop) -> PyErr {
    match stop {
        Stop::Input(e) => errors::input(e),
        Stop::Abandoned => errors::HwfocError::new_err("the decoding stopped unexpectedly"),
    }
}

/// Reads telemetry whole into a `pyarrow.Table` of docs/RECORD-SCHEMA.md's records.
///
/// `source`: a path (raw bytes, logic-analyser CSV or pcapng recording, detected from the
/// content), bytes, a binary file object, or a list of these read one after another. `esc`,
/// `start`, `end` select as the command's `--esc`, `--from`, `--to`; the settings convert
/// currents and RPM; `protocol` (a name, as the command's `--protocol`) reads that protocol
/// only; `join=True` reads the recordings given as one, as the command's `--join` (without it,
/// each file is ESCs of its own unless it is a file of the same `hwfoc record` run as another).
/// The schema metadata is that of `hwfoc decode --format parquet`. Raises InputError (also
/// when no input held a data frame, after the warnings, as the command fails), SelectionError,
/// SettingsError, ValueError for an unknown protocol; warns HwfocWarning for inputs without
/// frames and for damage or notes in a recording.
#[pyfunction]
#[pyo3(signature = (source, *, esc=None, start=None, end=None, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, protocol=None, join=false), text_signature = "(source, *, esc=None, start=None, end=None, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None, protocol=None, join=False)")]
#[allow(clippy::too_many_arguments)]
fn read<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    esc: Option<&Bound<'py, PyAny>>,
    start: Option<&Bound<'py, PyAny>>,
    end: Option<&Bound<'py, PyAny>>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<FormatSettings<'_>>,
    protocol: Option<&str>,
    join: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let settings = settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    let options = Options::new(esc, start, end, settings)?
        .forced(protocol)?
        .joined(join);
    let specs = source::specs(source)?;
    let provenance = options.provenance(&specs);
    let notes = Notes::default();
    let decoded = py.detach(|| decode_all(specs, &options, &notes));
    // What the inputs told comes first, as the command prints it while reading.
    warn_notices(py, &notes)?;
    let decoded = decoded.map_err(stop_error)?;
    for warning in &decoded.warnings {
        errors::warn(py, &py.get_type::<errors::HwfocWarning>(), warning)?;
    }
    if let Some(nothing) = decoded.nothing {
        return Err(errors::InputError::new_err(nothing));
    }
    let schema = provenance.schema(Some(decoded.escs));
    let batches = decoded
        .batches
        .into_iter()
        .map(|b| b.with_schema(schema.clone()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| errors::HwfocError::new_err(e.to_string()))?;
    let table =
        Table::try_new(batches, schema).map_err(|e| errors::HwfocError::new_err(e.to_string()))?;
    table.into_pyarrow(py)
}

/// The summary of `hwfoc summary --json`, as one JSON text.
fn summary_json(
    specs: Vec<Spec>,
    settings: Settings,
    (protocol, join): (Option<Protocol>, bool),
    notes: &Notes,
) -> Result<Result<String, String>, InputError> {
    let mut sources = sources(open_all(specs, notes)?, settings, (protocol, join));
    let mut summary = Interruptible::new(Summary::new());
    sources.run(&mut summary)?;
    if let Some(nothing) = nothing_decoded(&sources) {
        return Ok(Err(nothing));
    }
    Ok(Ok(summary.inner.report(&sources).json().to_string()))
}

/// What `hwfoc summary --json` prints for `source` (as `read` takes it), as Python objects:
/// settings, inputs, and per ESC its link statistics, field ranges, faults and fault episodes;
/// `protocol` and `join` as `read`'s. Raises InputError, ValueError for an unknown protocol.
#[pyfunction]
#[pyo3(signature = (source, *, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, protocol=None, join=false), text_signature = "(source, *, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None, protocol=None, join=False)")]
#[allow(clippy::too_many_arguments)]
fn summary<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<FormatSettings<'_>>,
    protocol: Option<&str>,
    join: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let settings = settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    let protocol = protocol_arg(protocol)?;
    let specs = source::specs(source)?;
    let notes = Notes::default();
    let json = py.detach(|| summary_json(specs, settings, (protocol, join), &notes));
    warn_notices(py, &notes)?;
    let json = json
        .map_err(errors::input)?
        .map_err(errors::InputError::new_err)?;
    py.import("json")?.call_method1("loads", (json,))
}

/// The Arrow schema of the records (names, types, nullability, units in the fields' metadata),
/// with the settings in its metadata.
#[pyfunction]
#[pyo3(signature = (*, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None), text_signature = "(*, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None)")]
fn record_schema<'py>(
    py: Python<'py>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<FormatSettings<'_>>,
) -> PyResult<Bound<'py, PyAny>> {
    let settings = settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    let provenance = Provenance::new(settings, Vec::new(), String::new());
    let schema = provenance.schema(None);
    arrow_pyarrow::ToPyArrow::to_pyarrow(schema.as_ref(), py)
}

/// The extension module.
#[pymodule]
fn _hwfoc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(scan::scan, m)?)?;
    m.add_function(wrap_pyfunction!(summary, m)?)?;
    m.add_function(wrap_pyfunction!(check::check_json, m)?)?;
    m.add_function(wrap_pyfunction!(record_schema, m)?)?;
    m.add_function(wrap_pyfunction!(live::open_ports, m)?)?;
    m.add_class::<scan::Scan>()?;
    m.add_class::<live::Decoder>()?;
    m.add_class::<can::CanDecoder>()?;
    m.add_class::<live::Ports>()?;
    m.add("HwfocError", py.get_type::<errors::HwfocError>())?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("PortError", py.get_type::<errors::PortError>())?;
    m.add("SelectionError", py.get_type::<errors::SelectionError>())?;
    m.add("SettingsError", py.get_type::<errors::SettingsError>())?;
    m.add("HwfocWarning", py.get_type::<errors::HwfocWarning>())?;
    m.add("PortWarning", py.get_type::<errors::PortWarning>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_CURRENT_SCALE", CURRENT_SCALE)?;
    m.add("DEFAULT_POLE_PAIRS", POLE_PAIRS)?;
    m.add("DEFAULT_GEAR_RATIO", GEAR_RATIO)?;
    let defaults = pyo3::types::PyDict::new(py);
    for setting in Protocol::settings() {
        defaults.set_item(setting.key, setting.default)?;
    }
    m.add("DEFAULT_SETTINGS", defaults)?;
    let protocols: Vec<&str> = Protocol::ALL.iter().map(|p| p.name()).collect();
    m.add("PROTOCOLS", pyo3::types::PyTuple::new(py, protocols)?)?;
    Ok(())
}
