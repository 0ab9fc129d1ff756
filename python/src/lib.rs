//! `slf._slf`: the slf Python package's native module, PyO3 over `slf-host`.
//!
//! Thin on purpose: each function parses the same flags as the `slf` command (the library's
//! [`slf_host::decode::settings`] and [`slf_host::sim::settings`], so the package and the
//! command share defaults, ranges and messages), runs the library, and hands numpy arrays
//! back without copying them. The Python layer (`slf/__init__.py`) turns keywords into
//! those flags, converts dtypes and orders, and names the axes in shape errors.
//!
//! - [`arrays`]: numpy arrays to light fields and frames and back;
//! - [`errors`]: the library's errors as `ValueError` / `OSError`, one line;
//! - [`capture`]: capture folders loaded, saved and checked;
//! - [`calibration`]: a sensor's calibration from its calibration captures;
//! - [`scene`]: the named scenes and the simulated camera;
//! - [`decode`]: the decode, with the GIL released, threads and a progress callback;
//! - [`metrics`]: PSNR, SSIM, SA;
//! - [`import`]: views and hyperspectral cubes as the camera's 13 bands.

use pyo3::prelude::*;

mod arrays;
mod calibration;
mod capture;
mod decode;
mod errors;
mod import;
mod metrics;
mod scene;
mod stack;

#[pymodule]
fn _slf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(scene::scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(capture::load_capture, m)?)?;
    m.add_function(wrap_pyfunction!(capture::save_capture, m)?)?;
    m.add_function(wrap_pyfunction!(capture::check_capture, m)?)?;
    m.add_function(wrap_pyfunction!(calibration::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(decode::decode, m)?)?;
    m.add_class::<stack::Stack>()?;
    m.add_function(wrap_pyfunction!(metrics::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(import::import_views, m)?)?;
    m.add_function(wrap_pyfunction!(import::import_cube, m)?)?;
    Ok(())
}
