//! What a user asks of a decode: every choice `slf decode`'s flags name, in one place, so
//! the command and the Python package (`slf.decode`) take the same settings with the same
//! defaults, ranges and one-line errors.
//!
//! [`DecodeSettings`] is a `clap` argument group: the CLI flattens it into `slf decode`, and
//! [`DecodeSettings::from_flags`] parses the same flags from a list of strings (the Python
//! package turns its keywords into them), so there is one parser, not two. An unset flag is
//! the preset's value ([`Preset`]) or the solver's default ([`Sl0Config::DEFAULT`]).
//! [`DecodeSettings::resolve`] turns them into a basis and options and refuses what does not
//! fit together; [`crate::decode::pipeline`] runs them on a capture.

use std::path::PathBuf;

use anyhow::{Result, anyhow, bail, ensure};
use clap::{Args, ValueEnum};
use slf_firmware::disparity::MAX_DISPARITY;
use slf_firmware::{
    ChoiceRule, DisparityRange, MemberChoice, Plausibility, ResponseModel, Sl0Config, SolveError, gains,
};

use crate::decode::baselines::Baseline;
use crate::decode::cs::{
    Balance, Basis, DecodeOptions, EstimateBy, NoiseSource, PatchViews, SolveSchedule, TrialBy, Window, read_blob,
};
use crate::decode::options::Maps;
use crate::decode::preset::Preset;
use crate::io::message::number as show;
use crate::io::patch::BANDS;
use crate::sim::flags::FromFlags;

/// Decode method: compressed sensing, or a baseline without it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Compressed sensing: the firmware's SL0 decoder with --dictionary.
    #[default]
    Cs,
    /// Baseline: per pixel, the spectrum interpolated between the bands it measured.
    Interpolate,
    /// Baseline: each band from the nearby pixels and views that measured it, matched to
    /// each pixel's own measurements.
    Demosaic,
    /// Baseline: PPID, demosaicking by the pseudo-panchromatic image (Mihoubi et al. 2017).
    Ppid,
}

impl Method {
    /// The baseline this method names; `None` for compressed sensing.
    pub fn baseline(self) -> Option<Baseline> {
        match self {
            Method::Cs => None,
            Method::Interpolate => Some(Baseline::Interpolate),
            Method::Demosaic => Some(Baseline::Demosaic),
            Method::Ppid => Some(Baseline::Ppid),
        }
    }
}

/// `--dictionary`: the basis kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DictionaryKind {
    /// The 5D DCT.
    Dct,
    /// A learned ensemble (the shipped one unless --blob says otherwise).
    Ensemble,
}

/// `--choice`: how an ensemble member is chosen per patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Choice {
    /// Solve with the DCT, pick the member that best represents it, solve with that (2
    /// solves); where the DCT's own solution is sparser, average the two.
    Screened,
    /// As screened, but where the DCT's own solution is sparser, solve with the DCT again
    /// from the member's solution (3 solves).
    ScreenedResolve,
    /// Solve with every member, keep the sparsest (K + 1 solves).
    Exhaustive,
}

/// `--window`: how overlapping patches are averaged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WindowKind {
    /// Every value of a patch counts the same.
    Uniform,
    /// Lenslets weigh 1, 2, 3, 2, 1 across a patch (per axis, multiplied).
    Tapered,
}

impl WindowKind {
    /// The firmware's window.
    pub fn window(self) -> Window {
        match self {
            WindowKind::Uniform => Window::Uniform,
            WindowKind::Tapered => Window::Tapered,
        }
    }
}

/// `--balance`: the white balance without given gains.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WhiteBalance {
    /// Each band's mean over the frame (grey world).
    Grey,
    /// No white balance (gains of 1).
    Off,
}

impl WhiteBalance {
    /// The decoder's balance.
    pub fn balance(self) -> Balance {
        match self {
            Self::Grey => Balance::GreyWorld,
            Self::Off => Balance::Off,
        }
    }
}

