//! `slf eval`: PSNR, SSIM and spectral angle of a reconstruction against the ground truth.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::metrics::evaluate;
use slf_host::io::lightfield::read_npy;

#[derive(clap::Args)]
pub struct Args {
    /// The ground truth light field, (U, V, H, W, B) .npy.
    pub truth: PathBuf,
    /// The reconstruction, same shape.
    pub recon: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let m = evaluate(&read_npy(&args.truth)?, &read_npy(&args.recon)?)?;
    // Written, not `println!`: a reader that stops early (`slf eval A B | head -1`)
    // closes the pipe, and `println!` panics on that.
    let mut out = std::io::stdout().lock();
    writeln!(out, "PSNR {:.3} dB (data range {:.6} = max of ground truth)", m.psnr, m.data_range)?;
    writeln!(out, "SSIM {:.4}", m.ssim)?;
    writeln!(out, "SA   {:.3} deg", m.sa)?;
    Ok(())
}
