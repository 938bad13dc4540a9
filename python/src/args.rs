//! Integer arguments checked against their range as they are converted: a negative or huge
//! `esc`, `baud`, `batch_rows` is a `ValueError`, `pole_pairs` a `SettingsError`, each naming
//! the argument and its range, never a bare `OverflowError`.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyInt;

/// `obj` as a `T` from `lo` to `hi`; out of that range, `error` of a message naming `name` and
/// the range.
fn int<T: TryFrom<i128>>(
    obj: Borrowed<'_, '_, PyAny>,
    name: &str,
    (lo, hi): (i128, i128),
    error: fn(String) -> PyErr,
) -> PyResult<T> {
    if !obj.is_instance_of::<PyInt>() {
        return Err(PyTypeError::new_err(format!(
            "{name}: give an integer from {lo} to {hi}, not a {}",
            obj.get_type().name()?
        )));
    }
    obj.extract::<i128>()
        .ok()
        .filter(|v| (lo..=hi).contains(v))
        .and_then(|v| T::try_from(v).ok())
        .ok_or_else(|| {
            error(format!(
                "{name}: {} is out of range: give {lo} to {hi}",
                &*obj
            ))
        })
}

/// The `SettingsError` of a setting out of range, worded as [`crate::errors::settings`].
fn settings_error(message: String) -> PyErr {
    crate::errors::SettingsError::new_err(format!("invalid setting: {message}"))
}

/// Defines an integer argument type: its name in messages, its range, the error out of it.
macro_rules! int_arg {
    ($(#[$doc:meta])* $ty:ident($inner:ty), $name:literal, $lo:expr, $error:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug)]
        pub struct $ty(pub $inner);

        impl<'a, 'py> FromPyObject<'a, 'py> for $ty {
            type Error = PyErr;

            fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
                int(obj, $name, ($lo, <$inner>::MAX as i128), $error).map($ty)
            }
        }
    };
}

int_arg!(
    /// `esc=`: the ESC index of a decoder's records, 0 to 255.
    Esc(u8),
    "esc",
    0,
    PyValueError::new_err
);
int_arg!(
    /// `baud=`: a line rate, at least 1.
    Baud(u32),
    "baud",
    1,
    PyValueError::new_err
);
int_arg!(
    /// `batch_rows=`: rows of a batch, at least 1.
    Rows(usize),
    "batch_rows",
    1,
    PyValueError::new_err
);
/// `pole_pairs=`: motor pole pairs, 1 to 65535 (0 is let through, for the settings to refuse
/// it in the command's words).
#[derive(Clone, Copy, Debug)]
pub struct PolePairs(pub u16);

impl<'a, 'py> FromPyObject<'a, 'py> for PolePairs {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if obj.extract::<u16>().is_ok_and(|p| p == 0) {
            return Ok(PolePairs(0));
        }
        int(obj, "pole_pairs", (1, u16::MAX.into()), settings_error).map(PolePairs)
    }
}
