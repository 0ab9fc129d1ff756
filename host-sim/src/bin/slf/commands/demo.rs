//! `slf demo`: the main job. Render a test scene, record it with the pixel mask at k = 1
//! and k = 3, decode both, print PSNR / SSIM / SA and the time, write previews.

use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::report;

use crate::args::ranged;
use slf_host::decode::settings::BasisSettings;

#[derive(clap::Args)]
pub struct Args {
    /// Where previews and files go.
    #[arg(long, default_value = "slf-demo")]
    pub out: PathBuf,
    /// Named scene (smooth, texture, depth, saturated, dark).
    #[arg(long, default_value = "depth")]
    pub scene: String,
    /// Spatial size (lenslets per side), 11..=2048: the smallest the metrics score (SSIM's
    /// 11 x 11 window).
    #[arg(long, default_value_t = 100, value_parser = ranged::<11, 2048>)]
    pub size: usize,
    #[command(flatten)]
    pub basis: BasisSettings,
}

pub fn run(args: Args) -> Result<()> {
    report::demo(&args.out, &args.scene, args.size, &args.basis.basis()?, args.basis.patch_views)
}
