//! `slf train`: learn a dictionary ensemble from light fields (or rendered training scenes)
//! into a firmware blob.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;
use slf_host::io::lightfield::read_npy;
use slf_host::io::output::Outputs;
use slf_host::train;

use crate::args::ranged;
use slf_host::decode::cs::PatchViews;
use slf_host::decode::settings::{WhiteBalance, patch_views};

#[derive(clap::Args)]
pub struct Args {
    /// Output blob (the firmware's format).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Training light fields (.npy); without them, random training scenes are rendered.
    #[arg(long, num_args = 1..)]
    pub input: Vec<PathBuf>,
    /// Random training scenes to render when no --input is given, 1..=1000.
    #[arg(long, default_value_t = 48, value_parser = ranged::<1, 1000>)]
    pub scenes: usize,
    /// Spatial size of each rendered training scene, 5..=1024.
    #[arg(long, default_value_t = 60, value_parser = ranged::<5, 1024>)]
    pub size: usize,
    /// Patches sampled for training, 1..=1000000.
    #[arg(long, default_value_t = 20_000, value_parser = ranged::<1, 1_000_000>)]
    pub patches: usize,
    /// Members K, 1..=256.
    #[arg(long, default_value_t = 8, value_parser = ranged::<1, 256>)]
    pub members: usize,
    /// Coefficients kept per patch when coding, 1..=5200 (8125 for the full-view patch).
    #[arg(long, default_value_t = 100, value_parser = ranged::<1, 8125>)]
    pub tau: usize,
    /// Views per axis of the patch the ensemble is for, 4 or 5: the paper's 5 x 5 x 4 x 4 x
    /// 13 patch, or the full-view 5 x 5 x 5 x 5 x 13 one.
    #[arg(long, value_parser = patch_views, value_name = "4|5", default_value = "4")]
    pub patch_views: PatchViews,
    /// Training iterations (assign patches to members, update each member), 0..=1000.
    #[arg(long, default_value_t = 10, value_parser = ranged::<0, 1000>)]
    pub iterations: usize,
    /// Patches per member for the HOSVD initialisation, 1..=100000.
    #[arg(long, default_value_t = 32, value_parser = ranged::<1, 100_000>)]
    pub group: usize,
    /// Seed of the patch sampling, initialisation and rendered scenes.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Learn every member (by default member 0 is the fixed 5D DCT).
    #[arg(long)]
    pub no_dct_member: bool,
    /// Scene generator for the rendered training scenes: realistic (slanted and curved
    /// surfaces, 1/f textures, measured spectra, five illuminants) or toy (the first
    /// ensemble's cards of chart colours under D65).
    #[arg(long, value_enum, default_value_t = GeneratorArg::Realistic)]
    pub generator: GeneratorArg,
    /// White balance of the training light fields, as the decoder balances a capture
    /// (grey: each band divided by its mean over the light field).
    #[arg(long, value_enum, default_value_t = WhiteBalance::Grey)]
    pub balance: WhiteBalance,
}

pub fn run(args: Args) -> Result<()> {
    let Args {
        output,
        input,
        scenes,
        size,
        patches,
        members,
        tau,
        iterations,
        group,
        seed,
        no_dct_member,
        generator,
        balance,
        patch_views,
    } = args;
    Outputs::new().inputs(&input, "--input").output(&output, "-o").check()?;
    let cfg = train::TrainConfig { members, tau, iterations, group, seed, dct_member: !no_dct_member, progress: true };
    let fields = if input.is_empty() {
        let generator = match generator {
            GeneratorArg::Realistic => train::Generator::Realistic,
            GeneratorArg::Toy => train::Generator::Toy,
        };
        train::check_training_memory(scenes, size, patches)?;
        train::training_fields(scenes, size, 1000 + seed, generator)
    } else {
        input.iter().map(|p| read_npy(p)).collect::<Result<Vec<_>, _>>()?
    };
    let fields = match balance {
        WhiteBalance::Grey => fields.iter().map(train::white_balanced).collect(),
        WhiteBalance::Off => fields,
    };
    train::train_blob(&fields, patches, patch_views, &cfg, &output)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GeneratorArg {
    /// Slanted and curved surfaces, 1/f textures, measured spectra, five illuminants.
    Realistic,
    /// Fronto-parallel cards of chart colours and narrow bands under D65.
    Toy,
}
