//! `slf baseline`: the paper's 1D method against the 5D decoder on the same patches, time
//! and memory.

use anyhow::Result;
use slf_host::decode::paper_1d;

use crate::args::{Family, ranged};

#[derive(clap::Args)]
pub struct Args {
    /// Patches (each a fresh measurement of a test patch), 1..=1000.
    #[arg(long, default_value_t = 3, value_parser = ranged::<1, 1000>)]
    pub patches: usize,
    /// Mask family.
    #[arg(long, value_enum, default_value_t = Family::Pixel)]
    pub mask: Family,
    /// Snapshots k (1..=13).
    #[arg(short, long, default_value_t = 1)]
    pub snapshots: u8,
}

pub fn run(args: Args) -> Result<()> {
    paper_1d::compare_1d(args.patches, args.mask.family(), args.snapshots)
}
