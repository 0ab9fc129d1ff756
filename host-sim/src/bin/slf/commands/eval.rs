//! `slf eval`: PSNR, SSIM and spectral angle of a reconstruction against the ground truth.

use std::path::PathBuf;

use anyhow::{Context, Result, bail, ensure};
use slf_host::eval::metrics::{BLOCK, WIN, blocks_over, check_error_map, evaluate, map_accuracy};
use slf_host::io::lightfield::{LightField, read_npy, read_npy_beside, read_npy_f32_2d};
use slf_host::outln;

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
    /// Score only the lenslets at least this many in from every edge of the frame: a turned
    /// lenslet array's corner lenslets reach past the sensor (`slf decode` says how many),
    /// and their views there were never measured.
    #[arg(long, default_value_t = 0)]
    pub border: usize,
}

/// The lenslets `border` in from every edge of `lf`.
fn interior(lf: LightField, border: usize, what: &str) -> Result<LightField> {
    if border == 0 {
        return Ok(lf);
    }
    ensure!(
        2 * border < lf.rows && 2 * border < lf.cols,
        "--border {border}: the {what} has {} x {} lenslets, nothing is {border} in from every edge",
        lf.rows,
        lf.cols
    );
    let (rows, cols) = (lf.rows - 2 * border, lf.cols - 2 * border);
    // SSIM's window must fit in what is scored: name the flag that cut it too small, and
    // the largest it may be.
    if (rows < WIN || cols < WIN) && lf.rows >= WIN && lf.cols >= WIN {
        bail!(
            "--border {border} leaves {rows} x {cols} of the {what}'s {} x {} lenslets, and SSIM needs at least {WIN} \
             x {WIN}: at most --border {}",
            lf.rows,
            lf.cols,
            (lf.rows.min(lf.cols) - WIN) / 2
        );
    }
    Ok(lf.window(border, border, rows, cols))
}

pub fn run(args: Args) -> Result<()> {
    let truth = read_npy(&args.truth)?;
    let recon = read_npy_beside(&args.recon, ("the ground truth", truth.data.len() as u64 * 4))?;
    ensure!(
        truth.shape() == recon.shape(),
        "shapes differ: truth {:?}, reconstruction {:?}",
        truth.shape(),
        recon.shape()
    );
    let (full_rows, full_cols) = (truth.rows, truth.cols);
    let b = args.border;
    let (truth, recon) = (interior(truth, b, "ground truth")?, interior(recon, b, "reconstruction")?);
    let m = evaluate(&truth, &recon)?;
    let (over, blocks) = blocks_over(&truth, &recon);
    if b > 0 {
        outln!(
            "scored: lenslets {b}..{} x {b}..{} of {full_rows} x {full_cols} (--border {b})",
            full_rows - b,
            full_cols - b
        )?;
    }
    outln!("PSNR {:.3} dB (data range {:.6} = max of ground truth)", m.psnr, m.data_range)?;
    outln!("SSIM {:.4}", m.ssim)?;
    outln!("SA   {:.3} deg", m.sa)?;
    if let Some(path) = &args.error_map {
        let full = read_npy_f32_2d(path, (full_rows, full_cols))?;
        check_error_map(&full, full_cols).with_context(|| path.display().to_string())?;
        let map: Vec<f32> = full
            .chunks_exact(full_cols)
            .skip(b)
            .take(truth.rows)
            .flat_map(|row| row.iter().skip(b).take(truth.cols).copied())
            .collect();
        let a = map_accuracy(&truth, &recon, &map)?;
        outln!(
            "estimate PSNR {:.3} dB (true {:.3}); blocks of {BLOCK} x {BLOCK} lenslets: rank correlation {:.3}, {:.1} % \
             within 2 x of the true RMS error ({} blocks)",
            a.estimated_psnr,
            m.psnr,
            a.rank_correlation,
            100.0 * a.within_2x,
            a.blocks
        )?;
    }
    outln!(
        "over {over} of {blocks} blocks of {BLOCK} x {BLOCK} lenslets decoded above 2 x the truth's maximum + 0.05"
    )?;
    Ok(())
}
