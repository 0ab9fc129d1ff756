//! `slf sweep`: PSNR / SSIM / SA of every test scene x mask family x k, decoded with
//! `--dictionary`; a markdown table.

use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::report;

use crate::args::ranged;
use slf_host::decode::settings::BasisSettings;

#[derive(clap::Args)]
pub struct Args {
    /// Spatial size (lenslets per side), 11..=1024: the smallest the metrics score (SSIM's
    /// 11 x 11 window).
    #[arg(long, default_value_t = 60, value_parser = ranged::<11, 1024>)]
    pub size: usize,
    /// Snapshot counts.
    #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
    pub k: Vec<u8>,
    /// Also write the table to this file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub basis: BasisSettings,
}

pub fn run(args: Args) -> Result<()> {
    slf_host::io::output::Outputs::new()
        .inputs(&args.basis.blob, "--blob")
        .outputs(args.output.as_deref(), "-o")
        .check()?;
    report::sweep(args.size, &args.k, args.output.as_deref(), &args.basis.basis()?, args.basis.patch_views)
}
