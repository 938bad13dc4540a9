//! What a Python caller may pass as an input: a path (`str` or `os.PathLike`), `bytes` (or
//! `bytearray`, `memoryview`), a binary file object, or a list of these (read one after another,
//! as the command reads the inputs named together). Opened into `hwfoc_io::Input`s off the
//! interpreter's lock.

use std::io::{self, Read};

use hwfoc_io::{Input, InputError, OpenInput};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyList, PyMemoryView, PyString, PyTuple};

/// One input as the caller gave it, ready to be opened on any thread.
pub enum Spec {
    /// A file, by path.
    Path(String),
    /// Bytes in memory.
    Bytes {
        /// How messages name it.
        name: String,
        /// The bytes.
        data: Vec<u8>,
    },
    /// A binary file object: read through its `read` method, a block at a time.
    File {
        /// How messages name it: its `name` attribute, or `<file object>`.
        name: String,
        /// The object.
        obj: Py<PyAny>,
    },
}

impl Spec {
    /// The input's name, as messages and the metadata give it.
    pub fn name(&self) -> &str {
        match self {
            Spec::Path(p) => p,
            Spec::Bytes { name, .. } | Spec::File { name, .. } => name,
        }
    }

    /// Opens the input and detects its format (this reads its first bytes).
    pub fn open(self) -> Result<Input, InputError> {
        match self {
            Spec::Path(path) => Input::open(&path),
            Spec::Bytes { name, data } => Input::from_memory(&name, data),
            Spec::File { name, obj } => Input::from_reader(&name, Box::new(PyReader { obj })),
        }
    }
}

/// The name of bytes given in memory.
pub const BYTES_NAME: &str = "<bytes>";

/// The inputs of `source`: one input, or a list or tuple of them.
pub fn specs(source: &Bound<'_, PyAny>) -> PyResult<Vec<Spec>> {
    if source.is_instance_of::<PyList>() || source.is_instance_of::<PyTuple>() {
        let specs = source
            .try_iter()?
            .map(|item| spec(&item?))
            .collect::<PyResult<Vec<_>>>()?;
        if specs.is_empty() {
            return Err(PyTypeError::new_err("no input given: the list is empty"));
        }
        return Ok(specs);
    }
    Ok(vec![spec(source)?])
}

/// A path, unless it names a serial port: reading one as a file would wait for its bytes
/// forever, without receive times.
fn path_spec(path: String) -> PyResult<Spec> {
    if hwfoc_ports::serial::is_port(&path) {
        return Err(crate::errors::InputError::new_err(format!(
            "{path} is a serial port: read it live with hwfoc.open_ports([\"{path}\"])"
        )));
    }
    Ok(Spec::Path(path))
}

/// One input.
pub fn spec(source: &Bound<'_, PyAny>) -> PyResult<Spec> {
    let py = source.py();
    if let Ok(s) = source.cast::<PyString>() {
        return path_spec(s.to_cow()?.into_owned());
    }
    if let Ok(b) = source.cast::<PyBytes>() {
        return Ok(bytes(b.as_bytes().to_vec()));
    }
    if let Ok(b) = source.cast::<PyByteArray>() {
        return Ok(bytes(b.to_vec()));
    }
    if source.is_instance_of::<PyMemoryView>() {
        let b = source.call_method0("tobytes")?;
        return Ok(bytes(b.cast::<PyBytes>()?.as_bytes().to_vec()));
    }
    if source.hasattr("__fspath__")? {
        let path = py.import("os")?.call_method1("fspath", (source,))?;
        return match path.cast::<PyString>() {
            Ok(s) => path_spec(s.to_cow()?.into_owned()),
            Err(_) => Err(PyTypeError::new_err(
                "a path given as bytes is not supported: give it as str",
            )),
        };
    }
    if source.hasattr("read")? {
        let name = source
            .getattr("name")
            .ok()
            .and_then(|n| n.extract::<String>().ok())
            .unwrap_or_else(|| "<file object>".to_string());
        return Ok(Spec::File {
            name,
            obj: source.clone().unbind(),
        });
    }
    Err(PyTypeError::new_err(format!(
        "cannot read a {}: give a path, bytes, a binary file object, or a list of these",
        source.get_type().name()?
    )))
}

fn bytes(data: Vec<u8>) -> Spec {
    Spec::Bytes {
        name: BYTES_NAME.to_string(),
        data,
    }
}

/// A Python binary file object as a reader: `read(n)`, the interpreter's lock taken for each
/// call only.
struct PyReader {
    obj: Py<PyAny>,
}

impl Read for PyReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        Python::attach(|py| {
            let data = self
                .obj
                .bind(py)
                .call_method1("read", (buf.len(),))
                .map_err(|e| raised(py, e))?;
            if data.is_none() {
                // A non-blocking stream with nothing yet: no bytes now is the end for a file.
                return Ok(0);
            }
            let data = if let Ok(b) = data.cast::<PyBytes>() {
                b.as_bytes().to_vec()
            } else if let Ok(b) = data.cast::<PyByteArray>() {
                b.to_vec()
            } else {
                return Err(io::Error::other(
                    "its read() returned text, not bytes: open it in binary mode ('rb')",
                ));
            };
            if data.len() > buf.len() {
                return Err(io::Error::other("its read(n) returned more than n bytes"));
            }
            buf[..data.len()].copy_from_slice(&data);
            Ok(data.len())
        })
    }
}

/// A `BaseException` that is not an `Exception` (`KeyboardInterrupt`, `SystemExit`) raised
/// inside a file object's `read()`, carried through the reading as an `io::Error` to be raised
/// again as itself (see [`crate::errors::input`]).
#[derive(Debug)]
pub struct Raised(pub PyErr);

impl std::fmt::Display for Raised {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for Raised {}

/// The `io::Error` of an exception raised by a file object's `read()`: an `Exception` becomes
/// its text (an input error naming the input), anything else is kept to be raised again.
fn raised(py: Python<'_>, e: PyErr) -> io::Error {
    if e.is_instance_of::<pyo3::exceptions::PyException>(py) {
        io::Error::other(e.to_string())
    } else {
        io::Error::other(Raised(e))
    }
}
