//! `slf bench`: speed against error. Sweeps solver settings, bases, masks and k; writes CSV,
//! markdown and a plot (or, with `--paper-scale`, the paper's scale end to end).

use std::path::PathBuf;

use anyhow::Result;
use slf_host::eval::bench::{self, BenchOptions};

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
}

pub fn run(args: Args) -> Result<()> {
    if args.paper_scale {
        println!("{}", bench::paper_scale()?);
        return Ok(());
    }
    let masks = args.masks.iter().map(|m| m.family()).collect();
    let opts = BenchOptions { quick: args.quick, progress: true, only: args.only, masks };
    let points = bench::run(&opts)?;
    bench::write(&points, &args.out)?;
    println!("{} points; wrote {}/bench.csv, bench.md, bench.png", points.len(), args.out.display());
    Ok(())
}
