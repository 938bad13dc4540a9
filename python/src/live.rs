//! Live telemetry: [`Decoder`], a streaming decoder fed bytes as they arrive, and [`Ports`],
//! serial ports read as `hwfoc monitor` reads them (`PortSet`: a reader thread per port that
//! survives unplugging; `PortStreams`: a timed decoding stream per port).

use crate::{CURRENT_SCALE, GEAR_RATIO, POLE_PAIRS};
use std::collections::VecDeque;
use std::sync::Mutex;
use std::time::Duration;

use arrow_array::RecordBatch;
use arrow_pyarrow::ToPyArrow;
use arrow_schema::SchemaRef;
use hwfoc::Settings;
use hwfoc::telemetry::AnyFrame;
use hwfoc_io::Batch;
use hwfoc_io::Handler;
use hwfoc_io::InputError;
use hwfoc_io::Notice;
use hwfoc_io::{Figure, LinkStats};
use hwfoc_io::{PortStreams, Stream};
use hwfoc_ports::clock::byte_times;
use hwfoc_ports::serial::PortSet;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyDict, PyMemoryView};

use crate::errors;
use crate::records::Frames;
use hwfoc_io::write::Provenance;

/// How long a wait for port events lasts before looking for Ctrl-C.
const POLL: Duration = Duration::from_millis(100);

/// The latest receive time `Decoder.feed` takes, s: the last Unix nanosecond a `u64` holds.
const MAX_T_S: f64 = u64::MAX as f64 / 1e9;

/// Why `Decoder.feed` refused its bytes.
enum Refused {
    /// A time given with some feeds and not others.
    MixedTiming,
    /// The first bytes are a candump log.
    CanLog,
}

/// Whether `bytes`, a stream's first, are a candump log: a first line that parses as one.
fn is_candump(bytes: &[u8]) -> bool {
    use hwfoc_ports::can::candump;
    let line = bytes.split(|&b| b == b'\n').next().unwrap_or_default();
    candump::looks_like_line(line)
        && std::str::from_utf8(line).is_ok_and(|line| candump::parse_line(line, 1).is_ok())
}

/// A handler gathering the data frames it is given.
#[derive(Default)]
struct Gather(Frames);

impl Handler for Gather {
    type Error = InputError;

    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, _: &Settings) {
        if let AnyFrame::Data(f) = frame {
            self.0.push(t, esc, f);
        }
    }
}

/// The link statistics as a dict.
pub(crate) fn stats_dict<'py>(py: Python<'py>, s: &LinkStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("bytes", s.bytes())?;
    d.set_item("bytes_skipped", s.bytes_skipped())?;
    d.set_item("frames", s.frames())?;
    d.set_item("info_frames", s.info_frames())?;
    for (name, value) in s.figures() {
        match value {
            Some(Figure::Count(n)) => d.set_item(name, n)?,
            Some(Figure::Ratio(r)) => d.set_item(name, r)?,
            None => d.set_item(name, py.None())?,
        }
    }
    d.set_item("last_packet", s.last_packet())?;
    Ok(d)
}

/// The bytes of a `bytes`, `bytearray` or `memoryview`.
pub(crate) fn bytes_of(data: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    if let Ok(b) = data.cast::<PyBytes>() {
        return Ok(b.as_bytes().to_vec());
    }
    if let Ok(b) = data.cast::<PyByteArray>() {
        return Ok(b.to_vec());
    }
    if data.is_instance_of::<PyMemoryView>() {
        let b = data.call_method0("tobytes")?;
        return Ok(b.cast::<PyBytes>()?.as_bytes().to_vec());
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "feed() takes bytes, bytearray or memoryview, not {}",
        data.get_type().name()?
    )))
}

/// The record schema with `settings` in its metadata.
pub(crate) fn live_schema(settings: Settings, inputs: Vec<String>) -> SchemaRef {
    Provenance::new(settings, inputs, String::new()).schema(None)
}

struct DecoderState {
    stream: Stream,
    times: Vec<f64>,
    /// Whether the bytes fed so far came with times (`None` before the first feed): a stream
    /// is timed throughout or not at all (a frame's time is its first byte's).
    timed: Option<bool>,
    /// Data frames given so far, of every format the stream carried (the stream's own
    /// statistics are of its current format).
    data_frames: u64,
}

