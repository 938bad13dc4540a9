//! [`CanDecoder`]: CAN frames a caller already holds (python-can `Message`s, or
//! `(timestamp, arbitration_id, data, is_extended)` tuples) decoded as a CAN bus is: DroneCAN
//! transfers, then a record per ESC status (`hwfoc_io::Stream::can`, the stream every CAN input
//! is read with).

use std::sync::Mutex;

use arrow_pyarrow::ToPyArrow;
use arrow_schema::SchemaRef;
use hwfoc::Settings;
use hwfoc::dronecan::CanFrame;
use hwfoc::telemetry::AnyFrame;
use hwfoc_io::{Batch, Stream};
use hwfoc_ports::clock::byte_times;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors;
use crate::live::{bytes_of, live_schema, stats_dict};
use crate::records::Frames;
use crate::{CURRENT_SCALE, GEAR_RATIO, POLE_PAIRS};

/// The latest time taken, Unix seconds: past it, nanoseconds overflow 64 bits (2554).
const MAX_T_S: f64 = 18_446_744_073.0;

struct CanState {
    stream: Stream,
    bytes: Vec<u8>,
    times: Vec<f64>,
}

/// A streaming decoder of one CAN bus's frames: see `hwfoc.CanDecoder`.
#[pyclass(module = "hwfoc")]
pub struct CanDecoder {
    state: Mutex<CanState>,
    esc: u8,
    settings: Settings,
    schema: SchemaRef,
}

/// A frame's time as a candump log's `(seconds.fraction)` is read (whole seconds plus the
/// fraction of its shortest decimal form), so that the frames of a log read by python-can give
/// the records `hwfoc.read` gives of the log, to the last bit of `t_s`.
fn time_ns(t: f64) -> u64 {
    let text = format!("{t}");
    let (whole, frac) = text.split_once('.').unwrap_or((&text, ""));
    let whole: f64 = whole.parse().unwrap_or(t.trunc());
    let frac = match frac.len() {
        0 => 0.0,
        n => frac
            .parse::<u64>()
            .map_or(t.fract(), |f| f as f64 / 10f64.powi(n as i32)),
    };
    ((whole + frac) * 1e9).round() as u64
}

/// One frame of `item`: a python-can `Message` (its attributes) or a tuple
/// `(timestamp, arbitration_id, data, is_extended)`; its time (Unix seconds) and frame.
fn frame_of(item: &Bound<'_, PyAny>) -> PyResult<(f64, CanFrame)> {
    let (t, id, data, extended): (f64, u32, Bound<'_, PyAny>, bool) = if let Ok(tuple) =
        item.cast::<PyTuple>()
    {
        tuple.extract().map_err(|_| {
            PyValueError::new_err("a frame tuple is (timestamp, arbitration_id, data, is_extended)")
        })?
    } else {
        let attr = |name: &str| item.getattr(name);
        let (remote, error, fd): (bool, bool, bool) = (
            attr("is_remote_frame")
                .and_then(|v| v.extract())
                .unwrap_or(false),
            attr("is_error_frame")
                .and_then(|v| v.extract())
                .unwrap_or(false),
            attr("is_fd").and_then(|v| v.extract()).unwrap_or(false),
        );
        if remote || error || fd {
            return Err(PyValueError::new_err(
                "a remote, error or CAN FD frame is no DroneCAN frame: pass data frames",
            ));
        }
        (
            attr("timestamp")?.extract()?,
            attr("arbitration_id")?.extract()?,
            attr("data")?,
            attr("is_extended_id")?.extract()?,
        )
    };
    if !(t.is_finite() && (0.0..MAX_T_S).contains(&t)) {
        return Err(PyValueError::new_err(format!(
            "timestamp: {t} is not a time in seconds from 1970 to 2554"
        )));
    }
    let data = if data.is_instance_of::<pyo3::types::PyList>() {
        data.extract::<Vec<u8>>()?
    } else {
        bytes_of(&data)?
    };
    let frame = if extended {
        CanFrame::extended(id, &data)
    } else {
        CanFrame::standard(id, &data)
    };
    let frame = frame.ok_or_else(|| {
        PyValueError::new_err(format!(
            "arbitration_id {id:#x} with {} data bytes is no classic CAN frame ({}-bit id, 0 to 8 \
             bytes)",
            data.len(),
            if extended { 29 } else { 11 }
        ))
    })?;
    Ok((t, frame))
}

/// Gathers the data frames a bus's stream hands on, an ESC at slot `s` as ESC `esc + s`.
fn gathering(gather: &mut Frames, esc: u8) -> impl FnMut(Option<f64>, Option<u8>, &AnyFrame) + '_ {
    move |t, slot, d| {
        if let AnyFrame::Data(f) = d {
            gather.push(t, slot.map_or(esc, |s| esc.saturating_add(s)), f);
        }
    }
}