/// The basis flags, shared by the commands that decode (`decode`, `sweep`, `demo`).
#[derive(Args, Clone, Debug)]
pub struct BasisSettings {
    /// Basis to decode with [default: ensemble; dct with --preset preview].
    #[arg(long, value_enum)]
    pub dictionary: Option<DictionaryKind>,
    /// How an ensemble member is chosen per patch.
    #[arg(long, value_enum, default_value_t = Choice::Screened)]
    pub choice: Choice,
    /// Ensemble blob (default: the shipped 8-member ensemble of the patch).
    #[arg(long)]
    pub blob: Option<PathBuf>,
    /// Views per axis a patch holds, 4 or 5: 4 the paper's 5 x 5 x 4 x 4 x 13 patch (a 5 x
    /// 5-view lenslet in four overlapping angular windows), 5 the full-view 5 x 5 x 5 x 5 x 13
    /// patch [default: 5 for lenslets of 5 x 5 views or more, 4 for 4 x 4; a --blob's own].
    #[arg(long, value_parser = patch_views, value_name = "4|5")]
    pub patch_views: Option<PatchViews>,
}

/// `--patch-views`: 4 or 5.
pub fn patch_views(s: &str) -> Result<PatchViews, String> {
    match s.trim() {
        "4" => Ok(PatchViews::Four),
        "5" => Ok(PatchViews::Five),
        _ => Err(format!("{s:?}: 4 (the paper's 4 x 4-view patch) or 5 (the full-view patch)")),
    }
}

impl BasisSettings {
    /// The basis the flags name, with the default preset's where --dictionary is not given.
    ///
    /// # Errors
    /// An unreadable blob.
    pub fn basis(&self) -> Result<Basis> {
        self.basis_for(Preset::Default)
    }