/// A streaming decoder of one ESC's bytes: see `hwfoc.Decoder`.
#[pyclass(module = "hwfoc")]
pub struct Decoder {
    state: Mutex<DecoderState>,
    esc: u8,
    settings: Settings,
    per_byte_ns: f64,
    schema: SchemaRef,
}

impl Decoder {
    fn batch(&self, py: Python<'_>, frames: &Frames) -> PyResult<Py<PyAny>> {
        Ok(frames
            .to_batch(self.schema.clone(), &self.settings)
            .to_pyarrow(py)?
            .unbind())
    }

    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, DecoderState>> {
        self.state
            .lock()
            .map_err(|_| errors::HwfocError::new_err("the decoder failed earlier"))
    }
}

#[pymethods]
impl Decoder {
    #[new]
    #[pyo3(signature = (*, esc=crate::args::Esc(0), baud=None, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, protocol=None), text_signature = "(*, esc=0, baud=None, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None, protocol=None)")]
    fn new(
        esc: crate::args::Esc,
        baud: Option<crate::args::Baud>,
        current_scale: f32,
        pole_pairs: crate::args::PolePairs,
        gear_ratio: f32,
        settings: Option<crate::FormatSettings<'_>>,
        protocol: Option<&str>,
    ) -> PyResult<Self> {
        let settings = crate::settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
        let protocol = crate::protocol_arg(protocol)?;
        let baud = crate::baud_arg(baud, protocol);
        Ok(Decoder {
            state: Mutex::new(DecoderState {
                stream: Stream::forced(protocol),
                times: Vec::new(),
                timed: None,
                data_frames: 0,
            }),
            esc: esc.0,
            settings,
            per_byte_ns: hwfoc::wire::byte_ns(baud),
            schema: live_schema(settings, Vec::new()),
        })
    }

    /// Decodes `data`, the next bytes of the stream; `t`: Unix time (s) the first of them was
    /// received, the others following at the baud rate's byte time. Returns the records of
    /// the data frames completed, as a `pyarrow.RecordBatch`.
    /// `t` outside 0 to 18446744073 (1970 to 2554) is a `ValueError`; first bytes that are a
    /// candump log are an `InputError` (decode its frames with `hwfoc.CanDecoder`).
    #[pyo3(signature = (data, t=None))]
    fn feed(&self, py: Python<'_>, data: &Bound<'_, PyAny>, t: Option<f64>) -> PyResult<Py<PyAny>> {
        let bytes = bytes_of(data)?;
        if let Some(t) = t
            && !(t.is_finite() && (0.0..=MAX_T_S).contains(&t))
        {
            return Err(PyValueError::new_err(format!(
                "t: {t} is not a time in seconds since 1970: give 0 to {:.0} (the year \
                 2554, the last nanosecond the clocks hold)",
                MAX_T_S.floor()
            )));
        }
        let esc = self.esc;
        let per_byte_ns = self.per_byte_ns;
        let frames = py.detach(|| {
            let mut state = self.state.lock().ok()?;
            let DecoderState {
                stream,
                times,
                timed,
                data_frames,
            } = &mut *state;
            if *timed.get_or_insert(t.is_some()) != t.is_some() {
                return Some(Err(Refused::MixedTiming));
            }
            if stream.stats().bytes() == 0 && is_candump(&bytes) {
                return Some(Err(Refused::CanLog));
            }
            let mut gather = Gather::default();
            times.clear();
            if let Some(t) = t {
                byte_times((t * 1e9).round() as u64, per_byte_ns, bytes.len(), times);
            }
            let batch = Batch {
                bytes: &bytes,
                times: t.map(|_| times.as_slice()),
                stream: 0,
            };
            // From a DataLink hub, channel `c` is ESC `esc + c`.
            stream.feed(batch, |t, channel, d| {
                if let AnyFrame::Data(f) = d {
                    gather
                        .0
                        .push(t, channel.map_or(esc, |c| esc.saturating_add(c)), f);
                }
            });
            *data_frames += gather.0.len() as u64;
            Some(Ok(gather.0))
        });
        let frames = frames
            .ok_or_else(|| errors::HwfocError::new_err("the decoder failed earlier"))?
            .map_err(|refused| match refused {
                Refused::MixedTiming => PyValueError::new_err(
                    "t: give a receive time with every feed() or with none (a stream is timed \
                     throughout or not at all)",
                ),
                Refused::CanLog => errors::InputError::new_err(
                    "the bytes fed are a candump log (text of CAN frames), not a serial wire's \
                     bytes: feed its frames to hwfoc.CanDecoder, or read the log with hwfoc.read",
                ),
            })?;
        self.batch(py, &frames)
    }

