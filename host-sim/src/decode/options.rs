//! What a decode is asked to do ([`DecodeOptions`]) and with what ([`Basis`],
//! [`PatchViews`]): the settings [`crate::decode::cs`] takes, resolved from a user's flags by
//! [`crate::decode::settings`] and named by [`crate::decode::preset`].

use anyhow::{Result, anyhow, bail, ensure};
use slf_firmware::BandCount;
use slf_firmware::Shape;
use slf_firmware::{DisparityRange, Plausibility, Response, ResponseModel, Sl0Config};

use crate::io::capture::Capture;
use crate::io::patch::HostEnsemble;
use crate::io::patch::{BANDS, LENSLETS};

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
        [LENSLETS, LENSLETS, v, v, BANDS]
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
        format!("{LENSLETS} x {LENSLETS} x {v} x {v} x {BANDS}")
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
pub const MAX_BLOB: usize = slf_firmware::blob::blob_len(slf_firmware::FullViewShape::DIMS, u16::MAX as usize);

/// Reads and validates a dictionary blob file, of either patch ([`PatchViews`]); a file
/// larger than [`MAX_BLOB`], a FIFO or a device is refused before reading.
///
/// # Errors
/// A message with the file and what is wrong.
pub fn read_blob(path: &std::path::Path) -> Result<Vec<u8>> {
    crate::io::file_checks::regular_file(
        path,
        MAX_BLOB as u64,
        "of the largest dictionary blob of a decoder's patch (65,535 members)",
    )?;
    let blob = std::fs::read(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let checked = match PatchViews::of_blob(&blob) {
        Some(PatchViews::Five) => HostEnsemble::<5, 5, 8125>::new(&blob).map(|_| ()),
        // The paper's patch also reports a blob of neither shape (its dimension check).
        _ => HostEnsemble::<4, 4, 5200>::new(&blob).map(|_| ()),
    };
    checked.map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(blob)
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
    Gains([f32; BANDS]),
}

/// How to decode.
#[derive(Clone, Copy, Debug)]
pub struct DecodeOptions {
    pub sl0: Sl0Config,
    /// Where the noise ball comes from.
    pub noise: NoiseSource,
    /// Patches per tile (rows, cols): the unit of parallel work.
    pub tile_patches: (u16, u16),
    /// Tiles decoded together, in parallel, before their sums join the frame's rows
    /// ([`crate::decode::strip`]); 0: [`crate::decode::strip::BATCH_TILES_PER_THREAD`] a
    /// worker thread. The decode is the same bit for bit whatever it is; larger batches
    /// hold more tiles' sums at once.
    pub batch_tiles: usize,
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
    /// times the steps between the other lenslets ([`crate::decode::seams::seam_score`]);
    /// `None` decodes every shifted patch.
    pub adaptive: Option<f32>,
    /// The white balance.
    pub balance: Balance,
    /// The disparities each spatial block may be sheared to ([`slf_firmware::disparity`]);
    /// `None` (the default): the capture's, [`DisparityRange::for_capture`] (-1..=1, in
    /// half pixels for a single snapshot and on the lenslet mask on the aligned sensor; whole
    /// ones behind a lenslet grid, [`Self::disparities_for`]); [`DisparityRange::OFF`]
    /// decodes every patch unsheared.
    pub disparities: Option<DisparityRange>,
    /// Whether a block sheared at the frame's edge is decoded unsheared as well
    /// ([`slf_firmware::TileDecoder::with_edge_fallback`]); off, the views no sheared patch reached are
    /// filled from their lenslet's other views. On by default.
    pub edge_fallback: bool,
    /// Whether every sheared block is decoded unsheared as well
    /// ([`slf_firmware::TileDecoder::with_sheared_fallback`]): off by default, on in the preview, whose
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
    pub response: Option<(Response<BandCount<BANDS>>, ResponseModel)>,
    /// The plausibility check of every solved patch ([`slf_firmware::TileDecoder::with_plausibility`]):
    /// [`Plausibility::DEFAULT`] unless set.
    pub plausibility: Plausibility,
    /// Whether each solved patch's error is estimated from held-out measurements
    /// ([`slf_firmware::TileDecoder::with_error_estimate`], [`crate::decode::report::DecodeReport::error_map`]). Off by default:
    /// a solve more a patch.
    pub error_estimate: bool,
    /// How the error is estimated where it is ([`EstimateBy`]).
    pub estimate_by: EstimateBy,
    /// How the model trial tells the models apart ([`TrialBy`]).
    pub trial_by: TrialBy,
    /// On a kronecker mask, each block mixed from the decode and the PPID baseline by their
    /// held-out errors ([`crate::decode::blend`]): three decodes and four PPIDs of the frame
    /// more. Off here (the plain decode, the device's); on in the default and best presets.
    pub baseline_blend: bool,
    /// Whether half-pixel disparities are checked against the whole ones by the held-out
    /// error estimate ([`slf_firmware::TileDecoder::with_shear_check`]). Off by default.
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
    /// ([`slf_firmware::ShearTrial::aliases`]). Off here, on in the default and best
    /// presets.
    pub shear_trial: bool,
    /// The per-patch maps the report keeps ([`Maps`]): none unless asked for, so a decode
    /// holds nothing that grows with the frame beyond its band of rows.
    pub maps: Maps,
}

/// The per-patch maps a decode's report keeps: which decoder made each patch
/// ([`crate::decode::report::DecodeReport::member_map`]) and each block's disparity
/// ([`crate::decode::report::DecodeReport::disparity_map`]). The disparities' counts, which
/// the summary prints, are kept either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Maps {
    pub members: bool,
    pub disparities: bool,
}

