//! numpy arrays to the library's light fields and frames, and back.
//!
//! In: C-ordered arrays of the right dtype (the Python layer converts others and says so);
//! their values are copied once into the library's owned buffers. Out: the library's
//! buffers become the arrays' memory, not copied.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use slf_host::io::lightfield::LightField;

/// An array's values in C order (the last axis fastest), whatever its memory order:
/// copied straight from a C-contiguous buffer, else element by element in logical order.
/// (rust-numpy's `as_slice` also accepts a Fortran-ordered buffer, whose memory order is
/// not the logical one: Fortran-ordered or transposed frames were read scrambled.)
pub fn c_order<T: numpy::Element + Copy>(a: &PyReadonlyArrayDyn<'_, T>) -> Vec<T> {
    match a.as_slice() {
        Ok(s) if a.is_c_contiguous() => s.to_vec(),
        _ => a.as_array().iter().copied().collect(),
    }
}

/// A `(U, V, H, W, B)` float32 array as a light field; `what` names it in errors.
pub fn light_field(a: &PyReadonlyArrayDyn<'_, f32>, what: &str) -> PyResult<LightField> {
    let shape = a.shape().to_vec();
    let [u, v, h, w, b] = shape[..] else {
        return Err(PyValueError::new_err(format!(
            "{what}: want 5 axes (U, V, H, W, B), got {} of shape {shape:?}",
            shape.len()
        )));
    };
    let data = c_order(a);
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
