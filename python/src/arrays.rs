//! numpy arrays to the library's light fields and frames, and back.
//!
//! In: C-ordered arrays of the right dtype (the Python layer converts others and says so);
//! their values are copied once into the library's owned buffers. Out: the library's
//! buffers become the arrays' memory, not copied.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use slf_host::io::lightfield::LightField;

/// A `(U, V, H, W, B)` float32 array as a light field; `what` names it in errors.
pub fn light_field(a: &PyReadonlyArrayDyn<'_, f32>, what: &str) -> PyResult<LightField> {
    let shape = a.shape().to_vec();
    let [u, v, h, w, b] = shape[..] else {
        return Err(PyValueError::new_err(format!(
            "{what}: want 5 axes (U, V, H, W, B), got {} of shape {shape:?}",
            shape.len()
        )));
    };
    let data = a.as_slice().map_err(|_| PyValueError::new_err(format!("{what}: not C-contiguous")))?.to_vec();
    if let Some(i) = data.iter().position(|x| !x.is_finite()) {
        let bad = data.iter().filter(|x| !x.is_finite()).count();
        let lf = LightField { views: (u, v), rows: h, cols: w, bands: b, data: Vec::new() };
        let (iu, iv, iy, ix, ib) = lf.coordinates(i);
        return Err(PyValueError::new_err(format!(
            "{what}: {bad} values are NaN or infinite, the first at (u, v, h, w, b) = ({iu}, {iv}, {iy}, {ix}, {ib})"
        )));
    }
    Ok(LightField { views: (u, v), rows: h, cols: w, bands: b, data })
}

/// A light field as a `(U, V, H, W, B)` float32 array, its buffer moved, not copied.
pub fn to_array<'py>(py: Python<'py>, lf: LightField) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let shape = lf.shape();
    PyArray1::from_vec(py, lf.data).reshape(&shape[..])
}

/// A 2D float32 array of `rows x cols`, its buffer moved.
pub fn plane<'py>(py: Python<'py>, data: Vec<f32>, rows: usize, cols: usize) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    PyArray1::from_vec(py, data).reshape(&[rows, cols][..])
}
