//! Decoding a capture on the workstation with the firmware's own tile decoder, in parallel
//! over tiles (rayon), one [`Workspace`] per worker thread.
//!
//! The patch is 5 x 5 lenslets x `PU x PV` views x 13 bands, a decode setting
//! ([`PatchViews`]): the paper's 4 x 4-view window, or the full-view patch, every view of a
//! 5 x 5-view lenslet. Where a patch has fewer views than a lenslet, the decoder's
//! overlapping angular windows
//! each give an estimate of the shared views; so do the end-aligned edge tiles for the
//! lenslets they share with the grid, and (by default) the patch grids shifted by the
//! stride ([`DEFAULT_STRIDE`], [`Window::Tapered`]). Every estimate is averaged into the
//! light field with its window's weight. The solver's noise ball comes from the capture's
//! noise description unless told otherwise ([`NoiseSource`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::{Result, anyhow, bail, ensure};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use slf_firmware::disparity::Disparity;
use slf_firmware::tile::PatchSeed;
use slf_firmware::{
    Dictionary, DisparityRange, Ended, FrameSource, HoldOut, PatchModel, PatchOrigin, PatchReport, PatchShape,
    PatchSink, Pick, Picked, Plausibility, Response, ResponseModel, Sl0Config, SolveError, Tile, TileDecoder,
    TileReport, Workspace,
};

use crate::decode::trial::{DCT_LEAN, frame_shear_trial, frame_trial, halves_alias, pilot_budget, rms};
use crate::io::capture::Capture;
use crate::io::lightfield::LightField;

/// A dictionary of the paper's patch: 5 x 5 lenslets x 4 x 4 views x 13 bands.
pub type PaperDictionary = Dictionary<5, 5, 4, 4, 13>;
/// A dictionary of the full-view patch: 5 x 5 lenslets x 5 x 5 views x 13 bands.
pub type FullViewDictionary = Dictionary<5, 5, 5, 5, 13>;

/// How many of a lenslet's views a patch holds per axis (`slf decode --patch-views`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchViews {
    /// The paper's patch, 5 x 5 x 4 x 4 x 13 (N = 5,200): a 5 x 5-view lenslet is covered
    /// by four overlapping angular windows, averaged.
    Four,
    /// The full-view patch, 5 x 5 x 5 x 5 x 13 (N = 8,125): every view of a 5 x 5-view
    /// lenslet in one patch, one solve a patch position.
    Five,
}

impl PatchViews {
    /// Both, the paper's first.
    pub const ALL: [Self; 2] = [Self::Four, Self::Five];

    /// Views per axis.
    pub fn count(self) -> usize {
        match self {
            Self::Four => 4,
            Self::Five => 5,
        }
    }

    /// The patch's dimensions `[PS, PT, PU, PV, B]`.
    pub fn dims(self) -> [usize; 5] {
        let v = self.count();
        [5, 5, v, v, 13]
    }

    /// The patch a capture with lenslets of `views` (rows, cols) views decodes with when
    /// not told: the full-view patch where a lenslet has at least 5 x 5 views, the paper's
    /// where it has 4 x 4; `None` for smaller lenslets, which no patch fits.
    pub fn fitting(views: (usize, usize)) -> Option<Self> {
        match views.0.min(views.1) {
            5.. => Some(Self::Five),
            4 => Some(Self::Four),
            _ => None,
        }
    }

    /// The patch a dictionary blob was made for (its header's dimensions); `None` for a
    /// blob too short to have a header or of another shape.
    pub fn of_blob(blob: &[u8]) -> Option<Self> {
        let dims = slf_firmware::blob::dims(blob)?;
        Self::ALL.into_iter().find(|v| v.dims() == dims)
    }

    /// The patch of `PU x PV` views (the const parameters of a generic decode); `None` for
    /// a shape that is neither.
    pub fn of_views(pu: usize, pv: usize) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.count() == pu && pu == pv)
    }

    /// The shipped ensemble of this patch.
    pub fn shipped_ensemble(self) -> &'static [u8] {
        match self {
            Self::Four => slf_firmware::DEFAULT_ENSEMBLE,
            Self::Five => slf_firmware::DEFAULT_FULL_VIEW_ENSEMBLE,
        }
    }

    /// `5 x 5 x 4 x 4 x 13`, as messages name a patch.
    pub fn shape_name(self) -> String {
        let v = self.count();
        format!("5 x 5 x {v} x {v} x 13")
    }
}

impl core::fmt::Display for PatchViews {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}", self.count())
    }
}

/// Which basis decodes: the 5D DCT, or an ensemble with a member choice.
#[derive(Clone, Debug)]
pub enum Basis {
    Dct,
    /// A blob and how members are chosen. `blob: None` is the shipped ensemble of the
    /// decode's patch ([`PatchViews::shipped_ensemble`]).
    Ensemble {
        blob: Option<Vec<u8>>,
        choice: slf_firmware::MemberChoice,
    },
}

impl Basis {
    /// The shipped ensemble with screened member choice: the default.
    pub fn default_ensemble() -> Self {
        Self::Ensemble { blob: None, choice: slf_firmware::MemberChoice::Screened(slf_firmware::ChoiceRule::DEFAULT) }
    }

    /// The patch a given blob was made for; `None` for the DCT and the shipped ensembles,
    /// which exist for every patch.
    pub fn blob_views(&self) -> Option<PatchViews> {
        match self {
            Self::Ensemble { blob: Some(b), .. } => PatchViews::of_blob(b),
            _ => None,
        }
    }

    /// A short name for reports.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Dct => "DCT",
            Self::Ensemble { choice: slf_firmware::MemberChoice::Screened(_), .. } => "ensemble screened",
            Self::Ensemble { choice: slf_firmware::MemberChoice::ScreenedResolve(_), .. } => {
                "ensemble screened, DCT wins re-solved"
            }
            Self::Ensemble { choice: slf_firmware::MemberChoice::Exhaustive(_), .. } => "ensemble exhaustive",
        }
    }
}

/// The largest dictionary blob of a decoder's patch: 65,535 members of the full-view
/// patch, the format's limit.
pub const MAX_BLOB: usize = slf_firmware::blob::blob_len([5, 5, 5, 5, 13], u16::MAX as usize);