impl CanDecoder {
    /// The records gathered, as a `pyarrow.RecordBatch` of the decoder's schema.
    fn batch(&self, py: Python<'_>, gather: Frames) -> PyResult<Py<PyAny>> {
        Ok(gather
            .to_batch(self.schema.clone(), &self.settings)
            .to_pyarrow(py)?
            .unbind())
    }
}

#[pymethods]
impl CanDecoder {
    #[new]
    #[pyo3(signature = (*, esc=crate::args::Esc(0), current_scale=CURRENT_SCALE, pole_pairs=crate::args::PolePairs(POLE_PAIRS), gear_ratio=GEAR_RATIO, settings=None), text_signature = "(*, esc=0, current_scale=DEFAULT_CURRENT_SCALE, pole_pairs=DEFAULT_POLE_PAIRS, gear_ratio=DEFAULT_GEAR_RATIO, settings=None)")]
    fn new(
        esc: crate::args::Esc,
        current_scale: f32,
        pole_pairs: crate::args::PolePairs,
        gear_ratio: f32,
        settings: Option<crate::FormatSettings<'_>>,
    ) -> PyResult<Self> {
        let settings = crate::settings_arg(current_scale, pole_pairs, gear_ratio, settings)?;
        Ok(CanDecoder {
            state: Mutex::new(CanState {
                stream: Stream::can(),
                bytes: Vec::new(),
                times: Vec::new(),
            }),
            esc: esc.0,
            settings,
            schema: live_schema(settings, Vec::new()),
        })
    }

    /// Decodes `frames`, the next frames of the bus in the order received: an iterable of
    /// python-can `Message`s or `(timestamp, arbitration_id, data, is_extended)` tuples, or
    /// one of them. Returns the records of the ESC statuses completed, as a
    /// `pyarrow.RecordBatch`; an ESC at slot `s` of the bus is ESC `esc + s`.
    fn feed(&self, py: Python<'_>, frames: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let single = frames
            .cast::<PyTuple>()
            .is_ok_and(|t| t.len() == 4 && t.get_item(0).is_ok_and(|x| x.extract::<f64>().is_ok()))
            || frames.hasattr("arbitration_id")?;
        let mut state = self
            .state
            .lock()
            .map_err(|_| errors::HwfocError::new_err("the decoder failed earlier"))?;
        let CanState {
            stream,
            bytes,
            times,
        } = &mut *state;
        bytes.clear();
        times.clear();
        let mut add = |item: &Bound<'_, PyAny>| -> PyResult<()> {
            let (t, frame) = frame_of(item)?;
            let record = frame.to_socketcan_record();
            byte_times(time_ns(t), 0.0, record.len(), times);
            bytes.extend_from_slice(&record);
            Ok(())
        };
        if single {
            add(frames)?;
        } else {
            for (k, item) in frames.try_iter()?.enumerate() {
                if k % 4096 == 4095 {
                    py.check_signals()?;
                }
                add(&item?)?;
            }
        }
        let mut gather = Frames::default();
        let esc = self.esc;
        py.detach(|| {
            let batch = Batch {
                bytes,
                times: Some(times),
                stream: 0,
            };
            stream.feed(batch, gathering(&mut gather, esc));
        });
        drop(state);
        self.batch(py, gather)
    }

    /// Ends the bus's stream: the records still held, as a `pyarrow.RecordBatch`. Live, a
    /// Hobbywing node heard before its GetEscID answer has its records held (up to 1 s of the
    /// bus's clock) until the answer places it; at the end they are given, the node placed by
    /// its node id, as `hwfoc decode -` gives them.
    fn finish(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let mut gather = Frames::default();
        self.state
            .lock()
            .map_err(|_| errors::HwfocError::new_err("the decoder failed earlier"))?
            .stream
            .finish(gathering(&mut gather, self.esc));
        self.batch(py, gather)
    }

    /// The bus's statistics so far (bytes, frames, ...), as `Decoder.stats`.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let stats = self
            .state
            .lock()
            .map_err(|_| errors::HwfocError::new_err("the decoder failed earlier"))?
            .stream
            .stats();
        stats_dict(py, &stats)
    }

    /// The Arrow schema of the batches `feed` returns.
    #[getter]
    fn schema<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.schema.as_ref().to_pyarrow(py)
    }
}