impl Maps {
    /// Both maps.
    pub const ALL: Self = Self { members: true, disparities: true };
}

/// How the model trial tells the DCT from the ensemble ([`DecodeOptions::model_trial`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TrialBy {
    /// Pilot patches, each decoded by both models from seven in eight of its measurements
    /// (about 0.1 of a solve a patch).
    #[default]
    Pilots,
    /// The frame decoded by each model again, as the decode makes it (seeds, overlap), from
    /// seven in eight samples ([`crate::decode::held_out`]): two more decodes of the frame.
    /// Where the light field does not hold each sample's value, the pilots.
    Decode,
}

/// How a decode's error is estimated ([`DecodeOptions::error_estimate`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum EstimateBy {
    /// The frame decoded again from seven in eight samples, by the same plan: the estimate
    /// of the decode actually made ([`crate::decode::held_out`]); a second decode's time.
    /// Where the light field does not hold each sample's value (a lenslet grid, a response
    /// in the projection), the patches' estimates.
    #[default]
    Decode,
    /// Each patch's own: one more solve of it from seven in eight of its measurements
    /// ([`slf_firmware::TileDecoder::with_error_estimate`]); a solve a patch.
    Patches,
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
            batch_tiles: 0,
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
            estimate_by: EstimateBy::Decode,
            trial_by: TrialBy::Pilots,
            baseline_blend: false,
            shear_check: false,
            model_trial: false,
            shear_trial: false,
            maps: Maps::default(),
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
    /// capture's default: [`DisparityRange::for_capture`] on the aligned sensor, whole
    /// disparities only behind a lenslet grid. There a patch at a half-pixel disparity reads
    /// the grid by the view cells' shares, a half view's cell the mean of two grid positions
    /// ([`slf_firmware::shares`]): on a plane at half a pixel it beats whole disparities by
    /// 7 dB (`tests/grid.rs`), but at pixel k = 1 the halves were ahead of whole disparities
    /// by more than 0.1 dB on 3 of 14 decodes (median -0.10 dB, worst -0.45, best +0.24:
    /// the realistic scenes at 64 x 64 lenslets and the HCI crops, behind grids turned 0.3
    /// degrees at 5.04 px and 1 degree at 5.1 px, `docs/results-grid-halves.md`); the shear
    /// trial kept them on every one. Read at the cells' centres, as before the shares, they
    /// were 0.35 to 2.37 dB lower still.
    pub fn disparities_for(&self, capture: &Capture) -> DisparityRange {
        let d = &capture.description;
        let snapshots = u8::try_from(d.frames.len()).unwrap_or(u8::MAX);
        let gridded = d.turned_grid().is_some();
        let default = DisparityRange::for_capture(d.mask.family(), snapshots);
        self.disparities.unwrap_or(if gridded { default.with_halves(false) } else { default })
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