/// Reads and validates a dictionary blob file, of either patch ([`PatchViews`]); a file
/// larger than [`MAX_BLOB`], a FIFO or a device is refused before reading.
///
/// # Errors
/// A message with the file and what is wrong.
pub fn read_blob(path: &std::path::Path) -> Result<Vec<u8>> {
    crate::io::capture::regular_file(
        path,
        MAX_BLOB as u64,
        "of the largest dictionary blob of a decoder's patch (65,535 members)",
    )?;
    let blob = std::fs::read(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let checked = match PatchViews::of_blob(&blob) {
        Some(PatchViews::Five) => slf_firmware::Ensemble::<5, 5, 5, 5, 13>::new(&blob).map(|_| ()),
        // The paper's patch also reports a blob of neither shape (its dimension check).
        _ => slf_firmware::Ensemble::<5, 5, 4, 4, 13>::new(&blob).map(|_| ()),
    };
    checked.map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(blob)
}

/// Decodes `capture` with `basis` (see [`decode`]).
///
/// # Errors
/// An invalid blob, or what [`decode`] reports.
pub fn decode_with(capture: &Capture, basis: &Basis, opts: &DecodeOptions) -> Result<(LightField, DecodeReport)> {
    decode_with_observer(capture, basis, opts, &|_, _| {})
}

/// [`decode_with`], calling `observer` after each tile (see [`decode_observed`]).
///
/// # Errors
/// An invalid blob, or what [`decode`] reports.
pub fn decode_with_observer(
    capture: &Capture,
    basis: &Basis,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    match opts.patch_views_for(capture, basis)? {
        PatchViews::Four => decode_basis::<4, 4, 5200>(capture, basis, opts, observer),
        PatchViews::Five => decode_basis::<5, 5, 8125>(capture, basis, opts, observer),
    }
}

/// [`decode_with_observer`] for one patch shape.
fn decode_basis<const PU: usize, const PV: usize, const N: usize>(
    capture: &Capture,
    basis: &Basis,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    let trained = opts.schedule == SolveSchedule::Trained;
    match basis {
        // With the model trial, a DCT decode screens the shipped ensemble on pilots and
        // leans to the DCT: the ensemble only where its pilots clearly predict better.
        Basis::Dct if opts.model_trial => {
            let lean = ModelPick::Trial { towards: Pick::First, margin: DCT_LEAN };
            trial_decode::<PU, PV, N>(
                capture,
                None,
                slf_firmware::MemberChoice::Screened(slf_firmware::ChoiceRule::DEFAULT),
                lean,
                opts,
                observer,
            )
        }
        Basis::Dct => {
            let dictionary = Dictionary::<5, 5, PU, PV, 13>::dct();
            // The DCT takes the schedules of the shipped blob, whose cold one is trained on
            // the DCT's solves (the screen's).
            match ensemble::<PU, PV>(None)?.schedules().filter(|_| trained) {
                Some(schedules) => {
                    let model = slf_firmware::ScheduledDictionary { dictionary, schedules };
                    decode_observed::<PU, PV, N, _>(capture, &model, opts, observer)
                }
                None => decode_observed::<PU, PV, N, _>(capture, &dictionary, opts, observer),
            }
        }
        Basis::Ensemble { blob, choice } if opts.model_trial => {
            let even = ModelPick::Trial { towards: Pick::Second, margin: 1.0 };
            trial_decode::<PU, PV, N>(capture, blob.as_deref(), *choice, even, opts, observer)
        }
        Basis::Ensemble { blob, choice } => {
            let ensemble = ensemble::<PU, PV>(blob.as_deref())?;
            let model = slf_firmware::EnsembleModel::new(ensemble, *choice);
            let model = if trained { model } else { model.with_schedules(None) };
            decode_observed::<PU, PV, N, _>(capture, &model, opts, observer)
        }
    }
}

/// The decode of the DCT or the ensemble of `blob` (the shipped one for `None`) with
/// `choice`, whichever the model trial picks by `pick`.
fn trial_decode<const PU: usize, const PV: usize, const N: usize>(
    capture: &Capture,
    blob: Option<&[u8]>,
    choice: slf_firmware::MemberChoice,
    pick: ModelPick,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    let model = slf_firmware::EnsembleModel::new(ensemble::<PU, PV>(blob)?, choice);
    let model = if opts.schedule == SolveSchedule::Trained { model } else { model.with_schedules(None) };
    // The trial's other model: the DCT the ensemble screens with, on its schedules.
    match model.scheduled_screen() {
        Some(dct) => decode_picked::<PU, PV, N, _, _>(capture, &dct, &model, pick, opts, observer),
        None => {
            let dct = Dictionary::<5, 5, PU, PV, 13>::dct();
            decode_picked::<PU, PV, N, _, _>(capture, &dct, &model, pick, opts, observer)
        }
    }
}

/// Which of [`decode_picked`]'s two models decodes the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelPick {
    /// The one named.
    Given(Pick),
    /// The one the model trial picks ([`slf_firmware::TrialErrors::pick_leaning`]): `towards` unless the
    /// other's pilots err below `margin` times its.
    Trial {
        /// The model kept on a tie or without pilots.
        towards: Pick,
        /// How far below (RMS) the other's error must be.
        margin: f32,
    },
}

/// The ensemble of `blob` (the shipped one of the patch for `None`) for `5 x 5 x PU x PV x
/// 13` patches.
///
/// # Errors
/// A blob that does not validate, or of the other patch (named, with the flag to change).
pub fn ensemble<const PU: usize, const PV: usize>(
    blob: Option<&[u8]>,
) -> Result<slf_firmware::Ensemble<'_, 5, 5, PU, PV, 13>> {
    let views = PatchViews::of_views(PU, PV).ok_or_else(|| anyhow!("no patch of {PU} x {PV} views"))?;
    let bytes = blob.unwrap_or(views.shipped_ensemble());
    if let Some(made) = PatchViews::of_blob(bytes).filter(|&m| m != views) {
        bail!(
            "the ensemble blob is for {} patches, this decode's patch is {} (--patch-views {views}): pass \
             --patch-views {made}, or train a blob for it with slf train --patch-views {views}",
            made.shape_name(),
            views.shape_name()
        );
    }
    slf_firmware::Ensemble::<5, 5, PU, PV, 13>::new(bytes).map_err(|e| anyhow!("ensemble blob: {e}"))
}

/// Patches the CS decoder decodes in `capture` with `views`-view patches (every tile's
/// patches in every angular window): the unit that times per patch are given in, also for
/// methods without patches.
///
/// # Errors
/// A capture the decoder does not take.
pub fn patch_count(capture: &Capture, views: PatchViews) -> Result<u64> {
    fn count<const PU: usize, const PV: usize, const N: usize>(capture: &Capture) -> Result<u64> {
        let decoder = capture.decoder::<PU, PV, N>(Sl0Config::DEFAULT)?;
        let windows = decoder.windows().count() as u64;
        Ok(decoder.tiles((2, 2)).map(|t| u64::from(t.lenslet_rows / 5) * u64::from(t.lenslet_cols / 5) * windows).sum())
    }
    match views {
        PatchViews::Four => count::<4, 4, 5200>(capture),
        PatchViews::Five => count::<5, 5, 8125>(capture),
    }
}

