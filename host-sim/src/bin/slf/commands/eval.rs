//! `slf eval`: PSNR, SSIM and spectral angle of a reconstruction against the ground truth.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::metrics::{BLOCK, blocks_over, evaluate, map_accuracy};
use slf_host::io::lightfield::{read_npy, read_npy_f32_2d};

#[derive(clap::Args)]
pub struct Args {
    /// The ground truth light field, (U, V, H, W, B) .npy.
    pub truth: PathBuf,
    /// The reconstruction, same shape.
    pub recon: PathBuf,
    /// The decode's error map (`slf decode --error-map`): its estimated PSNR printed beside
    /// the true one, and how well it ranks the true error of blocks of 5 x 5 lenslets.
    #[arg(long)]
    pub error_map: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    let (truth, recon) = (read_npy(&args.truth)?, read_npy(&args.recon)?);
    let m = evaluate(&truth, &recon)?;
    let (over, blocks) = blocks_over(&truth, &recon);
    // Written, not `println!`: a reader that stops early (`slf eval A B | head -1`)
    // closes the pipe, and `println!` panics on that.
    let mut out = std::io::stdout().lock();
    writeln!(out, "PSNR {:.3} dB (data range {:.6} = max of ground truth)", m.psnr, m.data_range)?;
    writeln!(out, "SSIM {:.4}", m.ssim)?;
    writeln!(out, "SA   {:.3} deg", m.sa)?;
    if let Some(path) = &args.error_map {
        let map = read_npy_f32_2d(path, (truth.rows, truth.cols))?;
        let a = map_accuracy(&truth, &recon, &map)?;
        writeln!(
            out,
            "estimate PSNR {:.3} dB (true {:.3}); blocks of {BLOCK} x {BLOCK} lenslets: rank correlation {:.3}, {:.1} % \
             within 2 x of the true RMS error ({} blocks)",
            a.estimated_psnr,
            m.psnr,
            a.rank_correlation,
            100.0 * a.within_2x,
            a.blocks
        )?;
    }
    writeln!(
        out,
        "over {over} of {blocks} blocks of {BLOCK} x {BLOCK} lenslets decoded above 2 x the truth's maximum + 0.05"
    )?;
    Ok(())
}
