//! `slf device-capture`: the capture the device binary decodes (frames as `.npy` and the
//! `capture.rs` constants).

use std::path::PathBuf;

use anyhow::Result;
use slf_host::decode::device;

#[derive(clap::Args)]
pub struct Args {
    /// Folder (firmware/device).
    #[arg(short, long, default_value = "firmware/device")]
    pub output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    device::write_capture(&args.output)
}