/// How overlapping patches are averaged where they meet: the firmware's window, so the
/// host and the device weigh estimates alike.
pub use slf_firmware::overlap::Window;

/// Where the projection's noise ball comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseSource {
    /// The capture's noise description ([`Capture::noise_model`]); exact projection if it
    /// has none.
    #[default]
    Capture,
    /// [`Sl0Config::noise`] and [`Sl0Config::shot`] as given (both 0: exact).
    Config,
}

/// The default stride: 2 lenslets, with [`Window::Tapered`], for the default full-view
/// patch ([`PatchViews::Five`]). With the paper's patch the default was 3 (chosen on the
/// speed-against-error plot, `docs/results-real.md`: on three real scenes stride 3 tapered
/// gained 1.2 / 1.4 / 2.1 dB over disjoint patches at pixel k = 1 / 3 and lenslet k = 3, and
/// no grid shows). A full-view patch position costs about a quarter of the four angular
/// windows it replaces but gives one estimate of a view where they gave up to four: at
/// stride 3 it decodes the realistic set in half the time with +0.19 dB at pixel k = 1 but
/// -0.19 dB at pixel k = 3 and a worse spectral angle (`docs/results-depth.md`, issue 40), at
/// stride 2 better in every measure and setting in about the same time as the paper's patch
/// at stride 3 (`--patch-views 4 --stride 3` is the decode before issue 40). The seam-driven
/// adaptive rule ([`DecodeOptions::adaptive`]) lands on the uniform strides' curve, not
/// above it, so it is off by default.
pub const DEFAULT_STRIDE: (u8, u8) = (2, 2);

/// The white balance of a decode ([`slf_firmware::gains`]): each band's measurements divided
/// by a gain before the solve and the decoded patch multiplied back.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Balance {
    /// Gains of 1: the plain decode.
    Off,
    /// Grey world: each band's mean over the capture's valid samples
    /// ([`slf_firmware::TileDecoder::estimate_gains`]), as the device does it.
    #[default]
    GreyWorld,
    /// These gains (e.g. from a white reference or a known illuminant).
    Gains([f32; 13]),
}

/// How to decode.
#[derive(Clone, Copy, Debug)]
pub struct DecodeOptions {
    pub sl0: Sl0Config,
    /// Where the noise ball comes from.
    pub noise: NoiseSource,
    /// Patches per tile (rows, cols): the unit of parallel work.
    pub tile_patches: (u16, u16),
    /// Show a progress bar once the run has taken a second.
    pub progress: bool,
    /// Lenslets between patch origins (rows, cols), each in 1..=5. 5 is the grid of
    /// disjoint patches; smaller strides add patch grids shifted by multiples of the stride,
    /// (5 / stride)^2 times the patches, averaged by [`Self::window`]. Default
    /// [`DEFAULT_STRIDE`] with the tapered window.
    pub stride: (u8, u8),
    /// How overlapping patches are averaged.
    pub window: Window,
    /// Decode a shifted patch only where the disjoint grid's first pass shows a seam there:
    /// where the steps across the grid's borders inside the patch are more than this many
    /// times the steps between the other lenslets ([`Seams::score`]); `None` decodes every
    /// shifted patch.
    pub adaptive: Option<f32>,
    /// The white balance.
    pub balance: Balance,
    /// The disparities each spatial block may be sheared to ([`slf_firmware::disparity`]);
    /// `None` (the default): the capture's, [`DisparityRange::for_snapshots`] (-1..=1, in
    /// half pixels for a single snapshot); [`DisparityRange::OFF`] decodes every patch
    /// unsheared.
    pub disparities: Option<DisparityRange>,
    /// Whether a block sheared at the frame's edge is decoded unsheared as well
    /// ([`TileDecoder::with_edge_fallback`]); off, the views no sheared patch reached are
    /// filled from their lenslet's other views. On by default.
    pub edge_fallback: bool,
    /// Whether every sheared block is decoded unsheared as well
    /// ([`TileDecoder::with_sheared_fallback`]): off by default, on in the preview, whose
    /// disjoint grid leaves the values between blocks sheared otherwise to no patch.
    pub sheared_fallback: bool,
    /// With a stride below 5: decode the disjoint grid first, then start every shifted
    /// patch (those the adaptive rule asks for) from that decode ([`slf_firmware::tile::PatchSeed`],
    /// [`slf_firmware::PatchModel::decode_seeded`]): one seeded solve a shifted patch
    /// where an unseeded one takes the DCT's cold solve and the member's warm one. On by
    /// default: the realistic set decodes as well or better in 0.71 of the time
    /// (`docs/bench/README.md`).
    pub seeded: bool,
    /// The patch's views per axis; `None` (the default): [`PatchViews::fitting`] the
    /// capture's lenslets, or the patch a given ensemble blob was made for.
    pub patch_views: Option<PatchViews>,
    /// The solves' schedule: a blob's trained ones (the default), or the hand-set one of
    /// [`Self::sl0`].
    pub schedule: SolveSchedule,
    /// The filters' response matrix (row-major, filter x band) and where the decode puts
    /// it ([`slf_firmware::response`], [`ResponseModel`]): a calibration's, whose leaked
    /// light the decode then separates. `None`: one-hot filters.
    pub response: Option<(Response<13>, ResponseModel)>,
    /// The plausibility check of every solved patch ([`TileDecoder::with_plausibility`]):
    /// [`Plausibility::DEFAULT`] unless set.
    pub plausibility: Plausibility,
    /// Whether each solved patch's error is estimated from held-out measurements
    /// ([`TileDecoder::with_error_estimate`], [`DecodeReport::error_map`]). Off by default:
    /// a solve more a patch.
    pub error_estimate: bool,
    /// Whether half-pixel disparities are checked against the whole ones by the held-out
    /// error estimate ([`TileDecoder::with_shear_check`]). Off by default.
    pub shear_check: bool,
    /// Whether an ensemble decode picks, for the frame, the ensemble or the DCT it screens
    /// with by their held-out errors on pilot patches ([`crate::decode::trial`]). Off here,
    /// where a decode measures the ensemble itself (`slf compare`, `slf evaluate`'s
    /// ensemble rows, the bench's choice points); on in every preset
    /// ([`crate::decode::preset::Preset::options`]), which `slf decode` and `slf.decode`
    /// run. A DCT decode with it (the preview's) screens the shipped ensemble on the pilots
    /// and leans to the DCT ([`crate::decode::trial::DCT_LEAN`]).
    pub model_trial: bool,
    /// Whether a decode with half-pixel disparities first checks them on pilot patches
    /// against the whole ones beside them by the held-out error estimate, and decodes the
    /// frame with whole disparities only where the whole ones estimate clearly better
    /// ([`crate::decode::trial::halves_alias`]). Off here, on in the default and best
    /// presets.
    pub shear_trial: bool,
}

