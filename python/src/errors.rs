//! The library's errors as Python exceptions: `OSError` (`FileNotFoundError` for a missing
//! file) where a file could not be read or written, `ValueError` for everything else; the
//! message is the library's, on one line.

use pyo3::PyErr;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};

/// `e` as the exception a Python user expects.
pub fn to_py(e: &anyhow::Error) -> PyErr {
    let message = slf_host::io::message::one_line(e);
    let io = e.chain().find_map(|c| c.downcast_ref::<std::io::Error>());
    match io.map(std::io::Error::kind) {
        Some(std::io::ErrorKind::NotFound) => PyFileNotFoundError::new_err(message),
        Some(_) => PyOSError::new_err(message),
        None => PyValueError::new_err(message),
    }
}

/// A parser's message (already one line) as a `ValueError`.
pub fn flags(message: String) -> PyErr {
    PyValueError::new_err(message)
}

/// `Result<T, anyhow::Error>` to `PyResult<T>`.
pub trait OrPy<T> {
    /// The error as [`to_py`] maps it.
    fn or_py(self) -> pyo3::PyResult<T>;
}

impl<T> OrPy<T> for anyhow::Result<T> {
    fn or_py(self) -> pyo3::PyResult<T> {
        self.map_err(|e| to_py(&e))
    }
}
