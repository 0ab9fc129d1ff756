//! Capture folders (`capture.json` and one frame file per snapshot, as `slf simulate`
//! writes them) to numpy and back: frames as a `(k, rows, cols)` uint16 array, the
//! description as its JSON text (the Python layer holds it as a dict).

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use slf_host::io::capture::{Capture, CaptureDescription};

use crate::errors::OrPy;

/// A capture from its frames `(k, rows, cols)` and description JSON, checked as a loaded
/// one is ([`Capture::new`]).
pub fn from_parts(frames: &PyReadonlyArrayDyn<'_, u16>, description: &str) -> PyResult<Capture> {
    let shape = frames.shape().to_vec();
    let [k, rows, cols] = shape[..] else {
        return Err(PyValueError::new_err(format!(
            "frames: want 3 axes (snapshots, rows, cols), got {} of shape {shape:?}",
            shape.len()
        )));
    };
    let d: CaptureDescription = slf_host::io::json::parse(description)
        .map_err(|e| PyValueError::new_err(format!("description: invalid capture description: {e}")))?;
    let data = crate::arrays::c_order(frames);
    let frames: Vec<Vec<u16>> =
        if rows * cols == 0 { vec![Vec::new(); k] } else { data.chunks(rows * cols).map(<[u16]>::to_vec).collect() };
    Capture::new(d, frames).or_py()
}

/// A capture as `(frames, description JSON)`, the frames read whole if they were paged.
pub fn to_parts<'py>(py: Python<'py>, capture: Capture) -> PyResult<(Bound<'py, PyArrayDyn<u16>>, String)> {
    let (rows, cols) = capture.frame_size();
    let k = capture.frames.len();
    let json = serde_json::to_string(&capture.description).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let data: Vec<u16> = capture.frames.held((rows, cols)).or_py()?.iter().flatten().copied().collect();
    Ok((PyArray1::from_vec(py, data).reshape(&[k, rows, cols][..])?, json))
}

/// Loads a capture folder: `(frames, description JSON)`.
#[pyfunction]
pub fn load_capture<'py>(py: Python<'py>, path: PathBuf) -> PyResult<(Bound<'py, PyArrayDyn<u16>>, String)> {
    let capture = py.detach(|| Capture::load(&path)).or_py()?;
    to_parts(py, capture)
}

/// Writes a capture folder, frames in the formats their names in the description say.
#[pyfunction]
pub fn save_capture(
    py: Python<'_>,
    frames: PyReadonlyArrayDyn<'_, u16>,
    description: &str,
    path: PathBuf,
) -> PyResult<()> {
    let capture = from_parts(&frames, description)?;
    py.detach(|| capture.save(&path)).or_py()
}

/// Checks a capture's frames against its description; returns the description as the
/// library writes it.
#[pyfunction]
pub fn check_capture(frames: PyReadonlyArrayDyn<'_, u16>, description: &str) -> PyResult<String> {
    let capture = from_parts(&frames, description)?;
    serde_json::to_string(&capture.description).map_err(|e| PyValueError::new_err(e.to_string()))
}