/// Which schedule the solves take.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SolveSchedule {
    /// The trained schedules the ensemble's blob carries (the DCT takes the shipped blob's);
    /// a blob without them (format version 1) solves with the hand-set one.
    #[default]
    Trained,
    /// The hand-set schedule: sigma annealed by --sigma-f with --steps a level down to
    /// --sigma-min (the decode before 2026-11-26).
    Annealed,
}

impl Default for DecodeOptions {
    fn default() -> Self {
        Self {
            sl0: Sl0Config::DEFAULT,
            noise: NoiseSource::Capture,
            tile_patches: (2, 2),
            progress: false,
            stride: DEFAULT_STRIDE,
            window: Window::Tapered,
            adaptive: None,
            balance: Balance::default(),
            disparities: None,
            edge_fallback: true,
            sheared_fallback: false,
            seeded: true,
            schedule: SolveSchedule::Trained,
            patch_views: None,
            response: None,
            plausibility: Plausibility::DEFAULT,
            error_estimate: false,
            shear_check: false,
            model_trial: false,
            shear_trial: false,
        }
    }
}

impl DecodeOptions {
    /// Disjoint patches (stride 5, the uniform window), unsheared, otherwise the defaults:
    /// the grid the firmware's tile decoder walks, one estimate per patch and angular
    /// window, as the device decodes its tiles.
    pub fn disjoint() -> Self {
        Self { stride: (5, 5), window: Window::Uniform, disparities: Some(DisparityRange::OFF), ..Self::default() }
    }

    /// The disparities a decode of `capture` searches: [`Self::disparities`], or the
    /// capture's default.
    pub fn disparities_for(&self, capture: &Capture) -> DisparityRange {
        let snapshots = u8::try_from(capture.description.frames.len()).unwrap_or(u8::MAX);
        self.disparities.unwrap_or(DisparityRange::for_snapshots(snapshots))
    }

    /// The patch a decode of `capture` with `basis` uses: [`Self::patch_views`], else the
    /// patch a given blob was made for, else the one [`PatchViews::fitting`] the capture.
    ///
    /// # Errors
    /// Lenslets with fewer views than the patch, or than any patch (4 x 4), in one line.
    pub fn patch_views_for(&self, capture: &Capture, basis: &Basis) -> Result<PatchViews> {
        let views = (capture.description.views[0], capture.description.views[1]);
        let Some(fits) = PatchViews::fitting(views) else {
            bail!(
                "the capture's lenslets have {} x {} views: the decoder's patches need at least 4 x 4",
                views.0,
                views.1
            );
        };
        let chosen = self.patch_views.or(basis.blob_views()).unwrap_or(fits);
        ensure!(
            chosen.count() <= views.0.min(views.1),
            "--patch-views {chosen}: the capture's lenslets have {} x {} views, fewer than the patch's {chosen} x \
             {chosen}: pass --patch-views {fits}",
            views.0,
            views.1
        );
        Ok(chosen)
    }

    /// Whether the decode seeds its shifted patches: [`Self::seeded`] with a stride below 5
    /// (the disjoint grid alone has no shifted patch).
    pub fn seeds(&self) -> bool {
        self.seeded && self.stride != (5, 5)
    }

    /// The solver's config for `capture`: [`Self::sl0`] with the noise ball from
    /// [`Self::noise`].
    pub fn solver_config(&self, capture: &Capture) -> Sl0Config {
        match (self.noise, capture.noise_model()) {
            (NoiseSource::Config, _) => self.sl0,
            (NoiseSource::Capture, Some((noise, shot))) => Sl0Config { noise, shot, ..self.sl0 },
            (NoiseSource::Capture, None) => Sl0Config { noise: 0.0, shot: 0.0, ..self.sl0 },
        }
    }
}

/// The firmware's tile decoder for `capture` as [`decode`] runs it: the solver config of
/// [`DecodeOptions::solver_config`] and the band gains of [`DecodeOptions::balance`]
/// (estimated from the frame for [`Balance::GreyWorld`], as the device does).
///
/// # Errors
/// A capture the decoder cannot take, or gains outside `[1/64, 64]`.
pub fn tile_decoder<'a, const PU: usize, const PV: usize, const N: usize>(
    capture: &'a Capture,
    opts: &'a DecodeOptions,
) -> Result<TileDecoder<'a, 5, 5, PU, PV, 13, N>> {
    let decoder = capture.decoder::<PU, PV, N>(opts.solver_config(capture))?;
    // The response first: the white balance's gains are of the unmixed spectrum.
    let decoder = match &opts.response {
        Some((response, model)) => {
            decoder.with_response(response, *model).map_err(|e| anyhow!("{}: {e}", capture.source()))?
        }
        None => decoder,
    };
    let gains = match opts.balance {
        Balance::Off => [1.0; 13],
        Balance::GreyWorld => {
            let raw = capture.raw_frames()?;
            decoder
                .estimate_gains(&mut FrameSource::new(&raw))
                .map_err(|e| anyhow!("{}: cannot read the frame for its white balance: {e:?}", capture.source()))?
        }
        Balance::Gains(g) => g,
    };
    let decoder = decoder.with_gains(&gains).map_err(|e| anyhow!("gains {gains:?}: {e}"))?;
    let decoder = decoder
        .with_error_estimate(opts.error_estimate.then_some(HoldOut::DEFAULT))
        .map_err(|e| anyhow!("{e}"))?
        .with_plausibility(opts.plausibility)
        .map_err(|e| anyhow!("--plausible {}:{}: {e}", opts.plausibility.factor, opts.plausibility.margin))?;
    Ok(decoder
        .with_disparities(opts.disparities_for(capture))
        .with_edge_fallback(opts.edge_fallback)
        .with_sheared_fallback(opts.sheared_fallback)
        .with_shear_check(opts.shear_check))
}

