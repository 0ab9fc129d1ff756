//! `slf simulate`: record a light field with the camera model (mask, optics, noise, 16-bit
//! frames, defects) into a capture folder. The flags are [`SimulateSettings`], shared with
//! the Python package.

use std::path::PathBuf;

use anyhow::Result;
use slf_host::io::lightfield::read_npy;
use slf_host::io::output::Outputs;
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
}

pub fn run(args: Args) -> Result<()> {
    let Args { input, output, settings } = args;
    let simulated = settings.run(read_npy(&input)?, &input.display().to_string())?;
    for n in &simulated.notes {
        eprintln!("{n}");
    }
    Outputs::new()
        .input(&input, "the light field")
        .outputs(simulated.capture.files_in(&output), "a file of the capture -o")
        .check_distinct()?;
    simulated.capture.save(&output)?;
    println!("wrote {} ({} snapshots)", output.display(), simulated.capture.frames.len());
    Ok(())
}
