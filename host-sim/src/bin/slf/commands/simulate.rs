//! `slf simulate`: record a light field with the camera model (mask, optics, noise, 16-bit
//! frames, defects) into a capture folder. The flags are [`SimulateSettings`], shared with
//! the Python package.

use slf_host::outln;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::io::lightfield::read_npy;
use slf_host::io::output::Outputs;
use slf_host::sim::calibration::{self, CalibrationCaptures};
use slf_host::sim::settings::SimulateSettings;

#[derive(clap::Args)]
pub struct Args {
    /// Light field .npy (U, V, H, W, B): 13 bands, or any other count with --wavelengths.
    pub input: PathBuf,
    /// Capture folder to write.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub settings: SimulateSettings,
    /// Also write the sensor's calibration captures into this folder (dark-NN, flat-NN,
    /// band-BB-NN: what `slf calibrate` reads), made with the same camera.
    #[arg(long)]
    pub calibration_captures: Option<PathBuf>,
    /// Exposures of each calibration capture kind (averaged by `slf calibrate`), 1..=256.
    #[arg(long, default_value_t = 8, requires = "calibration_captures")]
    pub exposures: usize,
}

pub fn run(args: Args) -> Result<()> {
    let Args { input, output, settings, calibration_captures, exposures } = args;
    let simulated = settings.run(read_npy(&input)?, &input.display().to_string())?;
    for n in &simulated.notes {
        eprintln!("{n}");
    }
    let d = &simulated.capture.description;
    // Made one at a time as they are written (one capture's memory, whatever the sensor).
    let calibration = CalibrationCaptures::new(&settings.camera(), d.lenslets, d.views, d.bands_nm.len(), exposures)?;
    let mut outputs = Outputs::new()
        .input(&input, "the light field")
        .outputs(simulated.capture.files_in(&output), "a file of the capture -o");
    if let Some(dir) = &calibration_captures {
        outputs = calibration.with_outputs(outputs, &simulated.capture, dir);
    }
    outputs.check_distinct()?;
    if let Some(dir) = &calibration_captures {
        calibration::apart_from(dir, &output)?;
    }
    // Both folders written before either is put in place: a refused or failed calibration
    // folder leaves no new capture either.
    let capture_folder = simulated.capture.stage(&output)?;
    let calibration_folder = calibration_captures.as_deref().map(|dir| calibration.stage(dir)).transpose()?;
    capture_folder.persist()?;
    outln!("wrote {} ({} snapshots)", output.display(), simulated.capture.frames.len())?;
    if let (Some(folder), Some(dir)) = (calibration_folder, &calibration_captures) {
        folder.persist()?;
        outln!("wrote {} calibration captures into {}", calibration.len(), dir.display())?;
    }
    Ok(())
}