    /// The basis the flags name, or `preset`'s where --dictionary is not given.
    ///
    /// # Errors
    /// An unreadable blob, or a blob with the DCT.
    pub fn basis_for(&self, preset: Preset) -> Result<Basis> {
        let preset_kind = if preset.uses_dct() { DictionaryKind::Dct } else { DictionaryKind::Ensemble };
        Ok(match self.dictionary.unwrap_or(preset_kind) {
            DictionaryKind::Dct => Basis::Dct,
            DictionaryKind::Ensemble => {
                let blob = match &self.blob {
                    Some(p) => Some(read_blob(p)?),
                    None => None,
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

/// The solver's flags; each unset one is the preset's value ([`Preset::options`]).
#[derive(Args, Clone, Debug)]
pub struct SolverSettings {
    /// SL0 sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_f)]
    pub sigma_f: f32,
    /// SL0 steps per sigma level (L).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.steps)]
    pub steps: u16,
    /// SL0 step size mu.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.mu)]
    pub mu: f32,
    /// SL0 smallest sigma (normalised units, white = 1) [default: 1e-3; 3e-3 with --preset
    /// preview].
    #[arg(long)]
    pub sigma_min: Option<f32>,
    /// Hard bound on SL0 steps per patch.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.max_iterations)]
    pub max_iterations: u32,
    /// Noise standard deviation per measurement (normalised units), instead of the
    /// capture's noise description; 0 (with no --shot) forces equality.
    #[arg(long, conflicts_with = "exact")]
    pub noise: Option<f32>,
    /// Shot noise: variance per unit of a measurement's value (normalised units, 1 /
    /// electrons at white), instead of the capture's noise description.
    #[arg(long, conflicts_with = "exact")]
    pub shot: Option<f32>,
    /// Exact projection: the decode equals the measurements, whatever noise the capture
    /// describes. Without --exact, --noise or --shot the noise ball comes from the capture.
    #[arg(long)]
    pub exact: bool,
    /// Early stop: end a patch's solve once a sigma level moves it by less than this RMS
    /// per value (normalised units); 0 never stops early.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.tolerance)]
    pub tolerance: f32,
    /// The ensemble's second solve starts from the DCT's patch at this fraction of its
    /// largest coefficient, in (0, 1]; 1 is a cold start.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_start)]
    pub warm_start: f32,
    /// The warm solve's sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_sigma_f)]
    pub warm_sigma_f: f32,
    /// The warm solve's steps per sigma level.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_steps)]
    pub warm_steps: u16,
    /// A seeded solve's (a shifted patch started from the disjoint grid's decode) sigma
    /// decrease factor per level, in (0, 1); it starts at --warm-start.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.seed_sigma_f)]
    pub seed_sigma_f: f32,
    /// Where a cold solve starts, in (0, 1]: 1 the minimum-norm solution at its largest
    /// coefficient; below 1 the band-gain fill (each pixel's gain times each band's mean
    /// over the patch) at that fraction of its largest coefficient, fewer sigma levels
    /// [default: 1; 0.03 with --preset preview].
    #[arg(long)]
    pub cold_start: Option<f32>,
    /// Short path: a patch whose measurements of each band agree within this (normalised
    /// units) is decoded as each band's mean, with no solve; 0: exactly flat patches only.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.flat)]
    pub flat: f32,
    /// A patch whose measurements cover fewer distinct bands than this (a kronecker mask's
    /// patch sees k, or up to 4k across mask blocks) is interpolated per pixel instead of
    /// solved; 0 solves every patch (the paper's decode).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.min_bands)]
    pub min_bands: u8,
}

impl SolverSettings {
    /// Where the noise ball comes from: the capture unless told.
    pub fn noise_source(&self) -> NoiseSource {
        if self.exact || self.noise.is_some() || self.shot.is_some() {
            NoiseSource::Config
        } else {
            NoiseSource::Capture
        }
    }

    /// The flags' configuration; `sigma_min` and `cold_start` from `base` (the preset's)
    /// unless given.
    ///
    /// # Errors
    /// A value out of its range, named.
    pub fn config(&self, base: &Sl0Config) -> Result<Sl0Config> {
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
            seed_sigma_f: self.seed_sigma_f,
            cold_start: self.cold_start.unwrap_or(base.cold_start),
            flat: self.flat,
            min_bands: self.min_bands,
        };
        match c.validate() {
            Ok(()) => Ok(c),
            Err(SolveError::InvalidConfig { field }) => {
                let value = match field {
                    "sigma_f" => show(c.sigma_f),
                    "steps" => c.steps.to_string(),
                    "mu" => show(c.mu),
                    "sigma_min" => show(c.sigma_min),
                    "max_iterations" => c.max_iterations.to_string(),
                    "noise" => show(c.noise),
                    "shot" => show(c.shot),
                    "tolerance" => show(c.tolerance),
                    "warm_start" => show(c.warm_start),
                    "warm_sigma_f" => show(c.warm_sigma_f),
                    "warm_steps" => c.warm_steps.to_string(),
                    "seed_sigma_f" => show(c.seed_sigma_f),
                    "cold_start" => show(c.cold_start),
                    "flat" => show(c.flat),
                    _ => String::from("?"),
                };
                bail!("--{} {value}: must be {}", field.replace('_', "-"), config_range(field))
            }
            Err(e) => bail!("{e}"),
        }
    }
}

/// The range [`Sl0Config::validate`] holds `field` to, in words.
fn config_range(field: &str) -> &'static str {
    match field {
        "sigma_f" | "warm_sigma_f" | "seed_sigma_f" => "in (0, 1)",
        "warm_start" | "cold_start" => "in (0, 1]",
        "steps" | "warm_steps" | "max_iterations" => "at least 1",
        "mu" => "in (0, 2] (above 2 the ascent grows small coefficients)",
        "sigma_min" => "in (0, 1] (normalised units, white = 1)",
        _ => "in [0, 1] (normalised units, white = 1)",
    }
}

/// Everything `slf decode` and `slf.decode` are asked, but where the capture comes from and
/// where the results go.
#[derive(Args, Clone, Debug)]
pub struct DecodeSettings {
    /// Decode method: compressed sensing, or a baseline without it.
    #[arg(long, value_enum, default_value_t = Method::Cs)]
    pub method: Method,
    /// The per-patch maps the report keeps: set by the caller from the outputs it writes
    /// (`--member-map`, `--disparity-map`; Python's report always has the disparities).
    #[arg(skip)]
    pub maps: Maps,
    /// A named decode: its basis, stride, window, disparities, edge fallback, sigma_min and
    /// cold start; any of those flags given as well overrides the preset's value.
    #[arg(long, value_enum, default_value_t = Preset::Default)]
    pub preset: Preset,
    #[command(flatten)]
    pub solver: SolverSettings,
    #[command(flatten)]
    pub basis: BasisSettings,
    /// Lenslets between patch origins, 1..=5 (5: disjoint patches, which show their
    /// grid; smaller strides decode (5 / stride)^2 times the patches and average them)
    /// [default: 2; preview 5, best 1; 3 was the default with the paper's patch].
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=5))]
    pub stride: Option<u8>,
    /// How overlapping patches are averaged [default: tapered; preview uniform].
    #[arg(long, value_enum)]
    pub window: Option<WindowKind>,
    /// With a stride below 5: decode a shifted patch only where a first pass on the
    /// disjoint grid shows a seam inside it, steps across the grid's borders more than
    /// this many times those between its other lenslets.
    #[arg(long)]
    pub adaptive: Option<f32>,
    /// A calibration folder (`slf calibrate`): the capture corrected for each pixel's dark
    /// level and flat (gain and vignetting), its hot pixels left out, and the filters'
    /// leaked light separated by their response matrix (--response-model). Baselines too
    /// (their spectra unmixed by its inverse).
    #[arg(long)]
    pub calibration: Option<std::path::PathBuf>,
    /// With --calibration, where the decode puts the filters' response matrix.
    #[arg(long, value_enum, default_value_t = ResponseChoice::Unmix, requires = "calibration")]
    pub response_model: ResponseChoice,
    /// Which lenslet grid the decode reads the frames through (a capture behind a turned,
    /// non-integer-pitch lenslet array: `lenslet_grid`).
    #[arg(long, value_enum, default_value_t = GridChoice::Auto)]
    pub grid: GridChoice,
    /// White balance: each band divided by a gain before the solve and multiplied back
    /// (grey: each band's mean over the frame, as the device does it).
    #[arg(long, value_enum, default_value_t = WhiteBalance::Grey)]
    pub balance: WhiteBalance,
    /// The 13 band gains, comma-separated (e.g. from a white reference); replaces
    /// --balance.
    #[arg(long, value_delimiter = ',', value_name = "G1,...,G13")]
    pub gains: Option<Vec<f32>>,
    /// Disparities (pixels per view step) each 5 x 5-lenslet block may be sheared to
    /// before decoding, MIN:MAX[:STEP] (default -1:1:0.5 for a single snapshot, -1:1 for
    /// more, behind a lenslet grid and with --preset preview; 0:0 decodes unsheared; a STEP of 0.5 adds the
    /// half-pixel shears, whose measurements interpolate the patch); chosen per block by
    /// how well the views' same-band samples agree.
    #[arg(long, value_parser = disparity_range, value_name = "MIN:MAX[:STEP]", allow_hyphen_values = true)]
    pub disparities: Option<DisparityRange>,
    /// Decode a block sheared at the frame's edge unsheared as well, for the views of its
    /// edge lenslets no sheared patch reached (false: those values come from their
    /// lenslet's other views, a fifth fewer patches on a 128 x 128-lenslet frame)
    /// [default: true; false with --preset preview].
    #[arg(long, value_name = "BOOL")]
    pub edge_fallback: Option<bool>,
    /// Decode every sheared block unsheared as well, for the values between blocks sheared
    /// otherwise that no sheared patch reached (false: those come from their lenslet's
    /// other views) [default: false; true with --preset preview].
    #[arg(long, value_name = "BOOL")]
    pub sheared_fallback: Option<bool>,
    /// With a stride below 5: decode the disjoint grid first and start each shifted patch
    /// from its decode, one solve a patch instead of two (false: every patch from
    /// nothing, the decode before 2026-11-25) [default: true].
    #[arg(long, value_name = "BOOL")]
    pub seeded: Option<bool>,
    /// The solves' schedule: trained (the blob's trained schedules, a few steps each; the
    /// DCT takes the shipped blob's) or annealed (the hand-set schedule the solver flags
    /// --sigma-f, --steps, --mu, --tolerance, --warm-*, --seed-sigma-f and --cold-start set).
    #[arg(long, value_enum, default_value_t = SolveSchedule::Trained)]
    pub schedule: SolveSchedule,
    /// The plausibility check of every solved patch: FACTOR:MARGIN (a value above FACTOR
    /// times the brightest white-balanced measurement of its pixel's 3 x 3 x 3 x 3
    /// neighbourhood plus MARGIN is implausible; FACTOR >= 1, MARGIN in [0, 1]), or off. An
    /// implausible patch is decoded again by the DCT's hand-set schedule from the
    /// minimum-norm start, and clipped to the bounds if that breaks them too; the summary
    /// counts both [default: 3:0.05].
    #[arg(long, value_parser = plausibility, value_name = "FACTOR:MARGIN|off")]
    pub plausible: Option<Plausibility>,
    /// Estimate the decode's error from samples held out (one in eight), in the output's
    /// units: the summary's estimated PSNR, and `slf decode --error-map` writes it per
    /// lenslet. The decode itself is the same bit for bit; the estimate costs what
    /// --estimate-by says.
    #[arg(long)]
    pub estimate: bool,
    /// How the error is estimated: `decode`, the frame decoded again by the same plan from
    /// seven in eight samples and its predictions of the eighth (a second decode's time);
    /// `patches`, each patch solved once more from seven in eight of its measurements (the
    /// DCT alone; a solve a patch) [default: decode; patches behind a lenslet grid or a
    /// response in the projection].
    #[arg(long, value_enum, value_name = "HOW")]
    pub estimate_by: Option<EstimateBy>,
    /// Check each half-pixel disparity against the whole ones next to it by the held-out
    /// error estimate of the block's patch at each, and decode at the one estimated best
    /// (three more solves a half-pixel block).
    #[arg(long)]
    pub shear_check: bool,
    /// With an ensemble: pick, per region of 3 x 3 tiles, the ensemble or the DCT it
    /// screens with by their held-out errors on one pilot patch a tile (each model
    /// decodes the pilot from seven in eight of its measurements; the one that predicts
    /// the eighth better decodes the region) [default: true].
    #[arg(long, value_name = "BOOL")]
    pub model_trial: Option<bool>,
    /// How the model trial tells the DCT from the ensemble: `pilots`, pilot patches each
    /// decoded by both from seven in eight of its measurements (about a tenth of a solve a
    /// patch); `decode`, the frame decoded again by each, as the decode makes it, from
    /// seven in eight samples, the one that predicts the eighth better decoding the frame
    /// (two more decodes of the frame; with --error-map the picked one's is the map)
    /// [default: pilots].
    #[arg(long, value_enum, value_name = "HOW")]
    pub trial_by: Option<TrialBy>,
    /// On a kronecker mask: mix each block's values from the decode and the PPID baseline by
    /// how well each predicted the samples it was not given (three held-out decodes of the
    /// frame and four PPIDs more; PPID's light field held whole); with --error-map their
    /// held-out decodes are the map's. Other masks are decoded as without it [default: true;
    /// false with --preset preview].
    #[arg(long, value_name = "BOOL")]
    pub baseline_blend: Option<bool>,
    /// With half-pixel disparities: check them first on one pilot patch a tile (up to 256)
    /// against the whole disparities beside them by the held-out error estimate, and decode
    /// the frame with whole disparities only where the whole ones estimate below 0.7 x the
    /// half ones' RMS error (half-pixel measurements alias on detail at the pixel scale)
    /// [default: true].
    #[arg(long, value_name = "BOOL")]
    pub shear_trial: Option<bool>,
}

/// Parses `--plausible`: `FACTOR:MARGIN` or `off`.
///
/// # Errors
/// Anything else, or a value out of range, in one line.
pub fn plausibility(s: &str) -> Result<Plausibility, String> {
    if s.trim() == "off" {
        return Ok(Plausibility::OFF);
    }
    let bad =
        || format!("{s:?}: want FACTOR:MARGIN with FACTOR in [1, 1000] and MARGIN in [0, 1] (e.g. 3:0.05), or off");
    let (f, m) = s.split_once(':').ok_or_else(bad)?;
    let (factor, margin) = (f.trim().parse::<f32>().map_err(|_| bad())?, m.trim().parse::<f32>().map_err(|_| bad())?);
    if !((1.0..=1000.0).contains(&factor) && (0.0..=1.0).contains(&margin)) {
        return Err(bad());
    }
    Ok(Plausibility { factor, margin })
}

impl DecodeSettings {
    /// The compressed-sensing decode these settings ask for: the basis and the options.
    ///
    /// # Errors
    /// A flag out of range or flags that do not fit together, named; an unreadable blob.
    pub fn resolve(&self) -> Result<(Basis, DecodeOptions)> {
        let base = self.preset.options();
        let balance = match &self.gains {
            Some(g) => {
                let g: [f32; BANDS] =
                    g.as_slice().try_into().map_err(|_| anyhow!("--gains: {BANDS} values, got {}", g.len()))?;
                if let Some((b, bad)) = g.iter().enumerate().find(|(_, x)| !gains::valid_gain(**x)) {
                    bail!(
                        "--gains: gain {} is {}: each must be in [1/{m}, {m}] (the decode's thresholds are in units \
                         of white)",
                        b + 1,
                        show(*bad),
                        m = gains::MAX_RATIO
                    );
                }
                Balance::Gains(g)
            }
            None => self.balance.balance(),
        };
        if let Some(a) = self.adaptive {
            ensure!(a.is_finite() && a >= 0.0, "--adaptive {a}: must be finite, at or above 0");
        }
        let options = DecodeOptions {
            sl0: self.solver.config(&base.sl0)?,
            noise: self.solver.noise_source(),
            stride: self.stride.map_or(base.stride, |s| (s, s)),
            window: self.window.map_or(base.window, WindowKind::window),
            adaptive: self.adaptive,
            balance,
            disparities: self.disparities.or(base.disparities),
            edge_fallback: self.edge_fallback.unwrap_or(base.edge_fallback),
            sheared_fallback: self.sheared_fallback.unwrap_or(base.sheared_fallback),
            seeded: self.seeded.unwrap_or(base.seeded),
            plausibility: self.plausible.unwrap_or(base.plausibility),
            error_estimate: self.estimate || base.error_estimate,
            estimate_by: self.estimate_by.unwrap_or(base.estimate_by),
            trial_by: self.trial_by.unwrap_or(base.trial_by),
            baseline_blend: self.baseline_blend.unwrap_or(base.baseline_blend),
            shear_check: self.shear_check || base.shear_check,
            // A dictionary named is the model asked for: no trial unless asked too.
            model_trial: self.model_trial.unwrap_or(base.model_trial && self.basis.dictionary.is_none()),
            shear_trial: self.shear_trial.unwrap_or(base.shear_trial),
            patch_views: self.basis.patch_views.or(base.patch_views),
            schedule: self.schedule,
            ..base
        };
        // The hand-set schedule's flags mean nothing to a trained schedule.
        if self.schedule == SolveSchedule::Trained {
            let d = Self::from_flags(std::iter::empty::<&str>()).map_err(|e| anyhow!(e))?;
            let (s, ds) = (&self.solver, &d.solver);
            let f = |a: f32, b: f32| a.to_bits() == b.to_bits();
            let hand = [
                (f(s.sigma_f, ds.sigma_f), "--sigma-f"),
                (s.steps == ds.steps, "--steps"),
                (f(s.mu, ds.mu), "--mu"),
                (f(s.tolerance, ds.tolerance), "--tolerance"),
                (f(s.warm_start, ds.warm_start), "--warm-start"),
                (f(s.warm_sigma_f, ds.warm_sigma_f), "--warm-sigma-f"),
                (s.warm_steps == ds.warm_steps, "--warm-steps"),
                (f(s.seed_sigma_f, ds.seed_sigma_f), "--seed-sigma-f"),
                (s.cold_start.map(f32::to_bits) == ds.cold_start.map(f32::to_bits), "--cold-start"),
            ];
            if let Some((_, flag)) = hand.iter().find(|(same, _)| !same) {
                bail!("{flag} sets the hand-set schedule, which the trained one replaces: add --schedule annealed");
            }
        }
        // Flags the decode would otherwise ignore in silence.
        let bands = BANDS;
        ensure!(
            usize::from(options.sl0.min_bands) <= bands,
            "--min-bands {}: at most {bands}, the patch's bands (above, every patch would be interpolated; 0 \
             solves every patch)",
            options.sl0.min_bands
        );
        ensure!(
            self.adaptive.is_none() || options.stride != (5, 5),
            "--adaptive needs a stride below 5: on the disjoint grid there are no shifted patches to choose"
        );
        ensure!(
            self.seeded != Some(true) || options.stride != (5, 5),
            "--seeded true needs a stride below 5: it seeds the shifted patches from the disjoint grid's decode"
        );
        let basis = self.basis.basis_for(self.preset)?;
        ensure!(
            self.basis.blob.is_none() || !matches!(basis, Basis::Dct),
            "--blob names an ensemble, but this decode uses the DCT ({}): add --dictionary ensemble or drop --blob",
            if self.basis.dictionary.is_some() { "--dictionary dct" } else { "--preset preview" }
        );
        Ok((basis, options))
    }

