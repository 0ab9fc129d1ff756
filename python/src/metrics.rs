//! PSNR, SSIM and spectral angle, as `slf eval` computes them.

use numpy::PyReadonlyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use slf_host::eval::metrics;

use crate::arrays::light_field;
use crate::errors::OrPy;

/// `{"psnr": dB, "ssim": .., "sa": degrees, "data_range": max of truth}`.
#[pyfunction]
pub fn evaluate<'py>(
    py: Python<'py>,
    truth: PyReadonlyArrayDyn<'py, f32>,
    recon: PyReadonlyArrayDyn<'py, f32>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, r) = (light_field(&truth, "truth")?, light_field(&recon, "recon")?);
    let m = py.detach(|| metrics::evaluate(&t, &r)).or_py()?;
    let d = PyDict::new(py);
    d.set_item("psnr", m.psnr)?;
    d.set_item("ssim", m.ssim)?;
    d.set_item("sa", m.sa)?;
    d.set_item("data_range", m.data_range)?;
    Ok(d)
}
