//! `slf calibrate`: a sensor's calibration from its calibration captures (dark frames,
//! flats, a band sweep or measured filter curves), written as a calibration folder that
//! `slf decode --calibration` reads (`docs/capture-format.md`, "Calibration"). The work is
//! [`calibrate_folders`], shared with the Python package.

use slf_host::outln;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::decode::calibrate::calibrate_folders;

#[derive(clap::Args)]
pub struct Args {
    /// Calibration capture folders (their `light`: dark, flat or a band); a folder holding
    /// only such folders (as `slf simulate --calibration-captures` writes) stands for them.
    #[arg(required = true)]
    pub captures: Vec<PathBuf>,
    /// Calibration folder to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Measured filter curves instead of a band sweep: a float .npy of shape (filters,
    /// bands), what a pixel behind each filter records of each band relative to light of
    /// equal energy in every band.
    #[arg(long)]
    pub response: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    let Args { captures, output, response } = args;
    let report = calibrate_folders(&captures, &output, response.as_deref())?;
    for line in &report.lines {
        eprintln!("{line}");
    }
    outln!("wrote {}", output.display())?;
    Ok(())
}