    /// Ends the stream: the records of frames still held (a frame cut off at the end is
    /// dropped), as a `pyarrow.RecordBatch`.
    fn finish(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let mut gather = Gather::default();
        let esc = self.esc;
        let mut state = self.lock()?;
        state.stream.finish(|t, channel, d| {
            if let AnyFrame::Data(f) = d {
                gather
                    .0
                    .push(t, channel.map_or(esc, |c| esc.saturating_add(c)), f);
            }
        });
        state.data_frames += gather.0.len() as u64;
        drop(state);
        self.batch(py, &gather.0)
    }

    /// The link statistics so far (bytes, frames, checksum failures, lost packets,
    /// duplicates, restarts...). `frames` counts the data frames of every format the stream
    /// carried (the rows given); the other figures are of its current format.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let state = self.lock()?;
        let d = stats_dict(py, &state.stream.stats())?;
        d.set_item("frames", state.data_frames)?;
        Ok(d)
    }

    /// The Arrow schema of the batches `feed` returns.
    #[getter]
    fn schema<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.schema.as_ref().to_pyarrow(py)
    }
}

struct PortsState {
    set: PortSet,
    streams: PortStreams,
}

/// Serial ports being read: an iterator of records (dicts): see `hwfoc.open_ports`.
#[pyclass(module = "hwfoc")]
pub struct Ports {
    state: Mutex<Option<PortsState>>,
    /// The records the streams held when the ports were closed (a CAN node's awaiting its
    /// GetEscID answer), set in the same hold of `state` that closes them, so that whoever
    /// finds the ports closed finds these too; handed on as records before the iterator ends.
    held: Mutex<Option<Frames>>,
    pending: Mutex<VecDeque<Py<PyAny>>>,
    names: Vec<String>,
    settings: Settings,
    schema: SchemaRef,
}

/// Opens serial ports: see `hwfoc.open_ports`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (ports, *, baud=None, current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None, protocol=None), text_signature = "(ports, *, baud=None, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None, protocol=None)")]
pub fn open_ports(
    py: Python<'_>,
    ports: Vec<String>,
    baud: Option<crate::args::Baud>,
    current_scale: f32,
    pole_pairs: crate::args::PolePairs,
    gear_ratio: f32,
    settings: Option<crate::FormatSettings<'_>>,
    protocol: Option<&str>,
) -> PyResult<Ports> {
    let settings = crate::settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
    if ports.is_empty() {
        return Err(PyValueError::new_err("no port given"));
    }
    let protocol = crate::protocol_arg(protocol)?;
    if let Some(p) = protocol.filter(|p| p.is_can()) {
        let serial = ports.iter().find(|n| !hwfoc_ports::can::is_can_spec(n));
        if let Some(port) = serial {
            return Err(PyValueError::new_err(format!(
                "protocol: {:?} reads CAN buses (slcan:PORT, can:INTERFACE), not the serial port \
                 {port}",
                p.name()
            )));
        }
    }
    let baud = crate::baud_arg(baud, protocol);
    let set = py
        .detach(|| PortSet::open(&ports, baud))
        .map_err(errors::port)?;
    let mut streams = PortStreams::with_map(baud, ports.clone(), settings.into());
    if let Some(protocol) = protocol {
        streams.force_protocol(protocol);
    }
    Ok(Ports {
        state: Mutex::new(Some(PortsState { set, streams })),
        held: Mutex::new(None),
        pending: Mutex::new(VecDeque::new()),
        schema: live_schema(settings, ports.clone()),
        names: ports,
        settings,
    })
}

