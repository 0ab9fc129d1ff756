//! Light fields to record: the named scenes of `slf scene`, and the camera of
//! `slf simulate` ([`SimulateSettings`], the command's own flags).

use numpy::{PyArrayDyn, PyReadonlyArrayDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use slf_host::sim::flags::FromFlags;
use slf_host::sim::scene::SceneSize;
use slf_host::sim::settings::SimulateSettings;

use crate::arrays::{light_field, to_array};
use crate::capture::to_parts;
use crate::errors::{OrPy, flags};

/// Renders a scene `(U, V, H, W, 13)`: `name` as `slf scene` takes it.
#[pyfunction]
pub fn scene<'py>(
    py: Python<'py>,
    name: &str,
    size: usize,
    views: usize,
    seed: u64,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let s = slf_host::sim::hard::by_name(name, seed).or_py()?;
    if size < slf_host::sim::scene::MIN_SCENE {
        return Err(PyValueError::new_err(format!(
            "size {size}: want {}..=4096 (the smallest light field slf.evaluate scores, SSIM's 11 x 11 window)",
            slf_host::sim::scene::MIN_SCENE
        )));
    }
    let shape = SceneSize { views: (views, views), rows: size, cols: size };
    shape.check().map_err(|e| PyValueError::new_err(format!("size {size} with views {views}: {e}")))?;
    let lf = py.detach(|| s.render(shape));
    to_array(py, lf)
}

/// Records `lf` with the camera `slf simulate` would use with these flags: `(frames,
/// description JSON, notes)`. With `calibration_captures`, also writes the sensor's
/// calibration captures there, `exposures` of each kind, as `slf simulate
/// --calibration-captures DIR --exposures N` does.
#[pyfunction]
#[pyo3(signature = (lf, args, calibration_captures=None, exposures=8))]
pub fn simulate<'py>(
    py: Python<'py>,
    lf: PyReadonlyArrayDyn<'py, f32>,
    args: Vec<String>,
    calibration_captures: Option<std::path::PathBuf>,
    exposures: usize,
) -> PyResult<(Bound<'py, PyArrayDyn<u16>>, String, Vec<String>)> {
    let settings = SimulateSettings::from_flags(&args).map_err(flags)?;
    let lf = light_field(&lf, "lf")?;
    let simulated = py
        .detach(|| -> anyhow::Result<_> {
            let simulated = settings.run(lf, "lf")?;
            if let Some(dir) = &calibration_captures {
                let d = &simulated.capture.description;
                let captures = slf_host::sim::calibration::CalibrationCaptures::new(
                    &settings.camera(),
                    d.lenslets,
                    d.views,
                    d.bands_nm.len(),
                    exposures,
                )?;
                let outputs = captures.with_outputs(slf_host::io::output::Outputs::new(), &simulated.capture, dir);
                outputs.check_distinct()?;
                captures.stage(dir)?.persist()?;
            }
            Ok(simulated)
        })
        .or_py()?;
    let (frames, json) = to_parts(py, simulated.capture)?;
    Ok((frames, json, simulated.notes))
}
