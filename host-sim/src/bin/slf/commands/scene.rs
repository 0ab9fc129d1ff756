//! `slf scene`: a named test scene, a realistic one or a random training scene, as a
//! `(U, V, H, W, B)` `.npy`.

use slf_host::outln;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::io::lightfield::{Dtype, write_npy};
use slf_host::sim::hard;
use slf_host::sim::scene::SceneSize;

use crate::args::ranged;

#[derive(clap::Args)]
pub struct Args {
    /// A name (test scenes: smooth, texture, depth, saturated, dark; realistic: outdoor,
    /// tungsten, office, led; hard cases: mosaic, mosaic-2, field, print, speculars, narrow,
    /// dim), `random` (the training scenes of the shipped ensemble) or `realistic` (slanted
    /// and curved surfaces, 1/f textures, measured spectra, five illuminants), the last two
    /// drawn from --seed.
    pub name: String,
    /// Output .npy file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Seed of a random scene.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Spatial rows and columns (lenslets), 11..=4096: the smallest slf eval scores
    /// (SSIM's 11 x 11 window).
    #[arg(long, default_value_t = 100, value_parser = ranged::<11, 4096>)]
    pub size: usize,
    /// Spatial rows (lenslets), 11..=4096, where they differ from --size (which then gives
    /// the columns): a frame wider than tall, e.g. for a strip's memory against the
    /// frame's height at equal width.
    #[arg(long, value_parser = ranged::<11, 4096>)]
    pub rows: Option<usize>,
    /// Views per side, 4..=16: the decoder's patch takes 4 x 4.
    #[arg(long, default_value_t = 5, value_parser = ranged::<4, 16>)]
    pub views: usize,
    /// Stored dtype.
    #[arg(long, value_enum, default_value_t = Dtype::F32)]
    pub dtype: Dtype,
}

pub fn run(args: Args) -> Result<()> {
    let Args { name, output, seed, size, rows, views, dtype } = args;
    let s = hard::by_name(&name, seed)?;
    let size = SceneSize { views: (views, views), rows: rows.unwrap_or(size), cols: size };
    let given = rows.map_or(String::new(), |r| format!(" --rows {r}"));
    size.check().map_err(|e| anyhow::anyhow!("--size {}{given} with --views {views}: {e}", size.cols))?;
    let lf = s.render(size);
    write_npy(&output, &lf, dtype)?;
    outln!("wrote {} ({:?})", output.display(), lf.shape())?;
    Ok(())
}