/// The tiles of the patch grids shifted by `(dy, dx)` lenslets for every multiple of the
/// stride below 5 other than (0, 0), each of at most `per` patches, whole patches only
/// (the unshifted grid, with its edge strips, already covers every lenslet).
pub fn shifted_tiles(lenslets: (usize, usize), stride: (u8, u8), per: (u16, u16)) -> Vec<Tile> {
    let offsets = |s: u8| (0..5usize).step_by(usize::from(s.clamp(1, 5)));
    let spans = |total: usize, off: usize, per: usize| -> Vec<(usize, usize)> {
        let whole = total.saturating_sub(off) / 5;
        let per = per.max(1);
        (0..whole.div_ceil(per)).map(|i| (off + i * per * 5, per.min(whole - i * per) * 5)).collect()
    };
    let mut tiles = Vec::new();
    for dy in offsets(stride.0) {
        for dx in offsets(stride.1) {
            if (dy, dx) == (0, 0) {
                continue;
            }
            for &(r0, nr) in &spans(lenslets.0, dy, usize::from(per.0)) {
                for &(c0, nc) in &spans(lenslets.1, dx, usize::from(per.1)) {
                    tiles.push(Tile {
                        lenslet_row: r0 as u16,
                        lenslet_col: c0 as u16,
                        lenslet_rows: nr as u16,
                        lenslet_cols: nc as u16,
                    });
                }
            }
        }
    }
    tiles
}

/// Which decoder made a patch: a row of [`DecodeReport::member_map`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchDecoder {
    /// SL0 with this ensemble member (the last solve's).
    Member(u16),
    /// SL0 with the single dictionary (the DCT, or a one-member basis).
    Dictionary,
    /// Per-pixel spectral interpolation: the patch measured fewer than `min_bands` bands.
    Interpolated,
    /// The flat short path: each band its mean, no solve.
    Flat,
}

impl PatchDecoder {
    /// The decoder of a patch from its report.
    pub fn of(report: &PatchReport) -> Self {
        match (report.outcome.ended, report.member) {
            (Ended::Interpolated, _) => Self::Interpolated,
            (Ended::Flat, _) => Self::Flat,
            (_, Some(m)) => Self::Member(m),
            (_, None) => Self::Dictionary,
        }
    }

    /// Its name in the member map's `decoder` column.
    pub fn name(self) -> &'static str {
        match self {
            Self::Member(_) => "member",
            Self::Dictionary => "dictionary",
            Self::Interpolated => "interpolated",
            Self::Flat => "flat",
        }
    }
}

/// What a decode did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DecodeReport {
    pub patches: TileReport,
    pub tiles: usize,
    pub failed_tiles: usize,
    /// SL0 steps over all patches (the last solve of each).
    pub steps: u64,
    /// Solves over all patches (more than one per patch with an ensemble).
    pub solves: u64,
    /// Which decoder made each decoded patch, by patch origin: the ensemble member, the
    /// single dictionary, interpolation or the flat short path.
    pub member_map: Vec<(PatchOrigin, PatchDecoder)>,
    /// Light-field values no decoded patch covered (left at 0).
    pub uncovered: usize,
    /// Values of a view no (sheared) patch covered, taken from the lenslet's other views.
    pub filled: usize,
    /// The disparity each spatial block was sheared to, by its first patch's origin
    /// (empty when the decode searched no disparity).
    pub disparity_map: Vec<(PatchOrigin, Disparity)>,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The band gains the decode used (1 without white balance).
    pub gains: [f32; 13],
    /// The patch it decoded with (`None` only in a report made by hand).
    pub patch_views: Option<PatchViews>,
    /// Each estimated patch's error estimate (RMS per value, the output's units), by
    /// origin ([`DecodeOptions::error_estimate`]; empty without it).
    pub error_map: Vec<(PatchOrigin, f32)>,
    /// What the model trial picked ([`DecodeOptions::model_trial`]; `None` without it).
    pub trial: Option<TrialReport>,
    /// What the shear trial found ([`DecodeOptions::shear_trial`]; `None` without it or
    /// without half-pixel disparities).
    pub shear_trial: Option<ShearTrialReport>,
}

/// The shear trial's finding in a decode ([`crate::decode::trial::frame_shear_trial`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShearTrialReport {
    /// Pilot patches at a half-pixel disparity that estimated both.
    pub pilots: u32,
    /// Whether the decode kept its half-pixel disparities (else whole ones only).
    pub halves: bool,
    /// The held-out error estimate at the half-pixel disparities (RMS over the pilots).
    pub half_error: f64,
    /// At the better whole disparity beside each.
    pub whole_error: f64,
}

/// The model trial's picks in a decode ([`crate::decode::trial`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrialReport {
    /// Pilot patches that estimated both models.
    pub pilots: u32,
    /// Whether the DCT decoded the frame (else the ensemble).
    pub dct: bool,
    /// The DCT's held-out error estimate over the pilots (RMS, the output's units).
    pub dct_error: f64,
    /// The ensemble's.
    pub ensemble_error: f64,
}

/// Weighted sums of the patch estimates over one tile's lenslets and the halo a sheared
/// patch reaches beyond them (`halo` lenslets on every side), all views and bands.
struct TileSums<const PU: usize, const PV: usize> {
    tile: Tile,
    views: (usize, usize),
    window: Window,
    halo: usize,
    sum: Vec<f32>,
    weight: Vec<f32>,
    steps: u64,
    solves: u64,
    members: Vec<(PatchOrigin, PatchDecoder)>,
    disparities: Vec<(PatchOrigin, Disparity)>,
    errors: Vec<(PatchOrigin, f32)>,
}

impl<const PU: usize, const PV: usize> TileSums<PU, PV> {
    fn new(tile: Tile, views: (usize, usize), window: Window, halo: usize) -> Self {
        let (rows, cols) = (tile.lenslet_rows as usize + 2 * halo, tile.lenslet_cols as usize + 2 * halo);
        let n = rows * cols * views.0 * views.1 * 13;
        let (sum, weight) = (vec![0.0; n], vec![0.0; n]);
        Self {
            tile,
            views,
            window,
            halo,
            sum,
            weight,
            steps: 0,
            solves: 0,
            members: Vec::new(),
            disparities: Vec::new(),
            errors: Vec::new(),
        }
    }

    /// Lenslet rows and columns of the buffer.
    fn extent(&self) -> (usize, usize) {
        (self.tile.lenslet_rows as usize + 2 * self.halo, self.tile.lenslet_cols as usize + 2 * self.halo)
    }

    /// Index in the buffer's `(s, t, u, v, b)` order, `(s, t)` counted from the halo's corner.
    fn at(&self, s: usize, t: usize, u: usize, v: usize, b: usize) -> usize {
        (((s * self.extent().1 + t) * self.views.0 + u) * self.views.1 + v) * 13 + b
    }
}

impl<const PU: usize, const PV: usize, const N: usize> PatchSink<N> for TileSums<PU, PV> {
    type Error = core::convert::Infallible;

