//! Real data as the camera's 13 bands: `slf import views` and `slf import cube` with the
//! command's own flags ([`ViewsSettings`], [`CubeSettings`]).

use numpy::PyArrayDyn;
use pyo3::prelude::*;
use slf_host::io::import::views::Imported;
use slf_host::sim::flags::FromFlags;
use slf_host::sim::import::{CubeSettings, ViewsSettings};

use crate::arrays::{plane, to_array};
use crate::errors::{OrPy, flags};

/// A light field, the centre view's disparity (or `None`) and notes.
type Out<'py> = (Bound<'py, PyArrayDyn<f32>>, Option<Bound<'py, PyArrayDyn<f32>>>, Vec<String>);

fn out(py: Python<'_>, imported: Imported) -> PyResult<Out<'_>> {
    let disparity = match imported.disparity {
        Some(d) => Some(plane(py, d.data, d.rows, d.cols)?),
        None => None,
    };
    Ok((to_array(py, imported.lightfield)?, disparity, imported.notes))
}

/// `slf import views FOLDER [flags]` without `-o`: `args` starts with the folder.
#[pyfunction]
pub fn import_views(py: Python<'_>, args: Vec<String>) -> PyResult<Out<'_>> {
    let settings = ViewsSettings::from_flags(&args).map_err(flags)?;
    let imported = py.detach(|| settings.run()).or_py()?;
    out(py, imported)
}

/// `slf import cube INPUT [flags]` without `-o`: `args` starts with the input.
#[pyfunction]
pub fn import_cube(py: Python<'_>, args: Vec<String>) -> PyResult<Out<'_>> {
    let settings = CubeSettings::from_flags(&args).map_err(flags)?;
    let imported = py.detach(|| settings.run()).or_py()?;
    out(py, imported)
}
