//! `slf decode`: a capture folder to a light field `.npy`, by compressed sensing (the
//! firmware's decoder, in parallel over tiles) or by a baseline without it.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::ValueEnum;
use slf_host::decode::baselines::Baseline;
use slf_host::decode::cs::{Balance, DecodeOptions, NoiseSource, decode_with, disparity_per_lenslet};
use slf_host::firmware::disparity::{Disparity, MAX_DISPARITY};
use slf_host::firmware::{DisparityRange, Sl0Config, gains};
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::{Dtype, write_npy, write_npy_f32_2d};

use crate::args::{BalanceArg, BasisArgs, PresetArg, WindowArg, ranged};

#[derive(clap::Args)]
pub struct Args {
    /// Capture folder (capture.json and frames).
    pub capture: PathBuf,
    /// Output .npy file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Decode method: compressed sensing, or a baseline without it.
    #[arg(long, value_enum, default_value_t = Method::Cs)]
    pub method: Method,
    /// A named decode: its basis, stride, window, disparities, edge fallback, sigma_min and
    /// cold start; any of those
    /// flags given as well overrides the preset's value.
    #[arg(long, value_enum, default_value_t = PresetArg::Default)]
    pub preset: PresetArg,
    #[command(flatten)]
    pub solver: SolverArgs,
    #[command(flatten)]
    pub basis: BasisArgs,
    /// Also write which ensemble member each patch used (CSV: the patch's origin, the
    /// disparity it was sheared to, the member).
    #[arg(long)]
    pub member_map: Option<PathBuf>,
    /// Lenslets between patch origins, 1..=5 (5: disjoint patches, which show their
    /// grid; smaller strides decode (5 / stride)^2 times the patches and average them)
    /// [default: 3; preview 5, best 2].
    #[arg(long, value_parser = ranged::<1, 5>)]
    pub stride: Option<usize>,
    /// How overlapping patches are averaged [default: tapered; preview uniform].
    #[arg(long, value_enum)]
    pub window: Option<WindowArg>,
    /// With a stride below 5: decode a shifted patch only where a first pass on the
    /// disjoint grid shows a seam inside it, steps across the grid's borders more than
    /// this many times those between its other lenslets.
    #[arg(long)]
    pub adaptive: Option<f32>,
    /// White balance: each band divided by a gain before the solve and multiplied back
    /// (grey: each band's mean over the frame, as the device does it).
    #[arg(long, value_enum, default_value_t = BalanceArg::Grey)]
    pub balance: BalanceArg,
    /// The 13 band gains, comma-separated (e.g. from a white reference); replaces
    /// --balance.
    #[arg(long, value_delimiter = ',', value_name = "G1,...,G13")]
    pub gains: Option<Vec<f32>>,
    /// Disparities (pixels per view step) each 5 x 5-lenslet block may be sheared to
    /// before decoding, MIN:MAX[:STEP] (default -1:1:0.5 for a single snapshot, -1:1 for
    /// more and with --preset preview; 0:0 decodes unsheared; a STEP of 0.5 adds the half-pixel shears, whose
    /// measurements interpolate the patch); chosen per block by how well the views'
    /// same-band samples agree.
    #[arg(long, value_parser = disparity_range, value_name = "MIN:MAX[:STEP]", allow_hyphen_values = true)]
    pub disparities: Option<DisparityRange>,
    /// Decode a block sheared at the frame's edge unsheared as well, for the views of its
    /// edge lenslets no sheared patch reached (false: those values come from their
    /// lenslet's other views, a fifth fewer patches on a 128 x 128-lenslet frame)
    /// [default: true; false with --preset preview].
    #[arg(long, value_name = "BOOL")]
    pub edge_fallback: Option<bool>,
    /// Also write the chosen disparity per lenslet (.npy, lenslet rows x cols, f32: the
    /// mean over the blocks that cover it); not with --disparities 0:0.
    #[arg(long)]
    pub disparity_map: Option<PathBuf>,
    /// Stored dtype.
    #[arg(long, value_enum, default_value_t = Dtype::F32)]
    pub dtype: Dtype,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(args: Args) -> Result<()> {
    let Args {
        capture,
        output,
        method,
        preset,
        solver,
        basis,
        member_map,
        stride,
        window,
        adaptive,
        balance,
        gains,
        disparities,
        edge_fallback,
        disparity_map,
        dtype,
        quiet,
    } = args;
    let cap = Capture::load(&capture)?;
    let balance = match gains {
        Some(g) => {
            let g: [f32; 13] =
                g.try_into().map_err(|g: Vec<f32>| anyhow::anyhow!("--gains: 13 values, got {}", g.len()))?;
            anyhow::ensure!(gains::valid(&g), "--gains: every gain must be finite and positive");
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
    let preset = preset.preset();
    let base = preset.options();
    let stride = stride.map_or(base.stride, |s| (s as u8, s as u8));
    let opts = DecodeOptions {
        sl0: solver.config(&base.sl0)?,
        noise: solver.noise_source(),
        progress: !quiet,
        stride,
        window: window.map_or(base.window, WindowArg::window),
        adaptive,
        balance,
        disparities: disparities.or(base.disparities),
        edge_fallback: edge_fallback.unwrap_or(base.edge_fallback),
        ..base
    };
    anyhow::ensure!(
        disparity_map.is_none() || !opts.disparities_for(&cap).is_off(),
        "--disparity-map needs disparities to search: with --disparities 0:0 every block is at 0"
    );
    if let Some(a) = adaptive {
        anyhow::ensure!(a.is_finite() && a >= 0.0, "--adaptive {a}: must be finite, at or above 0");
    }
    let (lf, r) = decode_with(&cap, &basis.basis_for(preset)?, &opts)?;
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
        let map = disparity_per_lenslet(&r.disparity_map, rows, cols);
        write_npy_f32_2d(&path, &map, rows, cols).with_context(|| format!("cannot write {}", path.display()))?;
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
        let mut counts = std::collections::BTreeMap::<Disparity, usize>::new();
        for (_, d) in &r.disparity_map {
            *counts.entry(*d).or_default() += 1;
        }
        let counts: Vec<String> =
            counts.iter().map(|(d, n)| format!("{}{d}: {n}", if d.in_halves() > 0 { "+" } else { "" })).collect();
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

/// `slf decode` warns when more than this fraction of patches failed or were flagged.
const WARN_FRACTION: f64 = 0.01;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
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

#[derive(clap::Args, Clone, Debug)]
pub struct SolverArgs {
    /// SL0 sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_f)]
    sigma_f: f32,
    /// SL0 steps per sigma level (L).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.steps)]
    steps: u16,
    /// SL0 step size mu.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.mu)]
    mu: f32,
    /// SL0 smallest sigma (normalised units, white = 1) [default: 1e-3; 3e-3 with --preset
    /// preview].
    #[arg(long)]
    sigma_min: Option<f32>,
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
    /// Where a cold solve starts, in (0, 1]: 1 the minimum-norm solution at its largest
    /// coefficient; below 1 the band-gain fill (each pixel's gain times each band's mean
    /// over the patch) at that fraction of its largest coefficient, fewer sigma levels
    /// [default: 1; 0.03 with --preset preview].
    #[arg(long)]
    cold_start: Option<f32>,
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

    /// The flags' configuration; `sigma_min` and `cold_start` from `base` (the preset's)
    /// unless given.
    fn config(&self, base: &Sl0Config) -> Result<Sl0Config> {
        let c = Sl0Config {
            sigma_f: self.sigma_f,
            steps: self.steps,
            mu: self.mu,
            sigma_min: self.sigma_min.unwrap_or(base.sigma_min),
            max_iterations: self.max_iterations,
            noise: self.noise.unwrap_or(0.0),
            shot: self.shot.unwrap_or(0.0),
            tolerance: self.tolerance,
            warm_start: self.warm_start,
            warm_sigma_f: self.warm_sigma_f,
            warm_steps: self.warm_steps,
            cold_start: self.cold_start.unwrap_or(base.cold_start),
            flat: self.flat,
            min_bands: self.min_bands,
        };
        c.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(c)
    }
}

/// `MIN:MAX[:STEP]`, integer disparities around 0 (e.g. `-1:1`) within the decoder's
/// limit, in steps of 1 (the default) or 0.5.
fn disparity_range(s: &str) -> Result<DisparityRange, String> {
    let bad = || {
        let m = MAX_DISPARITY;
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
    DisparityRange::new(a, b).map(|r| r.with_halves(halves)).ok_or_else(bad)
}
