//! The module's exceptions: one per error type of the libraries, all under `HwfocError`, each
//! with the message the `hwfoc` command prints after `hwfoc: ` (the error's `Display`), except
//! that where the command names its option (`--from`, `--to`) the message names the keyword
//! argument (`start`, `end`).

use hwfoc_io::EmptyWindow;
use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;

create_exception!(
    hwfoc,
    HwfocError,
    PyException,
    "Base class of the errors hwfoc raises; the message is the one the hwfoc command prints."
);
create_exception!(
    hwfoc,
    InputError,
    HwfocError,
    "An input could not be opened or read (missing file, directory, empty input, bad CSV row, \
     classic pcap, raw bytes where times are needed, too many streams)."
);
create_exception!(
    hwfoc,
    PortError,
    HwfocError,
    "A serial port could not be opened (missing, permission denied, busy, not a port)."
);
create_exception!(
    hwfoc,
    SelectionError,
    HwfocError,
    "A selection that cannot hold any frame: start not before end."
);
create_exception!(
    hwfoc,
    SettingsError,
    HwfocError,
    "A conversion setting out of range (current scale, pole pairs, gear ratio)."
);

/// The Python exception of an input error: a port's is a `PortError`, as the command tells
/// them apart; a `KeyboardInterrupt` (any `BaseException` not an `Exception`) raised inside a
/// file object's `read()` is raised again as itself.
pub fn input(e: hwfoc_io::InputError) -> PyErr {
    if let Some(raised) = raised_in_read(&e) {
        return raised;
    }
    match e {
        hwfoc_io::InputError::Port(e) => port(e),
        hwfoc_io::InputError::NoTiming { input } => InputError::new_err(format!(
            "start/end select frames by time, but {input} is raw bytes without receive times: \
             read a recording or a logic-analyser CSV, or leave out start and end"
        )),
        e => InputError::new_err(e.to_string()),
    }
}

/// The exception a file object's `read()` raised that is not an `Exception`, if `e` carries
/// one (see [`crate::source::Raised`]).
fn raised_in_read(e: &hwfoc_io::InputError) -> Option<PyErr> {
    let mut next: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(err) = next {
        let inner = err
            .downcast_ref::<std::io::Error>()
            .and_then(|io| io.get_ref())
            .and_then(|inner| inner.downcast_ref::<crate::source::Raised>());
        if let Some(crate::source::Raised(raised)) = inner {
            return Some(pyo3::Python::attach(|py| raised.clone_ref(py)));
        }
        next = err.source();
    }
    None
}

/// The Python exception of a port error.
pub fn port(e: hwfoc_ports::serial::PortError) -> PyErr {
    PortError::new_err(e.to_string())
}

/// The Python exception of an empty time window, naming the keyword arguments.
pub fn window(e: EmptyWindow) -> PyErr {
    SelectionError::new_err(e.between("start", "end").to_string())
}

/// The Python exception of a setting out of range, worded as the command words it.
pub fn settings(e: hwfoc::SettingsError) -> PyErr {
    SettingsError::new_err(format!("invalid setting: {e}"))
}

create_exception!(
    hwfoc,
    HwfocWarning,
    pyo3::exceptions::PyUserWarning,
    "What the hwfoc command prints as `hwfoc: warning: ...` (or `note: `): an input whose bytes \
     hold no frame, a damaged or foreign part of a recording skipped, a note written in a \
     recording."
);
create_exception!(
    hwfoc,
    PortWarning,
    HwfocWarning,
    "A serial port was lost (unplugged: it is retried) or is back."
);

/// Issues `message` as a Python warning of `category` (which the caller's filters may make an
/// error).
pub fn warn(
    py: pyo3::Python<'_>,
    category: &pyo3::Bound<'_, pyo3::types::PyType>,
    message: &str,
) -> pyo3::PyResult<()> {
    let text = std::ffi::CString::new(message.replace('\0', " "))?;
    PyErr::warn(py, category.as_any(), &text, 1)
}
