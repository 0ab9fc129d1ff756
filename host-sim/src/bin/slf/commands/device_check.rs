//! `slf device-check`: the device binary's output (its semihosting log) against the host's
//! decode of the same tiles; fails above 1e-5 relative difference.

use std::path::PathBuf;

use anyhow::Result;
use slf_host::decode::device;

#[derive(clap::Args)]
pub struct Args {
    /// The device's output.
    pub log: PathBuf,
    /// The capture it decoded.
    #[arg(long, default_value = "firmware/device/capture")]
    pub capture: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    device::check(&args.log, &args.capture)
}
