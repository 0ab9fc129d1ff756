//! A sensor's calibration from calibration capture folders, as `slf calibrate` makes it.

use std::path::PathBuf;

use pyo3::prelude::*;
use slf_host::decode::calibrate::calibrate_folders;

use crate::errors::OrPy;

/// Calibrates from the capture folders (or folders of them) `captures` into the folder
/// `output`; returns the report's lines.
#[pyfunction]
pub fn calibrate(py: Python<'_>, captures: Vec<PathBuf>, output: PathBuf) -> PyResult<Vec<String>> {
    py.detach(|| calibrate_folders(&captures, &output, None).map(|r| r.lines)).or_py()
}
