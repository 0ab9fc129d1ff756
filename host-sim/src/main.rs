//! `slf`: simulate captures of the compressive spectral light-field camera, decode them
//! with the firmware decoder, and measure the result. `slf --help` lists the commands.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use slf_host::camera::{CameraConfig, simulate};
use slf_host::capture::{Capture, MaskDescription};
use slf_host::decode::{Balance, Basis, DecodeOptions, NoiseSource, decode_with, read_blob};
use slf_host::demosaic::Baseline;
use slf_host::firmware::{ChoiceRule, DEFAULT_ENSEMBLE, MaskFamily, MemberChoice, Sl0Config};
use slf_host::lightfield::{Dtype, read_npy, write_npy};
use slf_host::metrics::evaluate;
use slf_host::scene::{self, SceneSize};
use slf_host::{baseline, report, train};

#[derive(Parser)]
#[command(name = "slf", version, about = "Compressive spectral light-field camera: simulate, decode, measure")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// A whole number in `LO..=HI`, for clap: the error names the range (clap names the argument).
fn ranged<const LO: usize, const HI: usize>(s: &str) -> Result<usize, String> {
    let v: usize = s.parse().map_err(|_| format!("{s:?} is not a whole number in {LO}..={HI}"))?;
    if (LO..=HI).contains(&v) { Ok(v) } else { Err(format!("{v} is out of range {LO}..={HI}")) }
}

/// A finite number above zero, for clap.
fn positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number above 0")),
    }
}

/// A finite number at or above zero, for clap.
/// `MIN:MAX[:STEP]`, integer disparities around 0 (e.g. `-1:1`) within the decoder's
/// limit, in steps of 1 (the default) or 0.5.
fn disparity_range(s: &str) -> Result<slf_host::firmware::DisparityRange, String> {
    let bad = || {
        let m = slf_host::firmware::disparity::MAX_DISPARITY;
        format!(
            "{s:?}: want MIN:MAX[:STEP], integers with -{m} <= MIN <= 0 <= MAX <= {m} and a step of 1 or 0.5 (e.g. -1:1:0.5)"
        )
    };
    let mut parts = s.split(':');
    let (Some(a), Some(b), step, None) = (parts.next(), parts.next(), parts.next(), parts.next()) else {
        return Err(bad());
    };
    let (a, b) = (a.trim().parse::<i8>().map_err(|_| bad())?, b.trim().parse::<i8>().map_err(|_| bad())?);
    let halves = match step.map(str::trim) {
        None | Some("1") => false,
        Some("0.5") | Some(".5") => true,
        Some(_) => return Err(bad()),
    };
    slf_host::firmware::DisparityRange::new(a, b).map(|r| r.with_halves(halves)).ok_or_else(bad)
}

fn non_negative(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number at or above 0")),
    }
}

/// A fraction in `[0, 1)`, for clap.
fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => Err(format!("{s:?} is not a fraction in [0, 1)")),
    }
}

/// The frame file format `slf simulate` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum FrameFormat {
    /// Binary 16-bit PGM (P5).
    Pgm,
    /// 16-bit grey PNG.
    Png,
    /// uint16 `.npy`, 2 axes.
    Npy,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Family {
    Pixel,
    Lenslet,
    Kronecker,
}

impl Family {
    fn family(self) -> MaskFamily {
        match self {
            Family::Pixel => MaskFamily::Pixel,
            Family::Lenslet => MaskFamily::Lenslet,
            Family::Kronecker => MaskFamily::Kronecker,
        }
    }

