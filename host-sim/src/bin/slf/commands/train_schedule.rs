//! `slf train-schedule`: learn the trained schedules of an ensemble's solves (SL0 unrolled,
//! its per-step parameters learned) into a blob that carries them.

use std::path::PathBuf;

use anyhow::Result;
use slf_host::decode::cs::read_blob;
use slf_host::io::output::Outputs;
use slf_host::train::schedule::{ScheduleConfig, train_schedule_blob};
use slf_host::train::{self, Generator};

use crate::args::ranged;

#[derive(clap::Args)]
pub struct Args {
    /// The ensemble's blob (version 1, or 2 whose schedules are trained anew).
    pub blob: PathBuf,
    /// Output blob: the ensemble with its schedules (format version 2).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Steps of the cold schedule (a solve from the measurements alone), 1..=64.
    #[arg(long, default_value_t = ScheduleConfig::default().cold_steps, value_parser = ranged::<1, 64>)]
    pub cold_steps: usize,
    /// Steps of the warm schedule (a solve from another member's solution or a seed), 1..=64.
    #[arg(long, default_value_t = ScheduleConfig::default().warm_steps, value_parser = ranged::<1, 64>)]
    pub warm_steps: usize,
    /// Realistic training scenes to render, 1..=1000.
    #[arg(long, default_value_t = 24, value_parser = ranged::<1, 1000>)]
    pub scenes: usize,
    /// Spatial size of each training scene, 5..=1024.
    #[arg(long, default_value_t = 40, value_parser = ranged::<5, 1024>)]
    pub size: usize,
    /// Training patches, 1..=100000.
    #[arg(long, default_value_t = ScheduleConfig::default().patches, value_parser = ranged::<1, 100_000>)]
    pub patches: usize,
    /// Adam iterations per schedule, 0..=100000.
    #[arg(long, default_value_t = ScheduleConfig::default().iterations, value_parser = ranged::<0, 100_000>)]
    pub iterations: usize,
    /// Patches per iteration, 1..=100000.
    #[arg(long, default_value_t = ScheduleConfig::default().batch, value_parser = ranged::<1, 100_000>)]
    pub batch: usize,
    /// Seed of the scenes, patches, masks and batches.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Steps of the alone schedule (a dictionary decoding alone: the preview's DCT), 1..=64.
    #[arg(long, default_value_t = ScheduleConfig::default().alone_steps, value_parser = ranged::<1, 64>)]
    pub alone_steps: usize,
}

pub fn run(args: Args) -> Result<()> {
    let Args { blob, output, cold_steps, warm_steps, scenes, size, patches, iterations, batch, seed, alone_steps } =
        args;
    Outputs::new().inputs(std::slice::from_ref(&blob), "BLOB").output(&output, "-o").check()?;
    let bytes = read_blob(&blob)?;
    let cfg = ScheduleConfig {
        cold_steps,
        warm_steps,
        patches,
        iterations,
        batch,
        seed,
        alone_steps,
        progress: true,
        ..Default::default()
    };
    train::check_training_memory(scenes, size, patches)?;
    let fields: Vec<_> = train::training_fields(scenes, size, 1000 + seed, Generator::Realistic)
        .iter()
        .map(train::white_balanced)
        .collect();
    train_schedule_blob(&bytes, &fields, &cfg, &output)
}
