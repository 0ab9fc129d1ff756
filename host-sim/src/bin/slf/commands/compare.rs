//! `slf compare`: mean PSNR / SSIM / SA over the test scenes for {DCT, ensemble exhaustive,
//! ensemble screened} x {pixel, lenslet, kronecker} x k, and time per patch; a markdown
//! table.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;
use slf_host::decode::cs::PatchViews;
use slf_host::decode::settings::patch_views;
use slf_host::eval::report;
use slf_host::firmware::{ChoiceRule, MaskFamily};

use crate::args::{Family, ranged};

#[derive(clap::Args)]
pub struct Args {
    /// Spatial size (lenslets per side), 11..=1024: the smallest the metrics score (SSIM's
    /// 11 x 11 window).
    #[arg(long, default_value_t = 40, value_parser = ranged::<11, 1024>)]
    pub size: usize,
    /// Snapshot counts.
    #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
    pub k: Vec<u8>,
    /// Also write the table to this file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Ensemble blob (default: the shipped one).
    #[arg(long)]
    pub blob: Option<PathBuf>,
    /// Only these mask families (default: all three).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub masks: Vec<Family>,
    /// Member-choice rule.
    #[arg(long, value_enum, default_value_t = Rule::Residual)]
    pub rule: Rule,
    /// Coefficients kept by the residual rule.
    #[arg(long, default_value_t = 100)]
    pub rule_tau: u16,
    /// Views per axis a patch holds, 4 or 5 [default: 5, the full-view patch; a --blob's
    /// own].
    #[arg(long, value_parser = patch_views, value_name = "4|5")]
    pub patch_views: Option<PatchViews>,
}

pub fn run(args: Args) -> Result<()> {
    slf_host::io::output::Outputs::new().inputs(&args.blob, "--blob").outputs(args.output.as_deref(), "-o").check()?;
    let masks: Vec<MaskFamily> = args.masks.iter().map(|m| m.family()).collect();
    report::compare(
        args.size,
        &args.k,
        args.output.as_deref(),
        args.blob.as_deref(),
        &masks,
        args.rule.rule(args.rule_tau),
        args.patch_views,
    )
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Rule {
    /// Energy outside the --rule-tau largest coefficients.
    Residual,
    /// The l1 norm of the coefficients.
    L1,
}

impl Rule {
    fn rule(self, tau: u16) -> ChoiceRule {
        match self {
            Rule::Residual => ChoiceRule::Residual { tau },
            Rule::L1 => ChoiceRule::L1,
        }
    }
}