impl Ports {
    fn take_pending(&self) -> Option<Py<PyAny>> {
        self.pending.lock().ok()?.pop_front()
    }

    /// Waits for the next port event and handles it: records become pending dicts, a port
    /// lost or back becomes a warning. `Ok(false)` once the ports are closed.
    fn step(&self, py: Python<'_>) -> PyResult<bool> {
        let got = py.detach(|| {
            let mut guard = self.state.lock().ok()?;
            let state = guard.as_mut()?;
            let event = state.set.next_event(POLL);
            let mut gather = Gather::default();
            if let Some(event) = &event {
                state.streams.feed(event, &mut gather);
            }
            Some((event, gather.0, state.streams.take_notices()))
        });
        let Some((event, frames, notices)) = got else {
            return Ok(false);
        };
        self.push_pending(py, &frames)?;
        if let Some(notice) = event
            .as_ref()
            .and_then(|e| Notice::of_port_event(e, &self.names))
        {
            crate::warn_notice(py, notice)?;
        }
        // What the streams found (ESCs past number 255 left out, two CAN ESCs on one channel).
        for notice in notices {
            crate::warn_notice(py, notice)?;
        }
        // Ctrl-C, whether the ports are busy or quiet.
        py.check_signals()?;
        Ok(true)
    }

    /// `frames` as pending records (dicts).
    fn push_pending(&self, py: Python<'_>, frames: &Frames) -> PyResult<()> {
        if frames.is_empty() {
            return Ok(());
        }
        let batch: RecordBatch = frames.to_batch(self.schema.clone(), &self.settings);
        let rows = batch.to_pyarrow(py)?.call_method0("to_pylist")?;
        let mut pending = self
            .pending
            .lock()
            .map_err(|_| errors::HwfocError::new_err("the ports failed earlier"))?;
        for row in rows.try_iter()? {
            pending.push_back(row?.unbind());
        }
        Ok(())
    }

    /// The records held at closing, as pending records: true if there were any.
    fn take_held(&self, py: Python<'_>) -> PyResult<bool> {
        let held = self.held.lock().ok().and_then(|mut h| h.take());
        match held {
            Some(frames) if !frames.is_empty() => self.push_pending(py, &frames).map(|()| true),
            _ => Ok(false),
        }
    }

    /// Closes the ports: the streams end, handing on what they held (kept for the iterator).
    fn shut(&self, py: Python<'_>) {
        // Joining the reader threads takes up to a read timeout: without the lock.
        py.detach(|| {
            let state = self.state.lock().ok().and_then(|mut s| {
                let mut state = s.take()?;
                let mut gather = Gather::default();
                state.streams.finish(&mut gather);
                if let Ok(mut held) = self.held.lock() {
                    *held = Some(gather.0);
                }
                Some(state)
            });
            drop(state);
        });
    }
}

#[pymethods]
impl Ports {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        loop {
            if let Some(record) = self.take_pending() {
                return Ok(Some(record));
            }
            match self.step(py) {
                Ok(true) => {}
                // Closed: the records held at closing, then the end.
                Ok(false) if self.take_held(py)? => {}
                Ok(false) => return Ok(None),
                Err(e) => {
                    // Ctrl-C (or a warning made an error): the ports are closed.
                    if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                        self.shut(py);
                    }
                    return Err(e);
                }
            }
        }
    }

    /// The ports, in the order given (the `esc` of their records).
    #[getter]
    fn ports(&self) -> Vec<String> {
        self.names.clone()
    }

    /// The link statistics of each port so far, in port order.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let all: Vec<LinkStats> = match self.state.lock().ok().as_ref().and_then(|s| s.as_ref()) {
            Some(state) => (0..self.names.len())
                .filter_map(|p| state.streams.stats(p))
                .collect(),
            None => Vec::new(),
        };
        all.iter().map(|s| stats_dict(py, s)).collect()
    }

    /// Stops reading and closes the ports; the iterator then gives the records the streams
    /// held (a CAN node's, awaiting its GetEscID answer) and ends.
    fn close(&self, py: Python<'_>) {
        self.shut(py);
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&self, py: Python<'_>, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.shut(py);
        false
    }
}