    fn accept(&mut self, o: PatchOrigin, patch: &[f32; N], report: &PatchReport) -> Result<(), Self::Error> {
        self.steps += u64::from(report.outcome.iterations);
        self.solves += u64::from(report.solves);
        self.members.push((o, PatchDecoder::of(report)));
        if (o.view_row, o.view_col) == (0, 0) && self.halo > 0 && !report.fallback {
            self.disparities.push((o, o.disparity));
        }
        if let (Some(e), false) = (report.error, report.fallback) {
            self.errors.push((o, e));
        }
        let scale = if report.fallback { slf_firmware::disparity::FALLBACK_WEIGHT } else { 1.0 };
        // The halo's corner, in sensor lenslets.
        let (r0, c0) =
            (self.tile.lenslet_row as isize - self.halo as isize, self.tile.lenslet_col as isize - self.halo as isize);
        let (rows, cols) = self.extent();
        // A pixel at a time: its 13 bands are consecutive in the patch and in the buffer, and
        // share the pixel's position and weight, found once instead of once a value (7 % of a
        // preview's one-thread time when they were, 1.6 % now; `perf record`, cotton_128).
        for (p, bands) in patch.as_chunks::<13>().0.iter().enumerate() {
            let [s, t, u, v, _] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(p * 13);
            // The pixel the value was read from (sheared patches: shifted per view).
            let Some((r, c)) = o.lenslet::<5, 5>(s, t, u, v, self.views) else { continue };
            let (Ok(r), Ok(c)) = (usize::try_from(r - r0), usize::try_from(c - c0)) else { continue };
            if r >= rows || c >= cols {
                continue;
            }
            let j = self.at(r, c, o.view_row as usize + u, o.view_col as usize + v, 0);
            let w = scale * self.window.weight::<5, 5>(s, t);
            for ((sum, weight), &x) in self.sum[j..j + 13].iter_mut().zip(&mut self.weight[j..j + 13]).zip(bands) {
                *sum += w * x;
                *weight += w;
            }
        }
        Ok(())
    }

    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Decodes every tile of `capture` with `model` (a dictionary or an ensemble); returns the
/// light field `(U, V, S, T, 13)`.
///
/// # Errors
/// A capture the decoder cannot take (band count, views, mask), with the reason.
pub fn decode<const PU: usize, const PV: usize, const N: usize, M: PatchModel<5, 5, PU, PV, 13, N> + Sync>(
    capture: &Capture,
    model: &M,
    opts: &DecodeOptions,
) -> Result<(LightField, DecodeReport)> {
    decode_observed(capture, model, opts, &|_, _| {})
}

/// [`decode`], calling `observer` after each tile with (tiles done, tiles in the pass), from
/// the worker threads: a progress display of the caller's own (the Python package's
/// callback). The adaptive rule ([`DecodeOptions::adaptive`]) makes a second pass.
///
/// # Errors
/// As [`decode`].
pub fn decode_observed<const PU: usize, const PV: usize, const N: usize, M: PatchModel<5, 5, PU, PV, 13, N> + Sync>(
    capture: &Capture,
    model: &M,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    decode_picked(capture, model, model, ModelPick::Given(Pick::Second), opts, observer)
}

/// [`decode_observed`] with two models: decoded by the one `pick` names, or by the one the
/// model trial picks for the frame ([`crate::decode::trial`]).
///
/// # Errors
/// As [`decode`].
pub fn decode_picked<const PU: usize, const PV: usize, const N: usize, A, Z>(
    capture: &Capture,
    first: &A,
    second: &Z,
    pick: ModelPick,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)>
where
    A: PatchModel<5, 5, PU, PV, 13, N> + Sync,
    Z: PatchModel<5, 5, PU, PV, 13, N> + Sync,
{
    let start = Instant::now();
    let d = &capture.description;
    ensure!(d.bands_nm.len() == 13, "the decoder's patch has 13 bands, the capture {}", d.bands_nm.len());
    if let Some(asked) = opts.patch_views {
        ensure!(
            asked.count() == PU && asked.count() == PV,
            "--patch-views {asked}: this decoder's patch has {PU} x {PV} views"
        );
    }
    ensure!(
        PU <= d.views[0] && PV <= d.views[1],
        "--patch-views {PU}: the capture's lenslets have {} x {} views, fewer than the patch's {PU} x {PV}",
        d.views[0],
        d.views[1]
    );
    let decoder = tile_decoder::<PU, PV, N>(capture, opts)?;
    let gains = *decoder.gains();
    let raw = capture.raw_frames()?;
    ensure!(
        (1..=5).contains(&opts.stride.0) && (1..=5).contains(&opts.stride.1),
        "stride {:?}: each axis must be in 1..=5 lenslets",
        opts.stride
    );
    let base: Vec<Tile> = decoder.tiles(opts.tile_patches).collect();
    ensure!(
        !base.is_empty(),
        "the sensor ({} x {} lenslets) is smaller than one 5 x 5 patch",
        d.lenslets[0],
        d.lenslets[1]
    );
    let lenslets = (d.lenslets[0], d.lenslets[1]);
    let views = (d.views[0], d.views[1]);
    let range = decoder.config().raw.range();
    // The trials' pilots by the decode's patches: the disjoint grid's blocks times the
    // stride's shifts.
    let shifts = |s: u8| 5usize.div_ceil(usize::from(s));
    let blocks: usize = base.iter().map(|t| usize::from(t.lenslet_rows / 5) * usize::from(t.lenslet_cols / 5)).sum();
    let budget = pilot_budget(blocks * shifts(opts.stride.0) * shifts(opts.stride.1));
    // The shear trial first: half-pixel shears off for the frame where its pilots estimate
    // the whole ones clearly better (by the estimating solve, `second`'s), so the model
    // trial's pilots are sheared as the decode will be.
    let sheared = (opts.shear_trial && decoder.disparities().has_halves())
        .then(|| frame_shear_trial(&decoder, second, &raw, &base, budget));
    let alias = sheared.as_ref().is_some_and(halves_alias);
    let decoder = if alias { decoder.with_disparities(decoder.disparities().with_halves(false)) } else { decoder };
    let (pick, trialled) = match pick {
        ModelPick::Given(p) => (p, None),
        ModelPick::Trial { towards, margin } => {
            let t = frame_trial(&decoder, first, second, &raw, &base, budget);
            (t.pick_leaning(towards, margin), Some(t))
        }
    };
    let model = Picked { first, second, pick };
    let model = &model;
    let halo = decoder.disparities().halo(views.0.max(views.1));
    let run = |tiles: &[Tile], prior: Option<&LightField>| -> Vec<(TileSums<PU, PV>, Result<TileReport, String>)> {
        let bar = ProgressBar::with_draw_target(Some(tiles.len() as u64), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("decoding {bar:40} {pos}/{len} tiles, {elapsed} elapsed, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let shown = AtomicBool::new(false);
        // Tiles done, counted here: the bar's position read after its increment could be
        // another thread's too, and an observer then saw one count twice.
        let done = AtomicUsize::new(0);
        let out = tiles
            .par_iter()
            .map_init(
                || Box::new(Workspace::<5, 5, PU, PV, 13, N>::new()),
                |ws, &tile| {
                    let mut sums = TileSums::new(tile, views, opts.window, halo);
                    let mut source = FrameSource::new(&raw);
                    let r = match prior {
                        Some(lf) => decoder.decode_tile_seeded(
                            model,
                            tile,
                            &mut source,
                            &mut FrameSeed::<PU, PV> { lf, views },
                            &mut sums,
                            ws,
                        ),
                        None => decoder.decode_tile(model, tile, &mut source, &mut sums, ws),
                    }
                    .map_err(|e| e.to_string());
                    bar.inc(1);
                    observer(done.fetch_add(1, Ordering::Relaxed) + 1, tiles.len());
                    if opts.progress && start.elapsed().as_secs_f64() > 1.0 && !shown.swap(true, Ordering::Relaxed) {
                        bar.set_draw_target(ProgressDrawTarget::stderr());
                    }
                    (sums, r)
                },
            )
            .collect();
        bar.finish_and_clear();
        out
    };
    // Unseeded, every patch in one parallel pass. Seeded, or with the adaptive rule, the
    // disjoint grid first, then the shifted patches (all, or those its seams ask for),
    // seeded from its decode unless told not to.
    let mut tiles = base;
    let seeded = opts.seeds();
    if opts.adaptive.is_none() && !seeded {
        tiles.extend(shifted_tiles(lenslets, opts.stride, opts.tile_patches));
    }
    let mut results = run(&tiles, None);
    if seeded && opts.adaptive.is_none() {
        let (first, _) = aggregate(&results, views, lenslets, tiles.len(), range);
        let shifted = shifted_tiles(lenslets, opts.stride, opts.tile_patches);
        results.extend(run(&shifted, Some(&first)));
        tiles.extend(shifted);
    }
    if let Some(threshold) = opts.adaptive {
        let (first, _) = aggregate(&results, views, lenslets, tiles.len(), range);
        let seams = Seams::new(&first);
        let chosen: Vec<Tile> = shifted_tiles(lenslets, opts.stride, (1, 1))
            .into_iter()
            .filter(|t| seams.score(t.lenslet_row as usize, t.lenslet_col as usize) > threshold)
            .collect();
        results.extend(run(&chosen, seeded.then_some(&first)));
        tiles.extend(chosen);
    }
    let (lf, mut report) = aggregate(&results, views, lenslets, tiles.len(), range);
    report.seconds = start.elapsed().as_secs_f64();
    report.gains = gains;
    report.patch_views = PatchViews::of_views(PU, PV);
    // A pilot of either trial costs three solves: three estimating ones for the shear
    // trial, the DCT's one and the ensemble's two for the model trial.
    report.solves += 3 * u64::from(sheared.map_or(0, |t| t.pilots) + trialled.map_or(0, |t| t.pilots));
    report.shear_trial = sheared.map(|t| {
        let (half_error, whole_error) = rms(&t);
        ShearTrialReport { pilots: t.pilots, halves: !alias, half_error, whole_error }
    });
    report.trial = trialled.map(|t| {
        let (dct_error, ensemble_error) = rms(&t);
        TrialReport { pilots: t.pilots, dct: pick == Pick::First, dct_error, ensemble_error }
    });
    Ok((lf, report))
}

/// A frame's decode as the start of the patches that overlap it ([`PatchSeed`]).
struct FrameSeed<'a, const PU: usize, const PV: usize> {
    lf: &'a LightField,
    views: (usize, usize),
}

impl<const PU: usize, const PV: usize, const N: usize> PatchSeed<N> for FrameSeed<'_, PU, PV> {
    fn seed(&mut self, o: PatchOrigin, patch: &mut [f32; N]) -> bool {
        let (rows, cols) = (self.lf.rows as isize, self.lf.cols as isize);
        for (p, bands) in patch.as_chunks_mut::<13>().0.iter_mut().enumerate() {
            let [s, t, u, v, _] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(p * 13);
            let Some((r, c)) = o.lenslet::<5, 5>(s, t, u, v, self.views) else { continue };
            // A sheared patch reaches past the sensor: its nearest lenslet's value.
            let (r, c) = (r.clamp(0, rows - 1) as usize, c.clamp(0, cols - 1) as usize);
            bands.copy_from_slice(self.lf.spectrum(o.view_row as usize + u, o.view_col as usize + v, r, c));
        }
        true
    }
}

/// The light field and the report from every tile's sums: each value the weighted mean of
/// the patch estimates that cover it.
fn aggregate<const PU: usize, const PV: usize>(
    results: &[(TileSums<PU, PV>, Result<TileReport, String>)],
    views: (usize, usize),
    lenslets: (usize, usize),
    tiles: usize,
    (lo, hi): (f32, f32),
) -> (LightField, DecodeReport) {
    let mut lf = LightField::zeros(views, lenslets.0, lenslets.1, 13);
    let mut sum = vec![0.0f32; lf.data.len()];
    let mut weight = vec![0.0f32; lf.data.len()];
    let mut report = DecodeReport { tiles, ..DecodeReport::default() };
    for (sums, r) in results {
        match r {
            Ok(t) => report.patches.add(t),
            Err(_) => report.failed_tiles += 1,
        }
        report.steps += sums.steps;
        report.solves += sums.solves;
        report.member_map.extend_from_slice(&sums.members);
        report.disparity_map.extend_from_slice(&sums.disparities);
        report.error_map.extend_from_slice(&sums.errors);
        let tile = sums.tile;
        let (rows, cols) = sums.extent();
        for s in 0..rows {
            for t in 0..cols {
                let (Some(r), Some(c)) = (
                    (tile.lenslet_row as usize + s).checked_sub(sums.halo),
                    (tile.lenslet_col as usize + t).checked_sub(sums.halo),
                ) else {
                    continue;
                };
                if r >= lenslets.0 || c >= lenslets.1 {
                    continue;
                }
                for u in 0..views.0 {
                    for v in 0..views.1 {
                        let src = sums.at(s, t, u, v, 0);
                        let dst = lf.index(u, v, r, c, 0);
                        for b in 0..13 {
                            sum[dst + b] += sums.sum[src + b];
                            weight[dst + b] += sums.weight[src + b];
                        }
                    }
                }
            }
        }
    }
    // Each value the weighted mean of estimates in the sensor's range [lo, hi]: the clamp
    // takes off only what rounding adds (the firmware's overlap ring does the same).
    for ((x, &s), &w) in lf.data.iter_mut().zip(&sum).zip(&weight) {
        if w > 0.0 {
            *x = (s / w).clamp(lo, hi);
        }
    }
    // A view of a lenslet no (sheared) patch covered takes the mean of the lenslet's
    // covered views, as the firmware's overlap ring does; a lenslet with none stays 0. Two
    // passes in the light field's memory order (views outermost), each mean adding the
    // covered views in view order: the same sums as a pass per lenslet and band, without
    // its stride of a whole view between reads.
    let plane = lenslets.0 * lenslets.1 * 13;
    let (mut mean, mut covered) = (vec![0.0f32; plane], vec![0u32; plane]);
    for (data, weight) in lf.data.chunks_exact(plane).zip(weight.chunks_exact(plane)) {
        for (((m, n), &x), &w) in mean.iter_mut().zip(covered.iter_mut()).zip(data).zip(weight) {
            if w > 0.0 {
                *m += x;
                *n += 1;
            }
        }
    }
    for (data, weight) in lf.data.chunks_exact_mut(plane).zip(weight.chunks_exact(plane)) {
        for (((x, &w), &m), &n) in data.iter_mut().zip(weight).zip(&mean).zip(&covered) {
            if w > 0.0 {
                continue;
            }
            if n > 0 {
                *x = (m / n as f32).clamp(lo, hi);
                report.filled += 1;
            } else {
                report.uncovered += 1;
            }
        }
    }
    (lf, report)
}

/// The disparity per lenslet (row-major, `rows x cols`) from a decode's
/// [`DecodeReport::disparity_map`]: the mean of the chosen disparities of the 5 x 5 blocks
/// that cover the lenslet (overlapping blocks at a stride below 5), NaN where none does.
pub fn disparity_per_lenslet(blocks: &[(PatchOrigin, Disparity)], rows: usize, cols: usize) -> Vec<f32> {
    per_lenslet(blocks.iter().map(|(o, d)| (o, f64::from(d.as_f32()))), rows, cols, |mean| mean)
}

/// `finish` of the mean of the values of the 5 x 5-lenslet blocks (by their origins) that
/// cover each lenslet (row-major, `rows x cols`), NaN where none does.
fn per_lenslet<'a>(
    blocks: impl Iterator<Item = (&'a PatchOrigin, f64)>,
    rows: usize,
    cols: usize,
    finish: impl Fn(f64) -> f64,
) -> Vec<f32> {
    let mut sum = vec![0.0f64; rows * cols];
    let mut count = vec![0u32; rows * cols];
    for (o, x) in blocks {
        for r in o.lenslet_row as usize..(o.lenslet_row as usize + 5).min(rows) {
            for c in o.lenslet_col as usize..(o.lenslet_col as usize + 5).min(cols) {
                sum[r * cols + c] += x;
                count[r * cols + c] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(&s, &n)| if n > 0 { finish(s / f64::from(n)) as f32 } else { f32::NAN }).collect()
}

/// The error estimate per lenslet (row-major, `rows x cols`) from a decode's
/// [`DecodeReport::error_map`]: the RMS of the estimates of the patches whose 5 x 5
/// lenslets cover it (every angular window, every overlapping patch), NaN where none does.
pub fn error_per_lenslet(patches: &[(PatchOrigin, f32)], rows: usize, cols: usize) -> Vec<f32> {
    per_lenslet(patches.iter().map(|(o, e)| (o, f64::from(*e) * f64::from(*e))), rows, cols, f64::sqrt)
}

/// The PSNR an error map estimates for a light field whose values span `data_range`: the
/// mean squared error is the mean of the lenslets' squared estimates (NaN ones left out);
/// `None` if none is finite.
pub fn estimated_psnr(map: &[f32], data_range: f64) -> Option<f64> {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for e in map.iter().filter(|e| e.is_finite()) {
        sum += f64::from(*e) * f64::from(*e);
        n += 1;
    }
    (n > 0).then(|| 10.0 * (data_range * data_range / (sum / n as f64).max(1e-20)).log10())
}

/// Steps between neighbouring lenslets of a decoded light field (mean absolute difference
/// over views and bands), to find where the disjoint grid's borders show.
pub struct Seams {
    /// Step between lenslet rows `y - 1` and `y` at column `x` (`y >= 1`), row-major.
    down: Vec<f32>,
    /// Step between lenslet columns `x - 1` and `x` at row `y` (`x >= 1`), row-major.
    right: Vec<f32>,
    cols: usize,
    rows: usize,
}

impl Seams {
    /// The steps of `lf`.
    pub fn new(lf: &LightField) -> Self {
        let (rows, cols) = (lf.rows, lf.cols);
        let per = (lf.views.0 * lf.views.1 * lf.bands) as f32;
        let step = |(y0, x0): (usize, usize), (y1, x1): (usize, usize)| {
            let mut total = 0.0f32;
            for u in 0..lf.views.0 {
                for v in 0..lf.views.1 {
                    let (a, b) = (lf.spectrum(u, v, y0, x0), lf.spectrum(u, v, y1, x1));
                    total += a.iter().zip(b).map(|(p, q)| (p - q).abs()).sum::<f32>();
                }
            }
            total / per
        };
        let mut down = vec![0.0; rows * cols];
        let mut right = vec![0.0; rows * cols];
        for y in 0..rows {
            for x in 0..cols {
                if y > 0 {
                    down[y * cols + x] = step((y - 1, x), (y, x));
                }
                if x > 0 {
                    right[y * cols + x] = step((y, x - 1), (y, x));
                }
            }
        }
        Self { down, right, cols, rows }
    }

    /// How much the disjoint grid's borders inside the patch at `(row, col)` stand out: the
    /// mean step across them over the mean step between the patch's other lenslets (0 for
    /// a patch that crosses no border).
    pub fn score(&self, row: usize, col: usize) -> f32 {
        let (mut seam, mut seams, mut inner, mut inners) = (0.0f32, 0u32, 0.0f32, 0u32);
        for y in row..(row + 5).min(self.rows) {
            for x in col..(col + 5).min(self.cols) {
                let i = y * self.cols + x;
                // Steps into (y, x) from above and from the left, inside the patch.
                for (inside, at_border, step) in
                    [(y > row, y % 5 == 0, self.down[i]), (x > col, x % 5 == 0, self.right[i])]
                {
                    if !inside {
                        continue;
                    }
                    if at_border {
                        (seam, seams) = (seam + step, seams + 1);
                    } else {
                        (inner, inners) = (inner + step, inners + 1);
                    }
                }
            }
        }
        if seams == 0 {
            return 0.0;
        }
        let inner = if inners > 0 { inner / inners as f32 } else { 0.0 };
        (seam / seams as f32) / inner.max(1e-6)
    }
}