    /// The compressed-sensing flags given with values other than their defaults, by name
    /// (a baseline uses none of them: each would be ignored in silence, a bad value never
    /// checked). A flag set to its default value is not told apart from one not given.
    pub fn compressed_sensing_flags(&self) -> Vec<&'static str> {
        let Ok(d) = Self::from_flags(std::iter::empty::<&str>()) else { return Vec::new() };
        let (s, ds) = (&self.solver, &d.solver);
        // f32 by bits: a NaN given differs from the default.
        let f = |a: f32, b: f32| a.to_bits() == b.to_bits();
        let of = |a: Option<f32>, b: Option<f32>| a.map(f32::to_bits) == b.map(f32::to_bits);
        [
            (self.preset == d.preset, "--preset"),
            (f(s.sigma_f, ds.sigma_f), "--sigma-f"),
            (s.steps == ds.steps, "--steps"),
            (f(s.mu, ds.mu), "--mu"),
            (of(s.sigma_min, ds.sigma_min), "--sigma-min"),
            (s.max_iterations == ds.max_iterations, "--max-iterations"),
            (of(s.noise, ds.noise), "--noise"),
            (of(s.shot, ds.shot), "--shot"),
            (s.exact == ds.exact, "--exact"),
            (f(s.tolerance, ds.tolerance), "--tolerance"),
            (f(s.warm_start, ds.warm_start), "--warm-start"),
            (f(s.warm_sigma_f, ds.warm_sigma_f), "--warm-sigma-f"),
            (s.warm_steps == ds.warm_steps, "--warm-steps"),
            (f(s.seed_sigma_f, ds.seed_sigma_f), "--seed-sigma-f"),
            (of(s.cold_start, ds.cold_start), "--cold-start"),
            (f(s.flat, ds.flat), "--flat"),
            (s.min_bands == ds.min_bands, "--min-bands"),
            (self.basis.dictionary == d.basis.dictionary, "--dictionary"),
            (self.basis.choice == d.basis.choice, "--choice"),
            (self.basis.blob == d.basis.blob, "--blob"),
            (self.basis.patch_views == d.basis.patch_views, "--patch-views"),
            (self.stride == d.stride, "--stride"),
            (self.window == d.window, "--window"),
            (of(self.adaptive, d.adaptive), "--adaptive"),
            (self.balance == d.balance, "--balance"),
            (self.gains.is_none(), "--gains"),
            (self.disparities == d.disparities, "--disparities"),
            (self.edge_fallback == d.edge_fallback, "--edge-fallback"),
            (self.sheared_fallback == d.sheared_fallback, "--sheared-fallback"),
            (self.seeded == d.seeded, "--seeded"),
            (self.schedule == d.schedule, "--schedule"),
            (self.plausible == d.plausible, "--plausible"),
            (self.estimate == d.estimate, "--estimate"),
            (self.estimate_by == d.estimate_by, "--estimate-by"),
            (self.shear_check == d.shear_check, "--shear-check"),
            (self.model_trial == d.model_trial, "--model-trial"),
            (self.trial_by == d.trial_by, "--trial-by"),
            (self.baseline_blend == d.baseline_blend, "--baseline-blend"),
            (self.shear_trial == d.shear_trial, "--shear-trial"),
        ]
        .into_iter()
        .filter_map(|(same, name)| (!same).then_some(name))
        .collect()
    }
}