    fn mask(self, seed: u64, k: u8) -> MaskDescription {
        MaskDescription::seeded(self.family(), seed, k)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    /// Compressed sensing: the firmware's SL0 decoder with --dictionary.
    Cs,
    /// Baseline: per pixel, the spectrum interpolated between the bands it measured.
    Interpolate,
    /// Baseline: each band from the nearby pixels and views that measured it, matched to
    /// each pixel's own measurements.
    Demosaic,
    /// Baseline: PPID, demosaicking by the pseudo-panchromatic image (Mihoubi et al. 2017).
    Ppid,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum GeneratorArg {
    /// Slanted and curved surfaces, 1/f textures, measured spectra, five illuminants.
    Realistic,
    /// Fronto-parallel cards of chart colours and narrow bands under D65.
    Toy,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum WindowArg {
    /// Every value of a patch counts the same.
    Uniform,
    /// Lenslets weigh 1, 2, 3, 2, 1 across a patch (per axis, multiplied).
    Tapered,
}

impl WindowArg {
    fn window(self) -> slf_host::decode::Window {
        match self {
            WindowArg::Uniform => slf_host::decode::Window::Uniform,
            WindowArg::Tapered => slf_host::decode::Window::Tapered,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum DictionaryKind {
    /// The 5D DCT.
    Dct,
    /// A learned ensemble (the shipped one unless --blob says otherwise).
    Ensemble,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Choice {
    /// Solve with the DCT, pick the member that best represents it, solve with that (2
    /// solves); where the DCT's own solution is sparser, average the two.
    Screened,
    /// As screened, but where the DCT's own solution is sparser, solve with the DCT again
    /// from the member's solution (3 solves).
    ScreenedResolve,
    /// Solve with every member, keep the sparsest (K + 1 solves).
    Exhaustive,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Rule {
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

#[derive(clap::Args, Clone, Debug)]
struct BasisArgs {
    /// Basis to decode with.
    #[arg(long, value_enum, default_value_t = DictionaryKind::Ensemble)]
    dictionary: DictionaryKind,
    /// How an ensemble member is chosen per patch.
    #[arg(long, value_enum, default_value_t = Choice::Screened)]
    choice: Choice,
    /// Ensemble blob (default: the shipped 8-member ensemble).
    #[arg(long)]
    blob: Option<PathBuf>,
}

impl BasisArgs {
    fn basis(&self) -> Result<Basis> {
        Ok(match self.dictionary {
            DictionaryKind::Dct => Basis::Dct,
            DictionaryKind::Ensemble => {
                let blob = match &self.blob {
                    Some(p) => read_blob(p)?,
                    None => DEFAULT_ENSEMBLE.to_vec(),
                };
                let rule = ChoiceRule::DEFAULT;
                let choice = match self.choice {
                    Choice::Screened => MemberChoice::Screened(rule),
                    Choice::ScreenedResolve => MemberChoice::ScreenedResolve(rule),
                    Choice::Exhaustive => MemberChoice::Exhaustive(rule),
                };
                Basis::Ensemble { blob, choice }
            }
        })
    }
}

#[derive(clap::Args, Clone, Debug)]
struct SolverArgs {
    /// SL0 sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_f)]
    sigma_f: f32,
    /// SL0 steps per sigma level (L).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.steps)]
    steps: u16,
    /// SL0 step size mu.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.mu)]
    mu: f32,
    /// SL0 smallest sigma (normalised units, white = 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_min)]
    sigma_min: f32,
    /// Hard bound on SL0 steps per patch.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.max_iterations)]
    max_iterations: u32,
    /// Noise standard deviation per measurement (normalised units), instead of the
    /// capture's noise description; 0 (with no --shot) forces equality.
    #[arg(long, conflicts_with = "exact")]
    noise: Option<f32>,
    /// Shot noise: variance per unit of a measurement's value (normalised units, 1 /
    /// electrons at white), instead of the capture's noise description.
    #[arg(long, conflicts_with = "exact")]
    shot: Option<f32>,
    /// Exact projection: the decode equals the measurements, whatever noise the capture
    /// describes. Without --exact, --noise or --shot the noise ball comes from the capture.
    #[arg(long)]
    exact: bool,
    /// Early stop: end a patch's solve once a sigma level moves it by less than this RMS
    /// per value (normalised units); 0 never stops early.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.tolerance)]
    tolerance: f32,
    /// The ensemble's second solve starts from the DCT's patch at this fraction of its
    /// largest coefficient, in (0, 1]; 1 is a cold start.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_start)]
    warm_start: f32,
    /// The warm solve's sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_sigma_f)]
    warm_sigma_f: f32,
    /// The warm solve's steps per sigma level.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_steps)]
    warm_steps: u16,
    /// Short path: a patch whose measurements of each band agree within this (normalised
    /// units) is decoded as each band's mean, with no solve; 0: exactly flat patches only.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.flat)]
    flat: f32,
    /// A patch whose measurements cover fewer distinct bands than this (a kronecker mask's
    /// patch sees k, or up to 4k across mask blocks) is interpolated per pixel instead of
    /// solved; 0 solves every patch (the paper's decode).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.min_bands)]
    min_bands: u8,
}

impl SolverArgs {
    /// Where the noise ball comes from: the capture unless told.
    fn noise_source(&self) -> NoiseSource {
        if self.exact || self.noise.is_some() || self.shot.is_some() {
            NoiseSource::Config
        } else {
            NoiseSource::Capture
        }
    }

    fn config(&self) -> Result<Sl0Config> {
        let c = Sl0Config {
            sigma_f: self.sigma_f,
            steps: self.steps,
            mu: self.mu,
            sigma_min: self.sigma_min,
            max_iterations: self.max_iterations,
            noise: self.noise.unwrap_or(0.0),
            shot: self.shot.unwrap_or(0.0),
            tolerance: self.tolerance,
            warm_start: self.warm_start,
            warm_sigma_f: self.warm_sigma_f,
            warm_steps: self.warm_steps,
            flat: self.flat,
            min_bands: self.min_bands,
        };
        c.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(c)
    }
}

/// `--balance`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum BalanceArg {
    /// Each band's mean over the frame (grey world).
    Grey,
    /// No white balance (gains of 1).
    Off,
}

impl BalanceArg {
    fn balance(self) -> Balance {
        match self {
            Self::Grey => Balance::GreyWorld,
            Self::Off => Balance::Off,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a default scene with the pixel mask at k = 1 and k = 3, decode, report, preview.
    Demo {
        /// Where previews and files go.
        #[arg(long, default_value = "slf-demo")]
        out: PathBuf,
        /// Named scene (smooth, texture, depth, saturated, dark).
        #[arg(long, default_value = "depth")]
        scene: String,
        /// Spatial size (lenslets per side), 5..=2048.
        #[arg(long, default_value_t = 100, value_parser = ranged::<5, 2048>)]
        size: usize,
        #[command(flatten)]
        basis: BasisArgs,
    },
    /// Write a named test scene or a random training scene as a (U, V, H, W, B) .npy.
    Scene {
        /// A name (test scenes: smooth, texture, depth, saturated, dark; realistic: outdoor,
        /// tungsten, office, led), `random` (the training scenes of the shipped ensemble) or
        /// `realistic` (slanted and curved surfaces, 1/f textures, measured spectra, five
        /// illuminants), the last two drawn from --seed.
        name: String,
        /// Output .npy file.
        #[arg(short, long)]
        output: PathBuf,
        /// Seed of a random scene.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Spatial rows and columns, 1..=4096.
        #[arg(long, default_value_t = 100, value_parser = ranged::<1, 4096>)]
        size: usize,
        /// Views per side, 1..=16.
        #[arg(long, default_value_t = 5, value_parser = ranged::<1, 16>)]
        views: usize,
        /// Stored dtype.
        #[arg(long, value_enum, default_value_t = Dtype::F32)]
        dtype: Dtype,
    },
    /// Real data in: views, hyperspectral cubes, other light fields, as a (U, V, H, W, 13)
    /// light field .npy.
    Import {
        #[command(subcommand)]
        source: ImportSource,
    },
    /// Record a light field with the camera model: writes a capture folder.
    Simulate {
        /// Light field .npy (U, V, H, W, B): 13 bands, or any other count with --wavelengths.
        input: PathBuf,
        /// Wavelengths of the light field's bands when it does not have the camera's 13
        /// (START:STOP:STEP or a comma list, nm): resampled over the camera's band filters.
        #[arg(long)]
        wavelengths: Option<String>,
        /// Capture folder to write.
        #[arg(short, long)]
        output: PathBuf,
        /// Mask family: which band each pixel sees in each snapshot.
        #[arg(long, value_enum, default_value_t = Family::Pixel)]
        mask: Family,
        /// Snapshots k (1..=13).
        #[arg(short, long, default_value_t = 1)]
        snapshots: u8,
        /// Seed of the mask, noise and defects.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Read noise, DN (finite, at or above 0).
        #[arg(long, default_value_t = 2.0, value_parser = non_negative)]
        read_noise: f32,
        /// Electrons at white (shot noise); finite, above 0.
        #[arg(long, default_value_t = 20_000.0, value_parser = positive)]
        full_well: f32,
        /// No shot or read noise.
        #[arg(long)]
        no_noise: bool,
        /// Fraction of defective pixels, in [0, 1).
        #[arg(long, default_value_t = 0.0, value_parser = fraction)]
        defects: f64,
        /// Frame file format.
        #[arg(long, value_enum, default_value_t = FrameFormat::Pgm)]
        format: FrameFormat,
    },
    /// Decode a capture folder into a light field .npy.
    Decode {
        /// Capture folder (capture.json and frames).
        capture: PathBuf,
        /// Output .npy file.
        #[arg(short, long)]
        output: PathBuf,
        /// Decode method: compressed sensing, or a baseline without it.
        #[arg(long, value_enum, default_value_t = Method::Cs)]
        method: Method,
        #[command(flatten)]
        solver: SolverArgs,
        #[command(flatten)]
        basis: BasisArgs,
        /// Also write which ensemble member each patch used (CSV: the patch's origin, the
        /// disparity it was sheared to, the member).
        #[arg(long)]
        member_map: Option<PathBuf>,
        /// Lenslets between patch origins, 1..=5 (5: disjoint patches, which show their
        /// grid; smaller strides decode (5 / stride)^2 times the patches and average them).
        #[arg(long, default_value_t = 3, value_parser = ranged::<1, 5>)]
        stride: usize,
        /// How overlapping patches are averaged.
        #[arg(long, value_enum, default_value_t = WindowArg::Tapered)]
        window: WindowArg,
        /// With a stride below 5: decode a shifted patch only where a first pass on the
        /// disjoint grid shows a seam inside it, steps across the grid's borders more than
        /// this many times those between its other lenslets.
        #[arg(long)]
        adaptive: Option<f32>,
        /// White balance: each band divided by a gain before the solve and multiplied back
        /// (grey: each band's mean over the frame, as the device does it).
        #[arg(long, value_enum, default_value_t = BalanceArg::Grey)]
        balance: BalanceArg,
        /// The 13 band gains, comma-separated (e.g. from a white reference); replaces
        /// --balance.
        #[arg(long, value_delimiter = ',', value_name = "G1,...,G13")]
        gains: Option<Vec<f32>>,
        /// Disparities (pixels per view step) each 5 x 5-lenslet block may be sheared to
        /// before decoding, MIN:MAX[:STEP] (default -1:1:0.5 for a single snapshot, -1:1 for
        /// more; 0:0 decodes unsheared; a STEP of 0.5 adds the half-pixel shears, whose
        /// measurements interpolate the patch); chosen per block by how well the views'
        /// same-band samples agree.
        #[arg(long, value_parser = disparity_range, value_name = "MIN:MAX[:STEP]", allow_hyphen_values = true)]
        disparities: Option<slf_host::firmware::DisparityRange>,
        /// Also write the chosen disparity per lenslet (.npy, lenslet rows x cols, f32: the
        /// mean over the blocks that cover it); not with --disparities 0:0.
        #[arg(long)]
        disparity_map: Option<PathBuf>,
        /// Stored dtype.
        #[arg(long, value_enum, default_value_t = Dtype::F32)]
        dtype: Dtype,
        /// No progress bar.
        #[arg(short, long)]
        quiet: bool,
    },
    /// PSNR, SSIM and spectral angle of a reconstruction against the ground truth.
    Eval {
        /// The ground truth light field, (U, V, H, W, B) .npy.
        truth: PathBuf,
        /// The reconstruction, same shape.
        recon: PathBuf,
    },
    /// The paper's 1D method against the 5D decoder on the same patches: time and memory.
    Baseline {
        /// Patches (each a fresh measurement of a test patch), 1..=1000.
        #[arg(long, default_value_t = 3, value_parser = ranged::<1, 1000>)]
        patches: usize,
        /// Mask family.
        #[arg(long, value_enum, default_value_t = Family::Pixel)]
        mask: Family,
        /// Snapshots k (1..=13).
        #[arg(short, long, default_value_t = 1)]
        snapshots: u8,
    },
    /// Learn a dictionary ensemble from light fields (or random training scenes); writes a blob.
    Train {
        /// Output blob (the firmware's format).
        #[arg(short, long)]
        output: PathBuf,
        /// Training light fields (.npy); without them, random training scenes are rendered.
        #[arg(long, num_args = 1..)]
        input: Vec<PathBuf>,
        /// Random training scenes to render when no --input is given, 1..=1000.
        #[arg(long, default_value_t = 48, value_parser = ranged::<1, 1000>)]
        scenes: usize,
        /// Spatial size of each rendered training scene, 5..=1024.
        #[arg(long, default_value_t = 60, value_parser = ranged::<5, 1024>)]
        size: usize,
        /// Patches sampled for training, 1..=1000000.
        #[arg(long, default_value_t = 20_000, value_parser = ranged::<1, 1_000_000>)]
        patches: usize,
        /// Members K, 1..=256.
        #[arg(long, default_value_t = 8, value_parser = ranged::<1, 256>)]
        members: usize,
        /// Coefficients kept per patch when coding, 1..=5200.
        #[arg(long, default_value_t = 100, value_parser = ranged::<1, 5200>)]
        tau: usize,
        /// Training iterations (assign patches to members, update each member), 0..=1000.
        #[arg(long, default_value_t = 10, value_parser = ranged::<0, 1000>)]
        iterations: usize,
        /// Patches per member for the HOSVD initialisation, 1..=100000.
        #[arg(long, default_value_t = 32, value_parser = ranged::<1, 100_000>)]
        group: usize,
        /// Seed of the patch sampling, initialisation and rendered scenes.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Learn every member (by default member 0 is the fixed 5D DCT).
        #[arg(long)]
        no_dct_member: bool,
        /// Scene generator for the rendered training scenes: realistic (slanted and curved
        /// surfaces, 1/f textures, measured spectra, five illuminants) or toy (the first
        /// ensemble's cards of chart colours under D65).
        #[arg(long, value_enum, default_value_t = GeneratorArg::Realistic)]
        generator: GeneratorArg,
        /// White balance of the training light fields, as the decoder balances a capture
        /// (grey: each band divided by its mean over the light field).
        #[arg(long, value_enum, default_value_t = BalanceArg::Grey)]
        balance: BalanceArg,
    },
    /// PSNR / SSIM / SA of every test scene x mask family x k, decoded with --dictionary
    /// (default: the shipped ensemble, screened); a markdown table.
    Sweep {
        /// Spatial size (lenslets per side), 5..=1024.
        #[arg(long, default_value_t = 60, value_parser = ranged::<5, 1024>)]
        size: usize,
        /// Snapshot counts.
        #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
        k: Vec<u8>,
        /// Also write the table to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[command(flatten)]
        basis: BasisArgs,
    },
    /// Speed against error: sweep solver settings, bases, masks and k; CSV, markdown, PNG.
    Bench {
        /// Output folder (bench.csv, bench.md, bench.png).
        #[arg(short, long, default_value = "slf-bench")]
        out: PathBuf,
        /// A CI-sized run: two small scenes, k = 3, no exhaustive choice.
        #[arg(long)]
        quick: bool,
        /// Instead of the sweep: the paper's scale end to end (512 x 512 x 5 x 5 x 13).
        #[arg(long)]
        paper_scale: bool,
        /// Only the settings whose name contains this (e.g. "screened"); the table and
        /// plot then hold just those points.
        #[arg(long)]
        only: Option<String>,
        /// Mask families to sweep (default: all three).
        #[arg(long, value_delimiter = ',')]
        masks: Vec<Family>,
    },
    /// Every baseline, the DCT and the ensemble on the given light fields at pixel k = 1, 3
    /// and lenslet k = 3: PSNR / SSIM / SA and ms per patch per scene and mean (table.md),
    /// and previews of a zoomed crop at pixel k = 1.
    Evaluate {
        /// Light fields, (U, V, H, W, 13) .npy; each is named by its file stem.
        #[arg(required = true, num_args = 1..)]
        inputs: Vec<PathBuf>,
        /// Output folder (table.md and previews).
        #[arg(short, long, default_value = "slf-evaluate")]
        out: PathBuf,
        /// Ensemble blob (default: the shipped one).
        #[arg(long)]
        blob: Option<PathBuf>,
        /// Also decode with overlapping patches at these strides (1..=4 lenslets), as
        /// extra rows for the DCT and the ensemble (default: the decoder's default, 3).
        #[arg(long, value_delimiter = ',', value_parser = ranged::<1, 4>, default_value = "3")]
        stride: Vec<usize>,
        /// How overlapping patches are averaged in those rows.
        #[arg(long, value_enum, default_value_t = WindowArg::Tapered)]
        window: WindowArg,
    },
    /// Write the capture the device binary decodes (frames as .npy and `capture.rs` constants).
    DeviceCapture {
        /// Folder (firmware/device).
        #[arg(short, long, default_value = "firmware/device")]
        output: PathBuf,
    },
    /// Compare the device binary's output (its semihosting log) with the host's decode of
    /// the same tiles; fails above 1e-5 relative difference.
    DeviceCheck {
        /// The device's output.
        log: PathBuf,
        /// The capture it decoded.
        #[arg(long, default_value = "firmware/device/capture")]
        capture: PathBuf,
    },
    /// Mean PSNR / SSIM / SA over the test scenes for {DCT, ensemble exhaustive, ensemble
    /// screened} x {pixel, lenslet, kronecker} x k, and time per patch; a markdown table.
    Compare {
        /// Spatial size (lenslets per side), 5..=1024.
        #[arg(long, default_value_t = 40, value_parser = ranged::<5, 1024>)]
        size: usize,
        /// Snapshot counts.
        #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
        k: Vec<u8>,
        /// Also write the table to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Ensemble blob (default: the shipped one).
        #[arg(long)]
        blob: Option<PathBuf>,
        /// Only these mask families (default: all three).
        #[arg(long, value_enum, value_delimiter = ',')]
        masks: Vec<Family>,
        /// Member-choice rule.
        #[arg(long, value_enum, default_value_t = Rule::Residual)]
        rule: Rule,
        /// Coefficients kept by the residual rule.
        #[arg(long, default_value_t = 100)]
        rule_tau: u16,
    },
}

/// `slf decode` warns when more than this fraction of patches failed or were flagged.
const WARN_FRACTION: f64 = 0.01;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                eprintln!(
                    "error: a command is required: demo, scene, simulate, decode, eval, baseline or sweep (see `slf --help`)"
                );
                return ExitCode::from(2);
            }
            // One readable line: clap's first line (its message), without usage and tips.
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("error: invalid arguments");
            eprintln!("{first} (see `slf --help`)");
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output went away (`| head`): it has what it wanted.
        Err(e) if e.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe) => {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Demo { out, scene, size, basis } => report::demo(&out, &scene, size, &basis.basis()?),
        Command::Scene { name, output, seed, size, views, dtype } => {
            let s = match name.as_str() {
                "random" => scene::random(seed),
                "realistic" => slf_host::realistic::realistic(seed),
                _ => slf_host::realistic::lookup(&name).with_context(|| {
                    format!(
                        "unknown scene {name:?}: one of {:?}, {:?}, random or realistic",
                        scene::NAMES,
                        slf_host::realistic::NAMES
                    )
                })?,
            };
            let size = SceneSize { views: (views, views), rows: size, cols: size };
            size.check().map_err(|e| anyhow::anyhow!("--size {} with --views {views}: {e}", size.rows))?;
            let lf = s.render(size);
            write_npy(&output, &lf, dtype)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
        Command::Import { source } => import_command(source),
        Command::Simulate {
            input,
            wavelengths,
            output,
            mask,
            snapshots,
            seed,
            read_noise,
            full_well,
            no_noise,
            defects,
            format,
        } => {
            let lf = with_camera_bands(read_npy(&input)?, wavelengths.as_deref(), &input)?;
            let mut cam = CameraConfig::pixel(seed, snapshots).with_mask(mask.mask(seed, snapshots));
            cam.read_noise = read_noise;
            cam.full_well = Some(full_well);
            cam.defect_fraction = defects;
            cam.frame_ext = format!("{format:?}").to_lowercase();
            if no_noise {
                cam = cam.noiseless();
            }
            let capture = simulate(&lf, &cam).map_err(|e| anyhow::anyhow!("{}: {e:#}", input.display()))?;
            let (clipped, total) = capture.saturated_pixels();
            if clipped > 0 {
                eprintln!(
                    "warning: {}: {clipped} of {total} pixels ({:.2} %) saturated: the light field exceeds white \
                     (max {:.3}, clips at {:.3}); saturated pixels are not measurements",
                    input.display(),
                    100.0 * clipped as f64 / total as f64,
                    lf.max(),
                    1.0 / cam.white_fraction
                );
            }
            capture.save(&output)?;
            println!("wrote {} ({} snapshots)", output.display(), capture.frames.len());
            Ok(())
        }
        Command::Decode {
            capture,
            output,
            method,
            solver,
            basis,
            member_map,
            stride,
            window,
            adaptive,
            balance,
            gains,
            disparities,
            disparity_map,
            dtype,
            quiet,
        } => {
            let cap = Capture::load(&capture)?;
            let balance = match gains {
                Some(g) => {
                    let g: [f32; 13] =
                        g.try_into().map_err(|g: Vec<f32>| anyhow::anyhow!("--gains: 13 values, got {}", g.len()))?;
                    anyhow::ensure!(
                        slf_host::firmware::gains::valid(&g),
                        "--gains: every gain must be finite and positive"
                    );
                    Balance::Gains(g)
                }
                None => balance.balance(),
            };
            if method != Method::Cs {
                anyhow::ensure!(member_map.is_none(), "--member-map needs --method cs (baselines use no ensemble)");
                let baseline = match method {
                    Method::Interpolate => Baseline::Interpolate,
                    Method::Ppid => Baseline::Ppid,
                    _ => Baseline::Demosaic,
                };
                let (lf, r) = baseline.run(&cap)?;
                write_npy(&output, &lf, dtype)?;
                println!(
                    "{:?}: {} sensor positions measured, {} filled from their neighbours, in {:.2} s; wrote {}",
                    method,
                    r.measured,
                    r.filled,
                    r.seconds,
                    output.display()
                );
                return Ok(());
            }
            let opts = DecodeOptions {
                sl0: solver.config()?,
                noise: solver.noise_source(),
                progress: !quiet,
                stride: (stride as u8, stride as u8),
                window: window.window(),
                adaptive,
                balance,
                disparities,
                ..DecodeOptions::default()
            };
            anyhow::ensure!(
                disparity_map.is_none() || !opts.disparities_for(&cap).is_off(),
                "--disparity-map needs disparities to search: with --disparities 0:0 every block is at 0"
            );
            if let Some(a) = adaptive {
                anyhow::ensure!(a.is_finite() && a >= 0.0, "--adaptive {a}: must be finite, at or above 0");
            }
            let (lf, r) = decode_with(&cap, &basis.basis()?, &opts)?;
            let p = &r.patches;
            let all = p.decoded + p.failed;
            anyhow::ensure!(
                p.decoded > 0,
                "{}: no patch decoded ({} failed, {} of {} tiles failed): every patch saturated, defective or \
                 unreadable; nothing written",
                capture.display(),
                p.failed,
                r.failed_tiles,
                r.tiles
            );
            if (p.failed + p.flagged) as f64 > WARN_FRACTION * f64::from(all) || r.failed_tiles > 0 {
                eprintln!(
                    "warning: {}: {} of {all} patches failed and {} were flagged (pixels left out), {} tiles failed",
                    capture.display(),
                    p.failed,
                    p.flagged,
                    r.failed_tiles
                );
            }
            if let Some(path) = member_map {
                let mut csv = String::from(
                    "lenslet_row,lenslet_col,view_row,view_col,disparity,member
",
                );
                for (o, m) in &r.member_map {
                    csv += &format!(
                        "{},{},{},{},{},{m}
",
                        o.lenslet_row, o.lenslet_col, o.view_row, o.view_col, o.disparity
                    );
                }
                std::fs::write(&path, csv).with_context(|| format!("cannot write {}", path.display()))?;
            }
            if let Some(path) = disparity_map {
                let (rows, cols) = (cap.description.lenslets[0], cap.description.lenslets[1]);
                let map = slf_host::decode::disparity_per_lenslet(&r.disparity_map, rows, cols);
                slf_host::lightfield::write_npy_f32_2d(&path, &map, rows, cols)
                    .with_context(|| format!("cannot write {}", path.display()))?;
            }
            write_npy(&output, &lf, dtype)?;
            let used = opts.solver_config(&cap);
            let ball = match (opts.noise, used.noise > 0.0 || used.shot > 0.0) {
                (_, false) => "exact projection".to_string(),
                (NoiseSource::Capture, true) => {
                    format!("the capture's noise (sd {:.2e} + shot {:.2e} per unit)", used.noise, used.shot)
                }
                (NoiseSource::Config, true) => format!("noise sd {:.2e} + shot {:.2e} per unit", used.noise, used.shot),
            };
            println!("projection: {ball}");
            let gains: Vec<String> = r.gains.iter().map(|g| format!("{g:.3}")).collect();
            match balance {
                Balance::Off => println!("white balance: off"),
                Balance::GreyWorld => println!("white balance: grey world, gains {}", gains.join(" ")),
                Balance::Gains(_) => println!("white balance: given gains {}", gains.join(" ")),
            }
            if !opts.disparities_for(&cap).is_off() {
                let mut counts = std::collections::BTreeMap::<slf_host::firmware::disparity::Disparity, usize>::new();
                for (_, d) in &r.disparity_map {
                    *counts.entry(*d).or_default() += 1;
                }
                let counts: Vec<String> = counts
                    .iter()
                    .map(|(d, n)| format!("{}{d}: {n}", if d.in_halves() > 0 { "+" } else { "" }))
                    .collect();
                println!(
                    "disparity: blocks per disparity {}; {} values of views no sheared patch reached, from their lenslet's other views",
                    counts.join(", "),
                    r.filled
                );
            }
            println!(
                "decoded {} patches ({} flagged, {} failed, {} tiles failed) in {:.2} s; wrote {}",
                r.patches.decoded,
                r.patches.flagged,
                r.patches.failed,
                r.failed_tiles,
                r.seconds,
                output.display()
            );
            Ok(())
        }
        Command::Eval { truth, recon } => {
            let m = evaluate(&read_npy(&truth)?, &read_npy(&recon)?)?;
            // Written, not `println!`: a reader that stops early (`slf eval A B | head -1`)
            // closes the pipe, and `println!` panics on that.
            use std::io::Write;
            let mut out = std::io::stdout().lock();
            writeln!(out, "PSNR {:.3} dB (data range {:.6} = max of ground truth)", m.psnr, m.data_range)?;
            writeln!(out, "SSIM {:.4}", m.ssim)?;
            writeln!(out, "SA   {:.3} deg", m.sa)?;
            Ok(())
        }
        Command::Baseline { patches, mask, snapshots } => baseline::compare_1d(patches, mask.family(), snapshots),
        Command::Bench { paper_scale: true, .. } => {
            println!("{}", slf_host::bench::paper_scale()?);
            Ok(())
        }
        Command::Bench { out, quick, only, masks, .. } => {
            let masks = masks.iter().map(|m| m.family()).collect();
            let opts = slf_host::bench::BenchOptions { quick, progress: true, only, masks };
            let points = slf_host::bench::run(&opts)?;
            slf_host::bench::write(&points, &out)?;
            println!("{} points; wrote {}/bench.csv, bench.md, bench.png", points.len(), out.display());
            Ok(())
        }
        Command::DeviceCapture { output } => slf_host::device::write_capture(&output),
        Command::DeviceCheck { log, capture } => slf_host::device::check(&log, &capture),
        Command::Sweep { size, k, output, basis } => report::sweep(size, &k, output.as_deref(), &basis.basis()?),
        Command::Evaluate { inputs, out, blob, stride, window } => {
            use slf_host::evaluation::{SETTINGS, evaluate_set, table};
            let blob = match blob {
                Some(p) => read_blob(&p)?,
                None => DEFAULT_ENSEMBLE.to_vec(),
            };
            let mut scenes = Vec::new();
            for p in &inputs {
                let name = p.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned());
                scenes.push((name, with_camera_bands(read_npy(p)?, None, p)?));
            }
            let strides: Vec<(u8, u8)> = stride.iter().map(|&s| (s as u8, s as u8)).collect();
            let rows = evaluate_set(&scenes, &SETTINGS, &blob, &strides, window.window(), &out)?;
            let t = table(&rows, &SETTINGS);
            let path = out.join("table.md");
            std::fs::write(&path, &t).with_context(|| format!("cannot write {}", path.display()))?;
            println!("{t}wrote {}", path.display());
            Ok(())
        }
        Command::Compare { size, k, output, blob, masks, rule, rule_tau } => {
            let masks: Vec<MaskFamily> = masks.iter().map(|m| m.family()).collect();
            report::compare(size, &k, output.as_deref(), blob.as_deref(), &masks, rule.rule(rule_tau))
        }
        Command::Train {
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
        } => {
            let cfg = train::TrainConfig {
                members,
                tau,
                iterations,
                group,
                seed,
                dct_member: !no_dct_member,
                progress: true,
            };
            let fields = if input.is_empty() {
                let generator = match generator {
                    GeneratorArg::Realistic => train::Generator::Realistic,
                    GeneratorArg::Toy => train::Generator::Toy,
                };
                train::training_fields(scenes, size, 1000 + seed, generator)
            } else {
                input.iter().map(|p| read_npy(p)).collect::<Result<Vec<_>, _>>()?
            };
            let fields = match balance {
                BalanceArg::Grey => fields.iter().map(train::white_balanced).collect(),
                BalanceArg::Off => fields,
            };
            train::train_blob(&fields, patches, &cfg, &output)
        }
    }
}

/// A pair `A,B` of whole numbers, for clap.
fn pair(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once(',').ok_or_else(|| format!("{s:?} is not a pair A,B"))?;
    let num = |t: &str| t.trim().parse::<usize>().map_err(|_| format!("{t:?} in {s:?} is not a whole number"));
    Ok((num(a)?, num(b)?))
}

/// A window `ROW,COL,ROWS,COLS`, for clap.
fn crop(s: &str) -> Result<slf_host::import::Crop, String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>().map_err(|_| format!("{t:?} in {s:?} is not a whole number")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [row, col, rows, cols] => Ok(slf_host::import::Crop { row, col, rows, cols }),
        _ => Err(format!("{s:?} is not ROW,COL,ROWS,COLS")),
    }
}

/// Where the spatial part of an import is cut and scaled.
#[derive(clap::Args, Clone, Debug)]
struct GeometryArgs {
    /// A window of the input, ROW,COL,ROWS,COLS in input pixels (default: all of it).
    #[arg(long, value_parser = crop)]
    crop: Option<slf_host::import::Crop>,
    /// Size after the crop, ROWS,COLS (area-averaged when shrinking).
    #[arg(long, value_parser = pair)]
    resize: Option<(usize, usize)>,
}

impl GeometryArgs {
    fn geometry(&self) -> slf_host::import::Geometry {
        slf_host::import::Geometry { crop: self.crop, resize: self.resize }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum FillArg {
    /// Refuse a window with missing views.
    None,
    /// Make a missing view from the nearest present one, moved by the disparity (the
    /// folder's published map, or one estimated from the present views).
    Warp,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum LightArg {
    /// The cube holds reflectance: lit by D65.
    Reflectance,
    /// The cube holds radiance relative to white already.
    Radiance,
}

#[derive(Subcommand)]
enum ImportSource {
    /// A folder of RGB views (HCI benchmark naming, or --pattern), lifted to 13 bands by
    /// Mallett and Yuksel (2019) under D65.
    Views {
        /// The folder.
        folder: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// File names with {row} and {col} placeholders, zero-padded as {row:02}
        /// (default: the HCI benchmark's input_CamNNN.png, NNN = row * grid columns + col).
        #[arg(long)]
        pattern: Option<String>,
        /// The number of the first row and column in --pattern names (0 or 1, usually).
        #[arg(long, default_value_t = 0)]
        index_base: usize,
        /// The full view grid, ROWS,COLS.
        #[arg(long, value_parser = pair, default_value = "9,9")]
        grid: (usize, usize),
        /// The window of views read, U,V (the decoder needs at least 4,4).
        #[arg(long, value_parser = pair, default_value = "5,5")]
        views: (usize, usize),
        /// The window's first view ROW,COL in the grid (default: centred).
        #[arg(long, value_parser = pair)]
        start: Option<(usize, usize)>,
        #[command(flatten)]
        geometry: GeometryArgs,
        /// Missing views in the window.
        #[arg(long, value_enum, default_value_t = FillArg::None)]
        fill: FillArg,
        /// The files hold linear values (default: sRGB-encoded, as PNGs usually are).
        #[arg(long)]
        linear: bool,
        /// The centre view's disparity map, .pfm (default: gt_disp_lowres.pfm in an HCI
        /// folder). Cut and scaled with the views, written as OUTPUT's stem + .disparity.npy.
        #[arg(long)]
        disparity: Option<PathBuf>,
        /// Largest disparity (pixels per view) tried when estimating one to fill views.
        #[arg(long, default_value_t = 4.0, value_parser = positive)]
        max_disparity: f32,
    },
    /// A hyperspectral cube: a (H, W, B) .npy with --wavelengths, or a folder of band
    /// images (CAVE: NAME_ms_01.png .. NAME_ms_31.png, 400..=700 nm by 10 nm); views made
    /// by a disparity.
    Cube {
        /// The .npy or folder.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// Wavelengths of the cube's bands, START:STOP:STEP or a comma list, nm (default
        /// for a folder of 31 bands: 400:700:10).
        #[arg(long)]
        wavelengths: Option<String>,
        /// The value of a perfect white reflector (integer images read as fractions of
        /// their full scale).
        #[arg(long, default_value_t = 1.0, value_parser = positive)]
        white: f32,
        /// What the cube's values are.
        #[arg(long, value_enum, default_value_t = LightArg::Reflectance)]
        light: LightArg,
        /// Views U,V.
        #[arg(long, value_parser = pair, default_value = "5,5")]
        views: (usize, usize),
        /// A fronto-parallel plane at this disparity (pixels per view step).
        #[arg(long, default_value_t = 1.0, conflicts_with = "disparity_map")]
        disparity: f32,
        /// The centre view's disparity a pixel, .pfm of the cube's size (instead of a plane).
        #[arg(long)]
        disparity_map: Option<PathBuf>,
        #[command(flatten)]
        geometry: GeometryArgs,
    },
    /// A (U, V, H, W, B) light field .npy of any band count, resampled to the camera's 13
    /// bands over their filters.
    Bands {
        /// The light field .npy.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// Wavelengths of its bands, START:STOP:STEP or a comma list, nm.
        #[arg(long)]
        wavelengths: String,
    },
    /// A light field in an HDF5 file (read in pure Rust: no C library needed).
    Hdf5 {
        /// The .h5 file.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// The dataset's path in the file, e.g. /lf/data.
        #[arg(long)]
        dataset: String,
        /// The dataset's axes, slowest first, as a permutation of u, v (views), h, w
        /// (space), b (bands), e.g. uvhwb or hwuvb.
        #[arg(long, default_value = "uvhwb")]
        axes: String,
        /// Wavelengths of its bands when it does not have the camera's 13 (START:STOP:STEP
        /// or a comma list, nm).
        #[arg(long)]
        wavelengths: Option<String>,
        /// The value of white (every value is divided by it).
        #[arg(long, default_value_t = 1.0, value_parser = positive)]
        white: f32,
    },
}

/// A light field with the camera's bands: as read if it has 13, resampled from
/// `wavelengths` otherwise.
fn with_camera_bands(
    lf: slf_host::lightfield::LightField,
    wavelengths: Option<&str>,
    input: &std::path::Path,
) -> Result<slf_host::lightfield::LightField> {
    use slf_host::import::bands::{CAMERA_FILTER, parse_wavelengths};
    use slf_host::spectra_data::BAND_NM;
    match wavelengths {
        Some(w) => {
            let w = parse_wavelengths(w)?;
            let out = slf_host::import::resample_lightfield(&lf, &w, &BAND_NM, CAMERA_FILTER)
                .with_context(|| input.display().to_string())?;
            eprintln!("note: {}: {} bands resampled to the camera's 13", input.display(), lf.bands);
            Ok(out)
        }
        None if lf.bands != BAND_NM.len() => anyhow::bail!(
            "{}: {} bands; the camera has 13 (400..=700 nm by 25): give the light field's wavelengths with \
             --wavelengths to resample it",
            input.display(),
            lf.bands
        ),
        None => Ok(lf),
    }
}

/// The disparity file written beside an imported light field.
fn disparity_path(output: &std::path::Path) -> PathBuf {
    output.with_extension("disparity.npy")
}

fn import_command(source: ImportSource) -> Result<()> {
    use slf_host::import::bands::{CAMERA_FILTER, parse_wavelengths};
    use slf_host::import::cube::{self, CubeConfig, Depth, Light};
    use slf_host::import::rgb::RgbLift;
    use slf_host::import::views::{Fill, Naming, ViewsConfig, import_views};
    use slf_host::lightfield::write_npy_f32_2d;
    use slf_host::spectra_data::BAND_NM;
    match source {
        ImportSource::Views {
            folder,
            output,
            pattern,
            index_base,
            grid,
            views,
            start,
            geometry,
            fill,
            linear,
            disparity,
            max_disparity,
        } => {
            let cfg = ViewsConfig {
                naming: pattern.map_or(Naming::Hci, Naming::Pattern),
                grid,
                index_base,
                views,
                start,
                geometry: geometry.geometry(),
                fill: if fill == FillArg::Warp { Fill::Warp } else { Fill::None },
                linear,
                disparity,
                max_disparity,
            };
            let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER)?;
            let imported = import_views(&folder, &cfg, &lift)?;
            for n in &imported.notes {
                eprintln!("note: {}: {n}", folder.display());
            }
            write_npy(&output, &imported.lightfield, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), imported.lightfield.shape());
            if let Some(d) = imported.disparity {
                let p = disparity_path(&output);
                write_npy_f32_2d(&p, &d.data, d.rows, d.cols)?;
                println!("wrote {} (the centre view's disparity, pixels per view)", p.display());
            }
            Ok(())
        }
        ImportSource::Cube { input, output, wavelengths, white, light, views, disparity, disparity_map, geometry } => {
            let (data, notes) = if input.is_dir() {
                (cube::read_band_folder(&input)?, Vec::new())
            } else {
                cube::read_cube_npy(&input)?
            };
            for n in notes {
                eprintln!("note: {}: {n}", input.display());
            }
            let wl = match wavelengths {
                Some(w) => parse_wavelengths(&w)?,
                None if input.is_dir() && data.channels == 31 => parse_wavelengths("400:700:10")?,
                None => anyhow::bail!(
                    "{}: {} bands: give their wavelengths with --wavelengths (START:STOP:STEP or a list)",
                    input.display(),
                    data.channels
                ),
            };
            let light = if light == LightArg::Reflectance { Light::Reflectance } else { Light::Radiance };
            let bands = cube::to_camera_bands(&data, &wl, &BAND_NM, CAMERA_FILTER, white, light)
                .with_context(|| input.display().to_string())?;
            let cfg = CubeConfig {
                wavelengths: Some(wl),
                white,
                light,
                views,
                depth: match disparity_map {
                    Some(p) => Depth::Map(p),
                    None => Depth::Plane(disparity),
                },
                geometry: geometry.geometry(),
            };
            let (lf, map) = cube::to_lightfield(&bands, &cfg, (data.rows, data.cols))?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            if let Some(d) = map {
                let p = disparity_path(&output);
                write_npy_f32_2d(&p, &d.data, d.rows, d.cols)?;
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        ImportSource::Bands { input, output, wavelengths } => {
            let lf = with_camera_bands(read_npy(&input)?, Some(&wavelengths), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
        ImportSource::Hdf5 { input, output, dataset, axes, wavelengths, white } => {
            use slf_host::import::hdf5::{Hdf5Layout, read_hdf5};
            let lf = read_hdf5(&input, &Hdf5Layout { dataset, axes }, white)?;
            let lf = with_camera_bands(lf, wavelengths.as_deref(), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
    }
}
