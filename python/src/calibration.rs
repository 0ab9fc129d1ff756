//! A sensor's calibration from calibration capture folders, as `slf calibrate` makes it.

use std::path::PathBuf;

use pyo3::prelude::*;
use slf_host::decode::calibrate::calibrate as calibrate_captures;
use slf_host::io::calibration::{DARK, DESCRIPTION, FLAT};
use slf_host::io::capture::Capture;
use slf_host::io::output::Outputs;

use crate::errors::OrPy;

/// Calibrates from the capture folders `captures` into the folder `output`; returns the
/// report's lines.
#[pyfunction]
pub fn calibrate(py: Python<'_>, captures: Vec<PathBuf>, output: PathBuf) -> PyResult<Vec<String>> {
    py.detach(|| -> anyhow::Result<Vec<String>> {
        let loaded: Vec<(String, Capture)> = captures
            .iter()
            .map(|p| Capture::load(p).map(|c| (p.display().to_string(), c)))
            .collect::<anyhow::Result<_>>()?;
        let mut outputs = Outputs::new();
        for (_, c) in &loaded {
            outputs = outputs.inputs(c.files(), "a calibration capture's file");
        }
        outputs
            .outputs([output.join(DESCRIPTION), output.join(DARK), output.join(FLAT)], "a file of the calibration")
            .check_distinct()?;
        let (calibration, report) = calibrate_captures(&loaded, None)?;
        calibration.save(&output)?;
        Ok(report.lines)
    })
    .or_py()
}
