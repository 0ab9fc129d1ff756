//! `slf bench`: speed against error. Sweeps solver settings, bases, masks and k; writes CSV,
//! markdown and a plot (or, with `--paper-scale`, the paper's scale end to end).

use slf_host::outln;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::bench::{self, BenchOptions};
use slf_host::eval::device_frame;

use crate::args::Family;

#[derive(clap::Args)]
pub struct Args {
    /// Output folder (bench.csv, bench.md, bench.png).
    #[arg(short, long, default_value = "slf-bench")]
    pub out: PathBuf,
    /// A CI-sized run: two small scenes, k = 3, no exhaustive choice.
    #[arg(long)]
    pub quick: bool,
    /// Instead of the sweep: the paper's scale end to end (512 x 512 x 5 x 5 x 13).
    #[arg(long)]
    pub paper_scale: bool,
    /// Only the settings whose name contains this (e.g. "screened"); the table and
    /// plot then hold just those points.
    #[arg(long)]
    pub only: Option<String>,
    /// Mask families to sweep (default: all three).
    #[arg(long, value_delimiter = ',')]
    pub masks: Vec<Family>,
    /// The device's frame figure to add to bench.md: the CSV `scripts/budgets.sh` writes
    /// (target/device-frame.csv), projected seconds for a 100 x 100-lenslet frame.
    #[arg(long, value_name = "CSV")]
    pub device: Option<PathBuf>,
    /// Instead of sweeping: draw bench.md and bench.png again from a bench.csv this command
    /// wrote (e.g. with `--device`). Its bench.csv is copied to --out byte for byte; it may
    /// be the bench.csv of --out, which is then left as it is.
    #[arg(long, value_name = "CSV")]
    pub from: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    if args.paper_scale {
        outln!("{}", bench::paper_scale()?)?;
        return Ok(());
    }
    // The device's file is read before the sweep, so a bad one costs no sweep.
    let device = args.device.as_deref().map(device_frame::read).transpose()?.unwrap_or_default();
    let n = if let Some(csv) = &args.from {
        bench::redraw(csv, &device, &args.out)?
    } else {
        let masks = args.masks.iter().map(|m| m.family()).collect();
        let opts = BenchOptions { quick: args.quick, progress: true, only: args.only, masks };
        let points = bench::run(&opts)?;
        bench::write(&points, &device, &args.out)?;
        points.len()
    };
    outln!("{n} points; wrote {}/bench.csv, bench.md, bench.png", args.out.display())?;
    Ok(())
}