/// `--grid`: which lenslet grid a decode reads the frames through.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum GridChoice {
    /// The calibration's grid (found from its flats) if it has one, else the capture's.
    #[default]
    Auto,
    /// The capture's own `lenslet_grid`, even with a calibration that found another.
    Capture,
    /// The aligned grid whatever the capture says: `U x V` pixels under each lenslet from
    /// pixel (0, 0), the frames cut to `S*U x T*V` (slf's decode before grids).
    Aligned,
}

/// `--response-model`: where a calibrated decode puts the filters' response matrix
/// ([`ResponseModel`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ResponseChoice {
    /// Decode as if the filters were one-hot, then unmix each decoded spectrum by the
    /// response's inverse (the sparse prior on the spectra the filters saw).
    #[default]
    Unmix,
    /// Each pixel's measurements as rows of the response in every projection of the
    /// solve (the sparse prior on the scene's spectra; whole-pixel shears only).
    Projection,
}

impl ResponseChoice {
    /// The firmware's.
    pub fn model(self) -> ResponseModel {
        match self {
            Self::Unmix => ResponseModel::Unmix,
            Self::Projection => ResponseModel::Projection,
        }
    }
}

/// `MIN:MAX[:STEP]`, integer disparities around 0 (e.g. `-1:1`) within the decoder's
/// limit, in steps of 1 (the default) or 0.5.
///
/// # Errors
/// The accepted forms, with the decoder's limit.
pub fn disparity_range(s: &str) -> Result<DisparityRange, String> {
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

impl FromFlags for DecodeSettings {
    const COMMAND: &'static str = "decode";
}
