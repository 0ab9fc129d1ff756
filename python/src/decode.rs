//! The decode: `slf decode`'s flags ([`DecodeSettings`]) on a capture held in numpy, with
//! the GIL released, on a thread pool of the caller's size, and a progress callback.

use slf_host::sim::flags::FromFlags;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::{PyArrayDyn, PyReadonlyArrayDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use slf_host::decode::cs::{PatchViews, disparity_per_lenslet};
use slf_host::decode::pipeline::{Outcome, output_shape};
use slf_host::decode::report::NO_ESTIMATE;
use slf_host::decode::settings::DecodeSettings;
use slf_host::io::calibration::Calibration;
use slf_host::io::lightfield::Dtype;
use slf_host::io::output::Outputs;
use slf_host::io::output_file::{OutputFile, OutputKind};
use slf_host::io::rows::Stoppable;

use crate::arrays::{plane, to_array};
use crate::capture::from_parts;
use crate::errors::{OrPy, flags};

/// A decode's light field (`None` when it went to a file) and its report.
type Decoded<'py> = (Option<Bound<'py, PyArrayDyn<f32>>>, Bound<'py, PyDict>);

/// Decodes the capture `(frames, description JSON)` with `slf decode`'s flags `args`:
/// `(light field, report)`. `threads`: the decode's threads (`None`: one per core);
/// `progress(done, total)` is called from the worker threads after each tile. With
/// `output`, the light field is written to that `.npy` file as its rows are decoded (the
/// memory of a band of rows, not the frame; the file is in place only once the decode is
/// done) and `None` is returned in its stead. `source`: the capture folder the frames were
/// read from, if any: `output` may not be one of its files, nor a file of the calibration
/// or the blob the flags name (as `slf decode` refuses them: it would destroy an input).
#[pyfunction]
#[pyo3(signature = (frames, description, args, threads=None, progress=None, output=None, source=None, slot=None))]
#[allow(clippy::too_many_arguments)] // the Python call's keyword arguments, one each
pub fn decode<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, u16>,
    description: &str,
    args: Vec<String>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    output: Option<std::path::PathBuf>,
    source: Option<std::path::PathBuf>,
    slot: Option<usize>,
) -> PyResult<Decoded<'py>> {
    let mut settings = DecodeSettings::from_flags(&args).map_err(flags)?;
    // The report's `disparity` plane is made from the disparity map; the member map is not
    // returned, so not kept.
    settings.maps.disparities = true;
    let capture = from_parts(&frames, description)?;
    if let (Some(path), None) = (&output, slot) {
        // Checked before the decode, with the command's check (paths resolved, hard links
        // by inode): the decode reads the calibration and the blob again, and a capture
        // folder written over is a user's raw data lost. (A slot's store is the temporary
        // folder slf.batch made: nothing else is in it.)
        let outputs = Outputs::new()
            .inputs(source.iter().flat_map(|dir| capture.files_in(dir)), "a file of the capture")
            .inputs(&settings.basis.blob, "blob")
            .inputs(settings.calibration.iter().flat_map(|d| Calibration::files_in(d)), "a file of calibration");
        match path.extension().is_some_and(|e| e.eq_ignore_ascii_case("zarr")) {
            true => outputs.folder_output(path, "output"),
            false => outputs.output(path, "output"),
        }
        .check()
        .map_err(|e| PyValueError::new_err(slf_host::io::message::one_line(&e)))?;
    }
    let kind = match (&output, slot) {
        (None, None) => None,
        (None, Some(_)) => return Err(PyValueError::new_err("slot: a capture's slot of a store named by output")),
        (Some(path), slot) => Some(output_kind(path, slot)?),
    };
    // The decode is compute-bound: threads past a few per core buy nothing, and 10**9 of
    // them were spawned until the OS refused.
    let most = 4 * std::thread::available_parallelism().map_or(1, usize::from);
    match threads {
        Some(0) => return Err(PyValueError::new_err("threads: at least 1 (None: one per core)")),
        Some(n) if n > most => {
            return Err(PyValueError::new_err(format!(
                "threads: {n} is more than the {most} (4 per core of this machine) a decode can use (None: one per core)"
            )));
        }
        _ => {}
    }
    // The first exception the callback raised, or Python's KeyboardInterrupt: the decode
    // stops at its next finished row, a file output is dropped unfinished, and the
    // exception is raised. Python runs its signal handlers on the main thread only, so the
    // decode runs on a thread of its own and the calling thread checks them while it waits.
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let stop = AtomicBool::new(false);
    let keep = |e: PyErr| {
        if let Ok(mut r) = raised.lock() {
            r.get_or_insert(e);
        }
        stop.store(true, Ordering::Relaxed);
    };
    let observer = |done: usize, total: usize| {
        if let (Some(cb), false) = (&progress, stop.load(Ordering::Relaxed)) {
            Python::attach(|py| cb.call1(py, (done, total)).map(drop)).unwrap_or_else(keep);
        }
    };
    // The light field in memory, or its file as it goes; the largest value either way
    // (the estimated PSNR's data range).
    let work = || {
        let run = || match &output {
            None => {
                let mut light_field = output_shape(&capture).zeros()?;
                let outcome = settings.run_into(
                    &capture,
                    false,
                    &observer,
                    &mut Stoppable { inner: &mut light_field, stop: &stop },
                )?;
                let peak = light_field.max();
                Ok((outcome, Some(light_field), peak))
            }
            Some(path) => {
                let kind = kind.unwrap_or(OutputKind::Npy(Dtype::F32));
                let command = args.join(" ");
                let mut file = OutputFile::create(kind, path, output_shape(&capture), &capture.description, &command)?;
                let outcome = settings.run_into(
                    &capture,
                    false,
                    &observer,
                    &mut Stoppable { inner: file.sink(), stop: &stop },
                )?;
                let peak = file.max();
                file.finish(&command)?;
                Ok((outcome, None, peak))
            }
        };
        match threads {
            None => run(),
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| anyhow::anyhow!("threads: {e}"))
                .and_then(|pool| pool.install(run)),
        }
    };
    let decoded = py.detach(|| {
        std::thread::scope(|scope| {
            let (tx, rx) = std::sync::mpsc::channel();
            scope.spawn(move || tx.send(work()));
            loop {
                match rx.recv_timeout(std::time::Duration::from_millis(20)) {
                    Ok(result) => return result,
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        if !stop.load(Ordering::Relaxed) {
                            Python::attach(|py| py.check_signals()).unwrap_or_else(keep);
                        }
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                        return Err(anyhow::anyhow!("the decode's thread ended without a result"));
                    }
                }
            }
        })
    });
    // The callback's exception first: the decode's error is then only that it was stopped.
    if let Some(e) = raised.lock().ok().and_then(|mut r| r.take()) {
        return Err(e);
    }
    let (outcome, light_field, peak) = decoded.or_py()?;
    let report = PyDict::new(py);
    if let Some(w) = outcome.warning() {
        report.set_item("warning", w)?;
    }
    let d = &capture.description;
    match &outcome {
        Outcome::Baseline { method, report: r } => {
            report.set_item("method", format!("{method:?}").to_lowercase())?;
            report.set_item("measured", r.measured)?;
            report.set_item("filled", r.filled)?;
            report.set_item("seconds", r.seconds)?;
        }
        Outcome::Cs { options, report: r } => {
            report.set_item("method", "cs")?;
            report.set_item("preset", settings.preset.name())?;
            report.set_item("decoded", r.patches.decoded)?;
            report.set_item("flagged", r.patches.flagged)?;
            report.set_item("failed", r.patches.failed)?;
            report.set_item("solved", r.patches.solved())?;
            report.set_item("interpolated", r.patches.interpolated)?;
            report.set_item("flat", r.patches.flat)?;
            report.set_item("implausible", r.patches.implausible)?;
            report.set_item("clipped", r.patches.clipped)?;
            report.set_item("tiles", r.tiles)?;
            report.set_item("failed_tiles", r.failed_tiles)?;
            report.set_item("solves", r.solves)?;
            report.set_item("steps", r.steps)?;
            report.set_item("filled", r.filled)?;
            report.set_item("gains", r.gains.to_vec())?;
            report.set_item("seconds", r.seconds)?;
            report.set_item("rows_held", r.rows_held)?;
            report.set_item("off_sensor_lenslets", r.off_sensor.lenslets)?;
            report.set_item("off_sensor_views", r.off_sensor.views)?;
            let [rows, cols] = d.lenslets;
            report.set_item("coverage", plane(py, r.off_sensor.coverage([rows, cols]), rows, cols)?)?;
            report.set_item("stride", options.stride.0)?;
            report.set_item("seeded", options.seeds())?;
            report.set_item("patch_views", r.patch_views.map(PatchViews::count))?;
            if options.disparities_for(&capture).is_off() {
                report.set_item("disparity", py.None())?;
            } else {
                let (rows, cols) = (d.lenslets[0], d.lenslets[1]);
                let map = disparity_per_lenslet(&r.disparity_map, rows, cols);
                report.set_item("disparity", plane(py, map, rows, cols)?)?;
            }
            if let Some(t) = &r.shear_trial {
                let trial = PyDict::new(py);
                trial.set_item("halves", t.halves)?;
                trial.set_item("pilots", t.pilots)?;
                trial.set_item("half_error", t.half_error)?;
                trial.set_item("whole_error", t.whole_error)?;
                report.set_item("shear_trial", trial)?;
            }
            if let Some(why) = &r.shear_trial_skipped {
                report.set_item("shear_trial_skipped", why)?;
            }
            if let Some(why) = &r.blend_skipped {
                report.set_item("baseline_blend_skipped", why)?;
            }
            if let Some(b) = &r.blend {
                let blend = PyDict::new(py);
                blend.set_item("mean_weight", b.mean_weight())?;
                blend.set_item("mostly_baseline", b.mostly_baseline())?;
                blend.set_item("lenslets", b.weights.len())?;
                blend.set_item("seconds", b.seconds)?;
                let (rows, cols) = (d.lenslets[0], d.lenslets[1]);
                blend.set_item("weights", plane(py, b.weights.clone(), rows, cols)?)?;
                report.set_item("baseline_blend", blend)?;
            }
            if let Some(t) = &r.trial {
                let trial = PyDict::new(py);
                trial.set_item("model", if t.dct { "dct" } else { "ensemble" })?;
                trial.set_item("pilots", t.pilots)?;
                trial.set_item("dct_error", t.dct_error)?;
                trial.set_item("ensemble_error", t.ensemble_error)?;
                trial.set_item("tied", t.tied)?;
                if let Some((dct, ensemble)) = t.by_decode {
                    trial.set_item("decode_dct_error", dct)?;
                    trial.set_item("decode_ensemble_error", ensemble)?;
                }
                report.set_item("trial", trial)?;
            }
            let (rows, cols) = (d.lenslets[0], d.lenslets[1]);
            if !r.estimated() && settings.estimate {
                report.set_item("estimate_note", NO_ESTIMATE)?;
            }
            if let Some(map) = r.error_map(rows, cols, settings.estimate) {
                report.set_item("estimated_psnr", r.estimated_psnr(&map, cols, f64::from(peak)))?;
                report.set_item("error_map", plane(py, map, rows, cols)?)?;
                report.set_item("estimate_seconds", r.estimate_seconds)?;
            }
        }
    }
    Ok((light_field.map(|lf| to_array(py, lf)).transpose()?, report))
}

/// The kind of `path`, by its extension, or a slot of a store.
///
/// # Errors
/// A slot of something other than a store, or an extension that names no output.
fn output_kind(path: &std::path::Path, slot: Option<usize>) -> PyResult<OutputKind> {
    let ext = |e: &str| path.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    match (slot, ext("npy"), ext("zarr")) {
        (Some(index), ..) => Ok(OutputKind::Slot(index)),
        (None, true, _) => Ok(OutputKind::Npy(Dtype::F32)),
        (None, _, true) => Ok(OutputKind::Zarr(None)),
        _ => Err(PyValueError::new_err(format!(
            "output {}: a .npy file or a .zarr store (an HDF5 file: slf decode -o OUT.h5)",
            path.display()
        ))),
    }
}
