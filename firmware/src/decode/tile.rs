//! Tiles: decoding a rectangle of the raw frame patch by patch.
//!
//! A [`Tile`] is a rectangle of lenslets holding whole patches, with all snapshots. Its
//! samples come from a [`TileSource`] and its decoded patches go to a [`PatchSink`]; both
//! are traits so the same decoder reads a frame in RAM today and a sensor or an external
//! frame buffer over `embedded-hal` later. A source is asked for short runs of one row
//! (`PV` samples of one lenslet's view row, per snapshot), which maps onto both random
//! access into RAM and addressed reads of a serial frame buffer; a sequential-only sensor
//! FIFO is buffered tile by tile by its source.
//!
//! Where a patch has fewer views than a lenslet (`PU < U`), each spatial block is decoded
//! in overlapping angular windows that together cover every view; the sink sees each
//! window's origin and can average the overlaps.
//!
//! Bad input loses only itself: an invalid sample (defective pixel, non-finite, negative,
//! saturated) is left out of the patch's constraints and flags the patch; a patch with no
//! valid sample is reported to the sink as an error and the tile goes on; a source error
//! ends that tile only, and [`TileDecoder::decode_frame`] goes on with the next tile.

use core::fmt;
use core::num::NonZeroUsize;

use crate::log::log;
use crate::operators::disparity::{
    Best, Consistency, Disparity, DisparityRange, HalfViews, is_half, reach, rounded_shift, shift,
};
use crate::operators::shape::PatchShape;
use crate::sensor::defects::DefectList;
use crate::sensor::grid::LensletGrid;
use crate::sensor::mask::{LensletSize, Mask, MaskFamily};
use crate::sensor::raw::{Invalid, RawFormat};
use crate::sensor::response::Response;
use crate::solver::choice::{ModelOutcome, PatchModel};
use crate::solver::fractional::{MAX_GRID, from_sensor, to_sensor};
use crate::solver::holdout::{HoldOut, estimate, hold_out};
use crate::solver::interpolate::{bands_measured, interpolate_bands};
use crate::solver::mixing::{mix_all, unmix_all};
use crate::solver::plausible::{Plausibility, clip, implausible};
use crate::solver::shares;
use crate::solver::sl0::{Ended, Outcome, Sl0Config, SolveError, solve};
use crate::solver::workspace::{CellShares, MAX_PLACES, MAX_SHARE_VIEWS, Workspace};

/// The source trait lives with the raw frames (the sensor layer); named here too, where the
/// decoder that reads it is.
pub use crate::sensor::source::TileSource;

/// Where decoded patches go.
pub trait PatchSink<const N: usize> {
    /// A write failure. `Copy`, to travel in errors.
    type Error: Copy + fmt::Debug;

    /// A decoded patch (layout of [`PatchShape::index`]) at `origin`, with its report.
    ///
    /// # Errors
    /// The sink's own error; the decoder then abandons the current tile.
    fn accept(&mut self, origin: PatchOrigin, patch: &[f32; N], report: &PatchReport) -> Result<(), Self::Error>;

    /// A patch that could not be decoded; the decoder goes on with the next one.
    ///
    /// # Errors
    /// The sink's own error; the decoder then abandons the current tile.
    fn reject(&mut self, origin: PatchOrigin, error: SolveError) -> Result<(), Self::Error> {
        let _ = (origin, error);
        Ok(())
    }
}

/// Where a seeded decode ([`TileDecoder::decode_tile_seeded`]) finds its start: an
/// estimate of a patch from its overlapping neighbours' decode (on the host, the disjoint
/// grid's averaged decode of the frame; the device's strip does not seed, see
/// `docs/bench/README.md`).
pub trait PatchSeed<const N: usize> {
    /// Writes the estimate of the patch at `origin` into `patch`, in the layout a
    /// [`PatchSink`] receives (sensor units, each value at the pixel
    /// [`PatchOrigin::lenslet`] names; a value it names none of is not read); `false` if
    /// there is none. A patch without an estimate, or with a NaN or an infinity in it, is
    /// decoded from nothing.
    fn seed(&mut self, origin: PatchOrigin, patch: &mut [f32; N]) -> bool;
}

/// No estimate anywhere: every patch decodes from nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoSeed;

impl<const N: usize> PatchSeed<N> for NoSeed {
    fn seed(&mut self, _: PatchOrigin, _: &mut [f32; N]) -> bool {
        false
    }
}

/// The sensor: `lenslets` rows x cols of lenslets, each `lenslet` views.
/// The raw frame is `lenslets.0 * lenslet.rows` x `lenslets.1 * lenslet.cols` pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorGeometry {
    pub lenslets: (u16, u16),
    pub lenslet: LensletSize,
}

impl SensorGeometry {
    /// Raw frame rows and columns.
    pub fn frame_size(&self) -> (usize, usize) {
        (self.lenslets.0 as usize * self.lenslet.rows as usize, self.lenslets.1 as usize * self.lenslet.cols as usize)
    }
}

/// A rectangle of lenslets holding whole patches: origin and size, in lenslets. Its origin
/// need not be on the patch grid (edge tiles are aligned to the sensor's far edge).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tile {
    pub lenslet_row: u16,
    pub lenslet_col: u16,
    pub lenslet_rows: u16,
    pub lenslet_cols: u16,
}

/// How much smaller a whole disparity's estimated error must be than the half one's for the
/// shear check ([`TileDecoder::with_shear_check`]) to take it.
pub const SHEAR_MARGIN: f32 = 0.7;

/// Where a patch sits: its first lenslet, its angular window's first view, and the
/// disparity it was sheared to ([`crate::operators::disparity`]; zero: unsheared).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatchOrigin {
    pub lenslet_row: u16,
    pub lenslet_col: u16,
    pub view_row: u8,
    pub view_col: u8,
    pub disparity: Disparity,
}

impl PatchOrigin {
    /// The sensor lenslet (row, col) whose pixel the patch's grid position `(s, t)` of
    /// view `(u, v)` of its window names, for `PS x PT`-lenslet patches and lenslets of
    /// `views` (rows, cols) views: the patch's own lenslet shifted by the shear. For a view
    /// half a lenslet off the grid ([`crate::operators::disparity::is_half`]) that pixel lies between
    /// positions `s` and `s + 1`, and the last position names none (`None`). May lie
    /// outside the sensor (a sheared patch reaches beyond its rectangle; such values were
    /// not measured and a sink drops them). A sink puts the patch's value at `(s, t, u, v)`
    /// there: a decoded half-pixel patch is handed over at its pixels
    /// ([`crate::solver::fractional::to_sensor`]).
    #[inline]
    pub fn lenslet<const PS: usize, const PT: usize>(
        &self,
        s: usize,
        t: usize,
        u: usize,
        v: usize,
        views: (usize, usize),
    ) -> Option<(isize, isize)> {
        let d = self.disparity;
        let (vr, vc) = (self.view_row as usize + u, self.view_col as usize + v);
        if (is_half(d, vr, views.0) && s + 1 >= PS) || (is_half(d, vc, views.1) && t + 1 >= PT) {
            return None;
        }
        let (du, dv) = (shift(d, vr, views.0), shift(d, vc, views.1));
        Some(((self.lenslet_row as usize + s) as isize + du, (self.lenslet_col as usize + t) as isize + dv))
    }
}

/// Why samples of a patch were left out, as bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatchFlags(u8);

impl PatchFlags {
    /// A pixel of the defect list.
    pub const DEFECTIVE: Self = Self(1);
    /// A NaN or infinite sample.
    pub const NON_FINITE: Self = Self(2);
    /// A negative raw sample.
    pub const NEGATIVE: Self = Self(4);
    /// A sample above `max_valid` (saturated).
    pub const OVER_RANGE: Self = Self(8);

    /// Whether every bit of `other` is set.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// No flag set: every sample of the patch was a measurement.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The raw bits.
    pub fn bits(self) -> u8 {
        self.0
    }

    fn insert(&mut self, other: Self) {
        self.0 |= other.0;
    }
}

impl From<Invalid> for PatchFlags {
    fn from(i: Invalid) -> Self {
        match i {
            Invalid::NonFinite => Self::NON_FINITE,
            Invalid::Negative => Self::NEGATIVE,
            Invalid::OverRange => Self::OVER_RANGE,
        }
    }
}

/// What happened to one decoded patch.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatchReport {
    /// How the (last) solve ended.
    pub outcome: Outcome,
    /// The ensemble member used (none for a single dictionary).
    pub member: Option<u16>,
    /// Solves the patch cost.
    pub solves: u16,
    /// Why samples were left out, if any were.
    pub flags: PatchFlags,
    /// Samples used as measurements.
    pub measured: u16,
    /// Samples left out.
    pub excluded: u16,
    /// An unsheared estimate of a block that was decoded sheared at the frame's edge: it
    /// is only there for the views no sheared patch reached, and a sink weighs it by
    /// [`crate::operators::disparity::FALLBACK_WEIGHT`].
    pub fallback: bool,
    /// What the plausibility check ([`crate::solver::plausible`]) did with the patch.
    pub checked: Checked,
    /// The patch's error estimate from held-out measurements ([`crate::solver::holdout`]):
    /// an RMS error per value in the output's units; `None` unless the decoder estimates
    /// ([`TileDecoder::with_error_estimate`]), and for patches it cannot estimate
    /// (interpolated, or too few measurements to hold any out).
    pub error: Option<f32>,
}

/// What the plausibility check did with a decoded patch ([`TileDecoder::with_plausibility`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Checked {
    /// Every value within its pixel's bound (or the check is off, the patch was not solved
    /// (interpolated or flat), or saturated samples were left out of it: its light is
    /// brighter than its measurements say).
    #[default]
    Plausible,
    /// The model's decode broke the bounds; the patch was decoded again by the safe path
    /// (the DCT's hand-set schedule from the minimum-norm start), which kept within them.
    Redecoded,
    /// The safe path broke them too: its values above a bound were set to the bound.
    Clipped,
}

/// Counts for one tile or frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TileReport {
    /// Patches decoded and accepted by the sink.
    pub decoded: u32,
    /// Of those, patches with samples left out.
    pub flagged: u32,
    /// Patches that could not be decoded (rejected to the sink).
    pub failed: u32,
    /// Of the decoded, patches that measured fewer than [`Sl0Config::min_bands`] bands and
    /// were interpolated per pixel ([`Ended::Interpolated`]), not solved: a user reads
    /// which decoder made their pixels.
    pub interpolated: u32,
    /// Of the decoded, patches flat within [`Sl0Config::flat`], each band its mean
    /// ([`Ended::Flat`]), not solved.
    pub flat: u32,
    /// Of the decoded, patches whose model's decode broke the plausibility check and was
    /// replaced ([`Checked::Redecoded`] or [`Checked::Clipped`]).
    pub implausible: u32,
    /// Of those, patches whose safe decode broke it too and was clipped to the bounds.
    pub clipped: u32,
}

impl TileReport {
    /// Adds another tile's counts (a frame's report is its tiles' sum).
    pub fn add(&mut self, o: &Self) {
        self.decoded += o.decoded;
        self.flagged += o.flagged;
        self.failed += o.failed;
        self.interpolated += o.interpolated;
        self.flat += o.flat;
        self.implausible += o.implausible;
        self.clipped += o.clipped;
    }

    /// Patches solved by SL0: the decoded less the interpolated and the flat.
    pub fn solved(&self) -> u32 {
        self.decoded.saturating_sub(self.interpolated).saturating_sub(self.flat)
    }
}

/// Errors of the tile layer: decoder set-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// The mask's lenslet size differs from the sensor's.
    LensletMismatch,
    /// The patch has more views than a lenslet.
    PatchViews,
    /// The mask's band count differs from the patch type's `B`.
    BandMismatch,
    /// A kronecker mask whose block is not the patch type's `PS x PT`.
    BlockMismatch,
    /// The raw format cannot normalise (not finite, or `white <= black`).
    RawFormat,
    /// The solver config is out of range.
    Solver(SolveError),
    /// An overlap stride outside `1..=` the patch's size.
    Stride,
    /// Band gains outside `[1 / MAX_RATIO, MAX_RATIO]`.
    Gains,
    /// A response matrix that mixes bands on a kronecker mask (whose general path is for
    /// selections).
    Response,
    /// A flat field per view whose length is not the lenslet's views, or with a gain
    /// outside `[1 / MAX_RATIO, MAX_RATIO]`.
    ViewGains,
    /// A plausibility bound with a factor below 1, a negative margin, or a NaN.
    Plausibility,
    /// Held-out measurements of a fold below 2.
    HoldOut,
    /// A lenslet grid of other views than the sensor's, or on a lenslet or kronecker mask.
    Grid,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::LensletMismatch => f.write_str("mask and sensor disagree on the lenslet size"),
            Self::PatchViews => f.write_str("patch has more views than a lenslet"),
            Self::BandMismatch => f.write_str("mask and patch disagree on the band count"),
            Self::BlockMismatch => f.write_str("kronecker mask block differs from the patch's lenslets"),
            Self::RawFormat => f.write_str("raw format: need finite levels with white > black"),
            Self::Solver(e) => write!(f, "solver: {e}"),
            Self::Stride => f.write_str("overlap stride must be in 1..=patch size per axis"),
            Self::Gains => f.write_str("band gains must each be in [1/64, 64]"),
            Self::Response => f.write_str("a response matrix that mixes bands needs a pixel or lenslet mask"),
            Self::Grid => f.write_str("a lenslet grid needs a pixel mask and the sensor's views"),
            Self::ViewGains => f.write_str("view gains: one per view of a lenslet, each in [1/64, 64]"),
            Self::Plausibility => f.write_str("plausibility bound: factor >= 1 and margin >= 0"),
            Self::HoldOut => f.write_str("held-out measurements: one in 2 or more"),
        }
    }
}

impl core::error::Error for ConfigError {}

/// Errors of one tile decode. The patches delivered before it stay delivered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TileError<S, K> {
    /// The tile is empty, not made of whole patches, or outside the sensor.
    Geometry,
    /// The source failed; the rest of the tile was not decoded.
    Source(S),
    /// The sink failed; the rest of the tile was not decoded.
    Sink(K),
}

impl<S: fmt::Debug, K: fmt::Debug> fmt::Display for TileError<S, K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Geometry => f.write_str("tile is not whole patches inside the sensor"),
            Self::Source(e) => write!(f, "tile source failed: {e:?}"),
            Self::Sink(e) => write!(f, "patch sink failed: {e:?}"),
        }
    }
}

impl<S: fmt::Debug, K: fmt::Debug> core::error::Error for TileError<S, K> {}

/// Counts for a frame, and the first tile that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameReport<S, K> {
    /// Patch counts over all tiles.
    pub patches: TileReport,
    /// Tiles attempted.
    pub tiles: u32,
    /// Tiles abandoned by a source or sink error.
    pub failed_tiles: u32,
    /// The first abandoned tile and why.
    pub first_failure: Option<(Tile, TileError<S, K>)>,
}

/// Everything a tile decode needs besides the dictionary and the workspace. Immutable.
#[derive(Clone, Copy, Debug)]
pub struct DecoderConfig<'a> {
    pub sensor: SensorGeometry,
    pub mask: Mask<'a>,
    pub raw: RawFormat,
    pub defects: DefectList<'a>,
    pub sl0: Sl0Config,
}

/// The tile decoder for patches of `PS x PT x PU x PV x B` (N values): a checked
/// [`DecoderConfig`], and the capture's band gains (white balance, [`crate::sensor::gains`]; 1
/// unless set by [`with_gains`](Self::with_gains)). Stateless; all mutable state is in the
/// caller's [`Workspace`].
#[derive(Clone, Copy, Debug)]
pub struct TileDecoder<
    'a,
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
> {
    config: DecoderConfig<'a>,
    gains: [f32; B],
    disparities: DisparityRange,
    edge_fallback: bool,
    sheared_fallback: bool,
    /// Borrowed (from flash on a device): by value it made every copy of the decoder
    /// 1.35 KB larger, 9.7 KB more stack in the device's run.
    response: &'a Response<B>,
    response_model: ResponseModel,
    view_gains: Option<(&'a [f32], (u16, u16))>,
    plausibility: Plausibility,
    holdout: Option<HoldOut>,
    shear_check: bool,
    grid: Option<LensletGrid>,
}

/// Where a decode puts the filters' response matrix ([`TileDecoder::with_response`]).
///
/// A pixel behind filter `f` measures `z_f = R[f] . x`: the one-hot selection of `z = R x`,
/// with `R` on the band mode only. Decoding `z` as if the filters were one-hot and unmixing
/// each decoded spectrum (`x = R^-1 z`) and projecting onto `R_F x = y` inside the solve
/// meet the same measurements; they differ in which of `z` and `x` the prior takes sparse.
/// Measured (`docs/results-sensor.md`): the projection loses 2.1 dB on average on the four
/// realistic scenes (6.3 at worst, under a spiky LED illuminant whose spike the leak
/// spreads) and gains 0.16 dB on average on the three HCI crops; the trained schedules
/// were trained with one-hot projections. Unmixing is the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResponseModel {
    /// Decode as one-hot, then each decoded spectrum `R^-1 z`: a `B x B` product per
    /// pixel of a decoded patch; half-pixel shears and every mask family stay.
    #[default]
    Unmix,
    /// `R` in every projection of the solve ([`crate::solver::mixing`]): a `k x k` solve per
    /// pixel and step; half-pixel shears off, not on kronecker masks.
    Projection,
}

/// Origins of the angular windows along one axis: `ceil(views / patch)` windows of
/// `patch` views, evenly stepped and ending at the last view.
fn window_origins(views: usize, patch: usize) -> impl Iterator<Item = usize> {
    let count = views.div_ceil(patch.max(1));
    let last = views.saturating_sub(patch);
    (0..count).map(move |i| (i * patch).min(last))
}

/// Spans `(start, length)` of tiles along one axis of `total` lenslets for patches of
/// `patch` lenslets, `per_tile` patches a tile: the grid, then an end-aligned strip.
/// (Sizes as `NonZeroUsize`: dividing by one has no division-by-zero panic path.)
fn spans(total: usize, patch: NonZeroUsize, per_tile: NonZeroUsize) -> impl Iterator<Item = (usize, usize)> {
    let whole = total / patch;
    let tiles = whole / per_tile + usize::from(whole % per_tile != 0);
    let (patch, per_tile) = (patch.get(), per_tile.get());
    let grid = (0..tiles).map(move |i| {
        let first = i * per_tile;
        (first * patch, per_tile.min(whole - first) * patch)
    });
    let edge = (whole > 0 && !total.is_multiple_of(patch)).then(|| (total - patch, patch));
    grid.chain(edge)
}

impl<'a, const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    TileDecoder<'a, PS, PT, PU, PV, B, N>
{
    /// Checks that the parts of `config` agree with each other and with the patch type.
    ///
    /// # Errors
    /// The first [`ConfigError`] found.
    pub fn new(config: DecoderConfig<'a>) -> Result<Self, ConfigError> {
        const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
        let DecoderConfig { sensor, mask, raw, sl0, .. } = &config;
        if mask.lenslet_size() != sensor.lenslet {
            return Err(ConfigError::LensletMismatch);
        }
        if PU > sensor.lenslet.rows as usize || PV > sensor.lenslet.cols as usize {
            return Err(ConfigError::PatchViews);
        }
        if mask.bands() != B {
            return Err(ConfigError::BandMismatch);
        }
        if mask.family() == MaskFamily::Kronecker && mask.kronecker_phi::<PS, PT, PU, PV>(0, 0).is_err() {
            return Err(ConfigError::BlockMismatch);
        }
        if !raw.is_valid() {
            return Err(ConfigError::RawFormat);
        }
        sl0.validate().map_err(ConfigError::Solver)?;
        Ok(Self {
            config,
            gains: [1.0; B],
            disparities: DisparityRange::OFF,
            edge_fallback: true,
            sheared_fallback: false,
            response: &Response::IDENTITY,
            response_model: ResponseModel::Unmix,
            view_gains: None,
            plausibility: Plausibility::DEFAULT,
            holdout: None,
            shear_check: false,
            grid: None,
        })
    }

    /// The checked config.
    pub fn config(&self) -> &DecoderConfig<'a> {
        &self.config
    }

    /// This decoder with band `b`'s measurements divided by `gains[b]` before the solve
    /// and the decoded patch multiplied back (white balance, [`crate::sensor::gains`]); gains of 1
    /// are the plain decode, bit for bit.
    ///
    /// # Errors
    /// [`ConfigError::Gains`] for a gain outside `[1 / MAX_RATIO, MAX_RATIO]` ([`crate::sensor::gains::valid`]).
    pub fn with_gains(self, gains: &[f32; B]) -> Result<Self, ConfigError> {
        if !crate::sensor::gains::valid(gains) {
            return Err(ConfigError::Gains);
        }
        Ok(Self { gains: *gains, ..self })
    }

    /// The band gains the decode uses.
    pub fn gains(&self) -> &[f32; B] {
        &self.gains
    }

    /// This decoder with the filters' response matrix (a calibrated sensor's leaky filters,
    /// [`crate::sensor::response`]) placed by `model`: each measurement is the pixel's
    /// spectrum through its filter's row, and the decoded patch is the light the scene
    /// sent. The identity is the one-hot decode, bit for bit. [`ResponseModel::Projection`]
    /// with a response that mixes bands turns half-pixel shears off (their projection is
    /// for selections; whole shears stay).
    ///
    /// # Errors
    /// [`ConfigError::Response`] for [`ResponseModel::Projection`] of a response that mixes
    /// bands on a kronecker mask.
    pub fn with_response(self, response: &'a Response<B>, model: ResponseModel) -> Result<Self, ConfigError> {
        let projected = model == ResponseModel::Projection && !response.is_identity();
        if projected && self.config.mask.family() == MaskFamily::Kronecker {
            return Err(ConfigError::Response);
        }
        let disparities = if projected { self.disparities.with_halves(false) } else { self.disparities };
        Ok(Self { response, response_model: model, disparities, ..self })
    }

    /// The response matrix the decode models, and where.
    pub fn response(&self) -> (&'a Response<B>, ResponseModel) {
        (self.response, self.response_model)
    }

    /// The response the solves model: the identity unless [`ResponseModel::Projection`].
    fn solved_response(&self) -> &'a Response<B> {
        match self.response_model {
            ResponseModel::Projection => self.response,
            ResponseModel::Unmix => &Response::IDENTITY,
        }
    }

    /// This decoder with every sample divided by its view's flat field in its region of the
    /// sensor: the lenslets cut into `regions = (rows, cols)` equal rectangles (region
    /// `(i, j)` holds lenslet row `r` when `r * rows / lenslet_rows == i`), and view `(u, v)`
    /// of a lenslet in region `(i, j)` divided by `gains[((i * cols + j) * U + u) * V + v]`.
    /// Vignetting: the outer views of a lenslet see a fraction of the centre's light, and
    /// the fraction drifts across the sensor with the micro-image's centre; one table per
    /// region is the compact calibration a device holds in flash in place of a gain per
    /// pixel (`docs/design.md` says what each costs and loses). `None`: every view as
    /// bright as the centre.
    ///
    /// # Errors
    /// [`ConfigError::ViewGains`] for a region count of 0 or above the lenslets', a table
    /// whose length is not the regions' views, or a gain outside `[1 / MAX_RATIO, MAX_RATIO]`.
    pub fn with_view_gains(self, gains: Option<(&'a [f32], (u16, u16))>) -> Result<Self, ConfigError> {
        let (lenslet, lenslets) = (self.config.sensor.lenslet, self.config.sensor.lenslets);
        if let Some((g, (rows, cols))) = gains {
            let views = usize::from(lenslet.rows) * usize::from(lenslet.cols);
            if rows == 0 || cols == 0 || rows > lenslets.0 || cols > lenslets.1 {
                return Err(ConfigError::ViewGains);
            }
            if g.len() != usize::from(rows) * usize::from(cols) * views || !crate::sensor::gains::valid(g) {
                return Err(ConfigError::ViewGains);
            }
        }
        Ok(Self { view_gains: gains, ..self })
    }

    /// This decoder reading a sensor behind a real lenslet array: view `(u, v)` of lenslet
    /// `(s, t)` from the pixel under its view cell's centre ([`LensletGrid::pixel`]), the
    /// frames `grid.sensor()` pixels, tiles and patches on the lenslet grid. Each
    /// measurement is one pixel's, through its own filter, and the solve takes it as what
    /// it is: the shares of the view cells its square covers, across micro-image borders
    /// too ([`crate::solver::shares`], from the pixel's place in its cell,
    /// [`LensletGrid::cell_position`]). A pixel whose centre lies in another cell is that
    /// cell's, so no pixel is read twice. Patches at a half-pixel shear, or whose solved
    /// response mixes bands, read the pixel under the cell's centre as the cell's value
    /// (neither projection is built with shares). `None`: the aligned grid, `U x V`
    /// pixels under every lenslet (the same bytes as before grids; so is a grid that
    /// [`LensletGrid::is_aligned`]).
    ///
    /// # Errors
    /// [`ConfigError::Grid`] for a grid of other views than the sensor's lenslets, or on a
    /// lenslet or kronecker mask (whose filters sit on the lenslets).
    pub fn with_grid(self, grid: Option<LensletGrid>) -> Result<Self, ConfigError> {
        if let Some(g) = &grid {
            let l = self.config.sensor.lenslet;
            if g.views() != (l.rows, l.cols) || self.config.mask.family() != MaskFamily::Pixel {
                return Err(ConfigError::Grid);
            }
        }
        Ok(Self { grid, ..self })
    }

    /// The lenslet grid the decode reads through, if not the aligned one.
    pub fn grid(&self) -> Option<&LensletGrid> {
        self.grid.as_ref()
    }

    /// The raw frames' size `(rows, cols)`: the grid's sensor, or the aligned lenslets'.
    pub fn frame_size(&self) -> (usize, usize) {
        self.grid.map_or_else(|| self.config.sensor.frame_size(), |g| g.sensor())
    }

    /// The flat field per view and region the decode divides out, if any.
    pub fn view_gains(&self) -> Option<(&'a [f32], (u16, u16))> {
        self.view_gains
    }

    /// This decoder with `bound` as its plausibility check ([`crate::solver::plausible`];
    /// [`Plausibility::DEFAULT`] unless set): a solved patch with a value above its
    /// pixel's bound is decoded again by the safe path (the DCT's hand-set schedule from
    /// the minimum-norm start), and what the safe path leaves above a bound is clipped to
    /// it; [`PatchReport::checked`] and [`TileReport::implausible`] say so.
    /// [`Plausibility::OFF`] never checks.
    ///
    /// # Errors
    /// [`ConfigError::Plausibility`] for a factor below 1, a negative margin, or a NaN.
    pub fn with_plausibility(self, bound: Plausibility) -> Result<Self, ConfigError> {
        if !bound.is_valid() {
            return Err(ConfigError::Plausibility);
        }
        Ok(Self { plausibility: bound, ..self })
    }

    /// The plausibility check the decode applies.
    pub fn plausibility(&self) -> Plausibility {
        self.plausibility
    }

    /// This decoder with (`Some`) or without (`None`, the default) an error estimate for
    /// each solved patch ([`PatchReport::error`], [`crate::solver::holdout`]): before the
    /// decode, one solve by the model's [`PatchModel::estimating_solve`] with the held-out
    /// measurements left out, their prediction error, and the patch read again. The decode
    /// itself is the same bit for bit; the estimate costs that solve and a second read. No
    /// estimate with the response in the projection ([`ResponseModel::Projection`]): its
    /// measurements are not values of the patch.
    ///
    /// # Errors
    /// [`ConfigError::HoldOut`] for a fold below 2.
    pub fn with_error_estimate(self, hold: Option<HoldOut>) -> Result<Self, ConfigError> {
        if hold.is_some_and(|h| h.fold < 2) {
            return Err(ConfigError::HoldOut);
        }
        Ok(Self { holdout: hold, ..self })
    }

    /// This decoder with or without (the default) the shear check: a block whose measurements
    /// agree best at a half-pixel disparity is decoded at a neighbouring whole disparity if
    /// the held-out error estimate ([`crate::solver::holdout`]) of its first window's patch
    /// there is below [`SHEAR_MARGIN`] times the half one's (the better of the two whole ones
    /// if both are); else at the half one. Half-pixel
    /// measurements interpolate the patch, and where the scene's detail is at the pixel
    /// scale the interpolation aliases (`docs/design.md`). Costs three estimating solves a
    /// half-pixel block.
    pub fn with_shear_check(self, on: bool) -> Self {
        Self { shear_check: on, ..self }
    }

    /// Whether half-pixel disparities are checked against the whole ones.
    pub fn shear_check(&self) -> bool {
        self.shear_check
    }

    /// [`Self::with_shear_check`]: `half`, or the whole disparity next to it whose first
    /// window's patch at block `(row, col)` estimates a held-out error below
    /// [`SHEAR_MARGIN`] times `half`'s (the smaller of the two).
    ///
    /// # Errors
    /// The source's error.
    #[inline(never)]
    fn check_shear<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource>(
        &self,
        model: &M,
        row: u16,
        col: u16,
        half: Disparity,
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<Disparity, S::Error> {
        let mut best = (f32::INFINITY, half);
        for (d, error) in self.shear_errors(model, (row, col), half, source, ws)? {
            // A whole disparity must estimate clearly better than the half one.
            let error = if d == half { error } else { error.map(|e| e / SHEAR_MARGIN) };
            if let Some(e) = error.filter(|e| *e < best.0) {
                best = (e, d);
            }
        }
        Ok(best.1)
    }

    /// The held-out error estimates of the first window's patch of the block at lenslet
    /// `(row, col)` sheared to `half` and to the whole disparities beside it (`None` where
    /// no estimate: no window, too few measurements).
    ///
    /// # Errors
    /// The source's error.
    pub(super) fn shear_errors<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource>(
        &self,
        model: &M,
        (row, col): (u16, u16),
        half: Disparity,
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<[(Disparity, Option<f32>); 3], S::Error> {
        let h = half.in_halves();
        let mut out =
            [half, Disparity::halves(h.saturating_sub(1)), Disparity::halves(h.saturating_add(1))].map(|d| (d, None));
        let Some((view_row, view_col)) = self.windows().next() else { return Ok(out) };
        for (d, error) in &mut out {
            let origin = PatchOrigin { lenslet_row: row, lenslet_col: col, view_row, view_col, disparity: *d };
            self.read_patch(origin, source, ws)?;
            *error = self.estimate_error(model, &HoldOut::DEFAULT, origin, source, ws, false)?.0;
        }
        Ok(out)
    }

    /// The held-out measurements the error estimate takes, if the decoder estimates.
    pub fn error_estimate(&self) -> Option<HoldOut> {
        self.holdout
    }

    /// The error estimate of the patch at `origin`, whose measurements are in `ws`
    /// ([`Self::with_error_estimate`]; `full`: from the model's whole decode, not its
    /// cheapest solve), and the solves it took; the measurements are read
    /// again from `source` after the estimating solve, and `ws.patch()` is clobbered.
    /// Out of line: its frame is not on the decode's stack when the estimate is off.
    ///
    /// # Errors
    /// The source's error.
    #[inline(never)]
    pub(super) fn estimate_error<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource>(
        &self,
        model: &M,
        hold: &HoldOut,
        origin: PatchOrigin,
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
        full: bool,
    ) -> Result<(Option<f32>, u16), S::Error> {
        if !self.solved_response().is_identity() || hold_out::<PS, PT, PU, PV, B, N>(hold, &mut ws.measurements) == 0 {
            return Ok((None, 0));
        }
        // The model's own decode (a model trial), or its cheapest solve (the estimate).
        let solved = if full {
            model.decode(&self.config.sl0, ws).map(|d| d.solves)
        } else {
            model.estimating_solve(&self.config.sl0, ws)
        };
        self.read_patch(origin, source, ws)?;
        let Ok(solves) = solved else { return Ok((None, 0)) };
        let half = ws.measurements().half_views();
        if !half.is_none() {
            to_sensor::<PS, PT, PU, PV, B, N>(half, &mut ws.signal);
        }
        // Behind a lenslet grid, the held-out pixels as they measured the decode (the
        // coefficients are not needed after the solve).
        let Workspace { signal, coeffs, measurements, .. } = ws;
        shares::to_sensor::<PS, PT, PU, PV, B, N>(measurements, signal, coeffs);
        let cfg = &self.config.sl0;
        Ok((estimate::<PS, PT, PU, PV, B, N>(hold, ws.measurements(), ws.patch(), cfg.noise, cfg.shot), solves))
    }

    /// The plausibility check on the solved patch in `ws` (the solve's units and frame):
    /// within the bounds it is left as it is; otherwise decoded again by the safe path, and
    /// clipped to the bounds if that breaks them too (or fails). `done` counts the solve.
    /// Out of line: the safe path's DCT (2 KB) stays off the decode's stack.
    #[inline(never)]
    fn check_plausible(
        &self,
        cfg: &Sl0Config,
        flags: PatchFlags,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
        done: &mut ModelOutcome,
    ) -> Checked {
        // A patch with saturated samples left out is brighter than it measured: no bound.
        if self.plausibility.is_off()
            || flags.contains(PatchFlags::OVER_RANGE)
            || matches!(done.outcome.ended, Ended::Interpolated | Ended::Flat)
        {
            return Checked::Plausible;
        }
        let bounds = self.plausibility.bounds::<PS, PT, PU, PV, B, N>(ws.measurements());
        if implausible::<PS, PT, PU, PV, B, N>(&bounds, ws.patch()) == 0 {
            return Checked::Plausible;
        }
        let safe = Sl0Config { cold_start: 1.0, ..*cfg };
        done.solves = done.solves.saturating_add(1);
        match solve(&crate::operators::dictionary::Dictionary::dct(), &safe, ws) {
            Ok(outcome) => {
                done.outcome = outcome;
                if implausible::<PS, PT, PU, PV, B, N>(&bounds, ws.patch()) == 0 {
                    return Checked::Redecoded;
                }
            }
            Err(_) => {
                // Nothing finite to keep: the band-gain fill holds the measurements.
                let Workspace { signal, measurements, .. } = ws;
                crate::solver::fill::fill_bands::<B, N>(measurements, signal);
            }
        }
        clip::<PS, PT, PU, PV, B, N>(&bounds, &mut ws.signal);
        Checked::Clipped
    }

    /// This decoder with each spatial block sheared to the disparity of `range` its
    /// measurements agree with best ([`crate::operators::disparity`]): the block's patches read, and
    /// report in [`PatchOrigin::disparity`], sheared pixels. A sink must place a patch's
    /// values with [`PatchOrigin::lenslet`] (the [`crate::OverlapDecoder`]'s does).
    /// [`DisparityRange::OFF`] is the unsheared decode, bit for bit. Half-pixel
    /// candidates are kept only for patches of at most [`MAX_GRID`] lenslets, and not on a
    /// kronecker mask (whose general path is for selections).
    pub fn with_disparities(self, range: DisparityRange) -> Self {
        let halves = range.has_halves()
            && PS * PT <= MAX_GRID
            && self.config.mask.family() != MaskFamily::Kronecker
            && self.solved_response().is_identity();
        Self { disparities: range.with_halves(halves), ..self }
    }

    /// The candidate disparities the decode searches.
    pub fn disparities(&self) -> DisparityRange {
        self.disparities
    }

    /// This decoder with or without the edge fallback (on unless turned off): a block
    /// sheared at the frame's edge is decoded unsheared as well, so the views of its edge
    /// lenslets that no sheared patch reached get a decode
    /// ([`PatchReport::fallback`]). Off, those values are left to the sink (the host fills
    /// them from their lenslet's other views): one patch a window fewer per edge block,
    /// a fifth of the patches of a 128 x 128-lenslet frame at disparities -1..1, less on a
    /// larger one.
    pub fn with_edge_fallback(self, on: bool) -> Self {
        Self { edge_fallback: on, ..self }
    }

    /// Whether sheared edge blocks are also decoded unsheared.
    pub fn edge_fallback(&self) -> bool {
        self.edge_fallback
    }

    /// This decoder with or without the sheared fallback (off unless turned on): every
    /// sheared block is decoded unsheared as well, as the edge fallback decodes the edge's
    /// ([`PatchReport::fallback`], weighed so little that it changes nothing a sheared
    /// patch reached). On a grid of disjoint patches, a block sheared to `d` reaches the
    /// outer views of its own last lenslets only through its neighbour, and only if the
    /// neighbour is sheared alike: where neighbours differ, those values are reached by no
    /// patch. The preview left 8 to 13 % of a 48 x 48-lenslet frame's values to the sink's
    /// fill from other views; with the fallback (and its model trial) it is at or above the
    /// strongest baseline on every scene at pixel k = 1 and 3 and lenslet k = 3, where 13 of
    /// 63 were below before (`docs/results-preview.md`), for up to 1.7 times the patches.
    pub fn with_sheared_fallback(self, on: bool) -> Self {
        Self { sheared_fallback: on, ..self }
    }

    /// Whether every sheared block is also decoded unsheared.
    pub fn sheared_fallback(&self) -> bool {
        self.sheared_fallback
    }

    /// Grey-world band gains of a frame: every valid sample of the sensor (defects and
    /// invalid samples left out) summed per band ([`crate::sensor::gains::gains_from_sums`]).
    /// Reads the frame once, one sensor row at a time in runs of up to 16 samples per
    /// snapshot.
    ///
    /// # Errors
    /// The source's error; nothing is estimated then.
    pub fn estimate_gains<S: TileSource>(&self, source: &mut S) -> Result<[f32; B], S::Error> {
        const RUN: usize = 16;
        let c = &self.config;
        let (rows, cols) = self.frame_size();
        let k = c.mask.snapshots();
        let mut sums = [0.0f32; B];
        let mut counts = [0u32; B];
        // A pixel measures at most `B` distinct bands, so `k <= B` (checked by the mask).
        let mut runs = [[0.0f32; RUN]; B];
        for row in 0..rows {
            // Per row in f32, then added to the totals: a frame's sum in one f32 would lose
            // the small bands' low digits.
            let mut row_sums = [0.0f32; B];
            for col0 in (0..cols).step_by(RUN) {
                let len = RUN.min(cols - col0);
                for (j, run) in runs.iter_mut().enumerate().take(k) {
                    let Some(out) = run.get_mut(..len) else { break };
                    source.read(j, row, col0, out)?;
                }
                for dc in 0..len {
                    let col = col0 + dc;
                    if c.defects.contains(row, col) {
                        continue;
                    }
                    // One band list per pixel, every snapshot's sample against it.
                    for (band, run) in c.mask.bands_at(row, col).iter().zip(&runs) {
                        let Ok(y) = c.raw.classify(run.get(dc).copied().unwrap_or(f32::NAN)) else { continue };
                        let y = y / self.view_gain(row, col);
                        if let (Some(s), Some(n)) = (row_sums.get_mut(*band as usize), counts.get_mut(*band as usize)) {
                            *s += y;
                            *n += 1;
                        }
                    }
                }
            }
            for (t, r) in sums.iter_mut().zip(&row_sums) {
                *t += r;
            }
        }
        if !self.solved_response().is_identity() {
            // The filters' means are `R` of the frame's mean spectrum: the gains are of the
            // spectrum (leaked light from a bright band would otherwise inflate a dark
            // band's gain and tilt the balanced spectra: measured on the office scene at 10 %
            // leakage, 2.6 dB lost with the DCT).
            let (mut means, mut ones) = ([0.0f32; B], [0u32; B]);
            for (((m, o), &s), &n) in means.iter_mut().zip(&mut ones).zip(&sums).zip(&counts) {
                (*m, *o) = (s / n.max(1) as f32, u32::from(n > 0));
            }
            self.response.unmix(&mut means);
            return Ok(crate::sensor::gains::gains_from_sums(&means, &ones));
        }
        Ok(crate::sensor::gains::gains_from_sums(&sums, &counts))
    }

    /// Patch origins of one spatial block: every angular window.
    pub fn windows(&self) -> impl Iterator<Item = (u8, u8)> + use<'a, PS, PT, PU, PV, B, N> {
        let l = self.config.sensor.lenslet;
        window_origins(l.rows as usize, PU)
            .flat_map(move |u| window_origins(l.cols as usize, PV).map(move |v| (u as u8, v as u8)))
    }

    /// The sensor cut into tiles of at most `patches` = (rows, cols) patches each, row by
    /// row: first the patch grid from lenslet (0, 0), then, where the lenslet count is not a
    /// multiple of the patch, one strip of patches aligned to the last lenslet row or
    /// column (overlapping the grid), so every lenslet is covered. Empty if the sensor is
    /// smaller than one patch.
    pub fn tiles(&self, patches: (u16, u16)) -> impl Iterator<Item = Tile> + use<'a, PS, PT, PU, PV, B, N> {
        let (rows, cols) = (self.config.sensor.lenslets.0 as usize, self.config.sensor.lenslets.1 as usize);
        let nonzero = |n: usize| NonZeroUsize::new(n).unwrap_or(NonZeroUsize::MIN);
        let per = (nonzero(patches.0 as usize), nonzero(patches.1 as usize));
        let (ps, pt) = (nonzero(PS), nonzero(PT));
        spans(rows, ps, per.0).flat_map(move |(r0, nr)| {
            spans(cols, pt, per.1).map(move |(c0, nc)| Tile {
                lenslet_row: r0 as u16,
                lenslet_col: c0 as u16,
                lenslet_rows: nr as u16,
                lenslet_cols: nc as u16,
            })
        })
    }

    fn check_tile(&self, tile: &Tile) -> bool {
        let (rows, cols) = self.config.sensor.lenslets;
        tile.lenslet_rows > 0
            && tile.lenslet_cols > 0
            && (tile.lenslet_rows as usize).is_multiple_of(PS)
            && (tile.lenslet_cols as usize).is_multiple_of(PT)
            && tile.lenslet_row as u32 + tile.lenslet_rows as u32 <= rows as u32
            && tile.lenslet_col as u32 + tile.lenslet_cols as u32 <= cols as u32
    }

    /// Reads the patch at `origin` into the workspace's measurements (each divided by its
    /// band's gain), as a decode does before it solves; returns the flags and the number of
    /// samples left out. A sheared patch (`origin.disparity != 0`) reads each view from its
    /// shifted lenslet ([`PatchOrigin::lenslet`]), one sample at a time; pixels the shear
    /// puts outside the sensor are not measurements. `origin` is not checked against the
    /// sensor: a pixel outside it is a read the source refuses.
    ///
    /// # Errors
    /// The source's error.
    pub fn read_patch<S: TileSource>(
        &self,
        origin: PatchOrigin,
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<(PatchFlags, u16), S::Error> {
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let k = c.mask.snapshots();
        let m = ws.measurements_mut();
        m.clear();
        // Checked within [1/64, 64] by `with_gains`; `B <= MAX_BANDS` by `PatchShape`.
        let _ = m.set_gains(&self.gains);
        ws.set_response(self.solved_response());
        let m = ws.measurements_mut();
        let mut flags = PatchFlags::default();
        let mut excluded = 0u16;
        let mut run = [[0.0f32; PV]; B];
        let half = HalfViews::of(origin.disparity, (origin.view_row as usize, origin.view_col as usize), (lu, lv));
        m.set_half_views(half);
        // Behind a lenslet grid each pixel is the shares of the cells it covers; with a
        // half-pixel shear or a response that mixes bands, the cell under its centre.
        let shares = self.cell_shares(origin, half);
        if m.set_shares(shares).is_err() {
            let _ = m.set_shares(None);
        }
        let shared = m.shares().is_some();
        for s in 0..PS {
            for u in 0..PU {
                for t in 0..PT {
                    if origin.disparity == Disparity::ZERO && self.grid.is_none() {
                        // One run of the lenslet's view row per snapshot.
                        let row = (origin.lenslet_row as usize + s) * lu + origin.view_row as usize + u;
                        let col0 = (origin.lenslet_col as usize + t) * lv + origin.view_col as usize;
                        for (j, r) in run.iter_mut().enumerate().take(k) {
                            source.read(j, row, col0, r)?;
                        }
                        for v in 0..PV {
                            let at = PatchShape::<PS, PT, PU, PV, B, N>::pixel_index(s, t, u, v);
                            self.put_pixel(
                                m,
                                at,
                                row,
                                col0 + v,
                                |j| run.get(j).map(|r| r[v]),
                                &mut flags,
                                &mut excluded,
                            );
                        }
                    } else {
                        for v in 0..PV {
                            let (vr, vc) = (origin.view_row as usize + u, origin.view_col as usize + v);
                            let Some(lenslet) = origin.lenslet::<PS, PT>(s, t, u, v, (lu, lv)) else { continue };
                            let Some((row, col)) = self.sensor_pixel(lenslet, vr, vc) else { continue };
                            let at = PatchShape::<PS, PT, PU, PV, B, N>::pixel_index(s, t, u, v);
                            if shared {
                                // The pixel's place in its cell; a pixel whose centre lies
                                // in another cell is that cell's measurement, not this one's.
                                let Some(place) = self.place_in_cell(lenslet, (vr, vc), (row, col)) else { continue };
                                let _ = m.set_place(at / B, place);
                            }
                            for (j, r) in run.iter_mut().enumerate().take(k) {
                                source.read(j, row, col, &mut r[..1])?;
                            }
                            self.put_pixel(m, at, row, col, |j| run.get(j).map(|r| r[0]), &mut flags, &mut excluded);
                        }
                    }
                }
            }
        }
        Ok((flags, excluded))
    }

    /// How the pixels of a patch at `origin` share view cells behind the lenslet grid:
    /// `None` on the aligned sensor (each pixel its cell, the selection's bits), for a
    /// half-pixel shear (its own interpolation) and for a solved response that mixes bands
    /// (neither projection is built with shares).
    fn cell_shares(&self, origin: PatchOrigin, half: HalfViews) -> Option<CellShares> {
        let g = self.grid.as_ref().filter(|g| !g.is_aligned())?;
        let fits = PU <= MAX_SHARE_VIEWS && PV <= MAX_SHARE_VIEWS && PS * PT * PU * PV <= MAX_PLACES;
        if !half.is_none() || !self.solved_response().is_identity() || !fits {
            return None;
        }
        let (lu, lv) = (usize::from(self.config.sensor.lenslet.rows), usize::from(self.config.sensor.lenslet.cols));
        let mut shares = CellShares::unsheared(g.pixel_width());
        let d = origin.disparity;
        for (u, o) in shares.shift.0.iter_mut().enumerate().take(PU) {
            *o = i8::try_from(shift(d, origin.view_row as usize + u, lu)).ok()?;
        }
        for (v, o) in shares.shift.1.iter_mut().enumerate().take(PV) {
            *o = i8::try_from(shift(d, origin.view_col as usize + v, lv)).ok()?;
        }
        Some(shares)
    }

    /// Where pixel `(row, col)`'s centre lies in the view cell of view `(u, v)` of lenslet
    /// `(lr, lc)`: cells off the cell's centre (rows, cols), `None` if outside that cell (so
    /// no pixel is two cells' measurement).
    fn place_in_cell(
        &self,
        (lr, lc): (isize, isize),
        (u, v): (usize, usize),
        (row, col): (usize, usize),
    ) -> Option<(f32, f32)> {
        let g = self.grid.as_ref()?;
        let (a, b) = g.cell_position(row, col)?;
        let (nu, nv) = g.views();
        let centre = |l: isize, n: u8, w: usize| l as f32 * f32::from(n) + w as f32 + 0.5;
        let (dr, dc) = (a - centre(lr, nu, u), b - centre(lc, nv, v));
        // Cells at least a pixel apart (pitch at least the views) never share the pixel under
        // their centres, which may sit on the cell's border (a grid offset by half a pixel);
        // smaller cells may, and the border then goes to the cell after it.
        let within = |d: f32, wide: bool| if wide { (-0.5..=0.5).contains(&d) } else { (-0.5..0.5).contains(&d) };
        let (wr, wc) = g.pixel_width();
        (within(dr, wr <= 1.0) && within(dc, wc <= 1.0)).then_some((dr, dc))
    }

    /// The sensor pixel `(row, col)` of view `(u, v)` of lenslet `(lr, lc)` (a shear can
    /// put the lenslet outside the sensor: then `None`).
    #[inline(always)]
    fn sensor_pixel(&self, (lr, lc): (isize, isize), u: usize, v: usize) -> Option<(usize, usize)> {
        let c = &self.config;
        let lr = usize::try_from(lr).ok().filter(|&r| r < usize::from(c.sensor.lenslets.0))?;
        let lc = usize::try_from(lc).ok().filter(|&c0| c0 < usize::from(c.sensor.lenslets.1))?;
        if let Some(g) = &self.grid {
            return g.pixel((lr as isize, lc as isize), (u, v));
        }
        Some((lr * usize::from(c.sensor.lenslet.rows) + u, lc * usize::from(c.sensor.lenslet.cols) + v))
    }

    /// A raw sample of sensor pixel `(row, col)` through `band` as a measurement:
    /// normalised and divided by its view's gain and the band's, or why it is not one.
    #[inline(always)]
    fn balanced(&self, band: u8, raw: f32, (row, col): (usize, usize)) -> Result<f32, Invalid> {
        let gain = self.gains.get(band as usize).copied().unwrap_or(1.0) * self.view_gain(row, col);
        self.config.raw.classify(raw).map(|y| y / gain)
    }

    /// A raw sample of sensor pixel `(row, col)` in the decoded light field's units:
    /// normalised and divided by its view's flat field (the band gains are divided out
    /// before the solve and multiplied back into its output), or why it is not a
    /// measurement. On the aligned grid with the identity response it is the light field's
    /// value at the pixel's lenslet, view and band: what a held-out sample is compared with.
    #[inline]
    pub fn light_field_value(&self, raw: f32, (row, col): (usize, usize)) -> Result<f32, Invalid> {
        let gain = self.view_gain(row, col);
        self.config.raw.classify(raw).map(|y| y / gain)
    }

    /// Whether the decode's light field holds each sample's own value: no lenslet grid
    /// (every pixel under one lenslet's view) and the identity response (a pixel measures
    /// one band). Then a sample the decode was not given can be compared with the output
    /// ([`Self::light_field_value`]).
    pub fn samples_are_values(&self) -> bool {
        self.grid.is_none() && self.solved_response().is_identity()
    }

    /// The flat field of sensor pixel `(row, col)`'s view ([`Self::with_view_gains`]); 1
    /// without one.
    #[inline(always)]
    fn view_gain(&self, row: usize, col: usize) -> f32 {
        let Some((table, (rr, rc))) = self.view_gains else { return 1.0 };
        let (lenslet, lenslets) = (self.config.sensor.lenslet, self.config.sensor.lenslets);
        let (lu, lv) = (usize::from(lenslet.rows), usize::from(lenslet.cols));
        // The pixel's lenslet and view: on the grid, the cell its centre lies in.
        let ((s, t), (u, v)) = match &self.grid {
            Some(g) => g.view_of(row, col).unwrap_or(((0, 0), (0, 0))),
            None => (
                (row.checked_div(lu).unwrap_or(0), col.checked_div(lv).unwrap_or(0)),
                (row.checked_rem(lu).unwrap_or(0), col.checked_rem(lv).unwrap_or(0)),
            ),
        };
        let region = |l: usize, count: u16, regions: u16| {
            (l * usize::from(regions))
                .checked_div(usize::from(count))
                .unwrap_or(0)
                .min(usize::from(regions).saturating_sub(1))
        };
        let (i, j) = (region(s, lenslets.0, rr), region(t, lenslets.1, rc));
        table.get(((i * usize::from(rc) + j) * lu + u) * lv + v).copied().unwrap_or(1.0)
    }

    /// Sensor pixel `(row, col)`'s samples (`sample(j)` of snapshot `j`) as measurements
    /// of the patch's pixel whose first band is at `at`, each divided by its band's gain;
    /// a defective pixel or an invalid sample is left out and flagged.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn put_pixel(
        &self,
        m: &mut crate::solver::workspace::Measurements<N>,
        at: usize,
        row: usize,
        col: usize,
        sample: impl Fn(usize) -> Option<f32>,
        flags: &mut PatchFlags,
        excluded: &mut u16,
    ) {
        let c = &self.config;
        if c.defects.contains(row, col) {
            flags.insert(PatchFlags::DEFECTIVE);
            *excluded += c.mask.snapshots() as u16;
            return;
        }
        for (j, band) in c.mask.bands_at(row, col).iter().enumerate() {
            let ok = match self.balanced(*band, sample(j).unwrap_or(f32::NAN), (row, col)) {
                Ok(y) => m.set(at + *band as usize, y).map_err(|_| Invalid::NonFinite),
                Err(e) => Err(e),
            };
            if let Err(e) = ok {
                flags.insert(e.into());
                *excluded += 1;
            }
        }
    }

    /// The disparity of `range` whose shear best aligns the views of the `PS x PT` block
    /// at lenslet `(row, col)`: every view of each of its lenslets (not only a window's),
    /// scored by [`Consistency`]. 0 when the range is off (nothing is read).
    ///
    /// # Errors
    /// The source's error.
    pub fn choose_disparity<S: TileSource>(
        &self,
        row: usize,
        col: usize,
        source: &mut S,
    ) -> Result<Disparity, S::Error> {
        if self.disparities.is_off() {
            return Ok(Disparity::ZERO);
        }
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let k = c.mask.snapshots();
        let mut best = Best::default();
        let mut one = [[0.0f32; 1]; B];
        for d in self.disparities.candidates() {
            let mut score = Consistency::new();
            for s in 0..PS {
                for t in 0..PT {
                    for u in 0..lu {
                        let lr = (row + s) as isize + rounded_shift(d, u, lu);
                        for v in 0..lv {
                            let lc = (col + t) as isize + rounded_shift(d, v, lv);
                            let Some((r, cc)) = self.sensor_pixel((lr, lc), u, v) else { continue };
                            if c.defects.contains(r, cc) {
                                continue;
                            }
                            for (j, o) in one.iter_mut().enumerate().take(k) {
                                source.read(j, r, cc, o)?;
                            }
                            for (band, o) in c.mask.bands_at(r, cc).iter().zip(&one) {
                                if let Ok(y) = self.balanced(*band, o[0], (r, cc)) {
                                    score.add(*band as usize, y);
                                }
                            }
                        }
                    }
                    score.end_point();
                }
            }
            best.offer(d, &score);
        }
        Ok(best.disparity())
    }

    /// Decodes every patch of `tile` with `model` (a dictionary or an ensemble), sending
    /// each to `sink`, clamped to the sensor's physical range ([`RawFormat::range`]).
    ///
    /// # Errors
    /// [`TileError::Geometry`] before anything is read; [`TileError::Source`] or
    /// [`TileError::Sink`] abandon the rest of the tile (what was sent stays sent).
    pub fn decode_tile<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource, K: PatchSink<N>>(
        &self,
        model: &M,
        tile: Tile,
        source: &mut S,
        sink: &mut K,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<TileReport, TileError<S::Error, K::Error>> {
        self.decode_tile_seeded(model, tile, source, &mut NoSeed, sink, ws)
    }

    /// [`decode_tile`](Self::decode_tile), each patch `seed` has an estimate of decoded
    /// from it ([`PatchModel::decode_seeded`]: one seeded solve where the screened
    /// ensemble takes a cold one and a warm one).
    ///
    /// # Errors
    /// As [`decode_tile`](Self::decode_tile).
    pub fn decode_tile_seeded<
        M: PatchModel<PS, PT, PU, PV, B, N>,
        S: TileSource,
        Q: PatchSeed<N> + ?Sized,
        K: PatchSink<N>,
    >(
        &self,
        model: &M,
        tile: Tile,
        source: &mut S,
        seed: &mut Q,
        sink: &mut K,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<TileReport, TileError<S::Error, K::Error>> {
        if !self.check_tile(&tile) {
            return Err(TileError::Geometry);
        }
        let mut report = TileReport::default();
        for bs in 0..tile.lenslet_rows as usize / PS {
            for bt in 0..tile.lenslet_cols as usize / PT {
                let (row, col) = (tile.lenslet_row + (bs * PS) as u16, tile.lenslet_col + (bt * PT) as u16);
                let mut disparity =
                    self.choose_disparity(row as usize, col as usize, source).map_err(TileError::Source)?;
                if self.shear_check && !disparity.is_whole() {
                    disparity = self.check_shear(model, row, col, disparity, source, ws).map_err(TileError::Source)?;
                }
                for (view_row, view_col) in self.windows() {
                    let origin = PatchOrigin { lenslet_row: row, lenslet_col: col, view_row, view_col, disparity };
                    self.decode_patch(model, origin, false, source, seed, sink, ws, &mut report)?;
                }
                // A block sheared at the frame's edge leaves some views of the edge's
                // lenslets to no patch (their points lie outside the other views), and
                // with the sheared fallback so does any sheared block whose neighbours are
                // sheared otherwise: an unsheared decode of the block fills them, weighed
                // so little that it changes nothing a sheared patch reached.
                if disparity != Disparity::ZERO
                    && (self.sheared_fallback
                        || (self.edge_fallback && self.near_edge(row as usize, col as usize, disparity)))
                {
                    for (view_row, view_col) in self.windows() {
                        let origin = PatchOrigin {
                            lenslet_row: row,
                            lenslet_col: col,
                            view_row,
                            view_col,
                            disparity: Disparity::ZERO,
                        };
                        self.decode_patch(model, origin, true, source, seed, sink, ws, &mut report)?;
                    }
                }
            }
        }
        Ok(report)
    }

    /// Whether a block at lenslet `(row, col)` sheared to `d` reaches past the sensor's edge.
    fn near_edge(&self, row: usize, col: usize, d: Disparity) -> bool {
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let (rows, cols) = (c.sensor.lenslets.0 as usize, c.sensor.lenslets.1 as usize);
        let (hr, hc) = (reach(d, lu), reach(d, lv));
        row < hr || col < hc || row + PS + hr > rows || col + PT + hc > cols
    }

    /// Reads, decodes and sends the patch at `origin` (a fallback: see
    /// [`PatchReport::fallback`]), counting it in `report`.
    #[allow(clippy::too_many_arguments)]
    fn decode_patch<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource, Q: PatchSeed<N> + ?Sized, K: PatchSink<N>>(
        &self,
        model: &M,
        origin: PatchOrigin,
        fallback: bool,
        source: &mut S,
        seed: &mut Q,
        sink: &mut K,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
        report: &mut TileReport,
    ) -> Result<(), TileError<S::Error, K::Error>> {
        let (lo, hi) = self.config.raw.range();
        let (flags, excluded) = self.read_patch(origin, source, ws).map_err(TileError::Source)?;
        let cfg = &self.config.sl0;
        let bands = bands_measured::<B, N>(ws.measurements());
        let (error, estimating) = match &self.holdout {
            Some(hold) if bands >= u32::from(cfg.min_bands) => {
                self.estimate_error(model, hold, origin, source, ws, false).map_err(TileError::Source)?
            }
            _ => (None, 0),
        };
        // No band at all is no measurement: the model reports it.
        let decoded = if bands > 0 && bands < u32::from(cfg.min_bands) {
            let Workspace { signal, measurements, .. } = ws;
            interpolate_bands::<B, N>(measurements, signal);
            // Each pixel's interpolated bands are as its filters saw them: `R x`.
            unmix_all(&self.solved_response().balanced(&self.gains), signal);
            Ok(ModelOutcome { outcome: Outcome::interpolated(), member: None, solves: 0 })
        } else if seed.seed(origin, &mut ws.signal) && ws.signal.iter().all(|x| x.is_finite()) {
            // (A seed with a NaN or an infinity is no estimate: the patch decodes from nothing.)
            let half = ws.measurements().half_views();
            if self.response_model == ResponseModel::Unmix {
                // The seed is decoded light; the solve decodes it as the filters saw it.
                mix_all(self.response, &mut ws.signal);
            }
            if !half.is_none() {
                from_sensor::<PS, PT, PU, PV, B, N>(half, &mut ws.signal);
            }
            ws.balance_patch(&self.gains);
            model.decode_seeded(cfg, ws)
        } else {
            model.decode(cfg, ws)
        };
        match decoded {
            Ok(mut done) => {
                let checked = self.check_plausible(cfg, flags, ws, &mut done);
                let half = ws.measurements().half_views();
                if !half.is_none() {
                    to_sensor::<PS, PT, PU, PV, B, N>(half, &mut ws.signal);
                }
                ws.unbalance_patch(&self.gains);
                if self.response_model == ResponseModel::Unmix {
                    // Each decoded spectrum is as the filters saw it: `x = R^-1 z`.
                    unmix_all(self.response, &mut ws.signal);
                }
                ws.clamp_patch(lo, hi);
                let r = PatchReport {
                    outcome: done.outcome,
                    member: done.member,
                    solves: done.solves.saturating_add(estimating),
                    flags,
                    measured: ws.measurements().count() as u16,
                    excluded,
                    fallback,
                    checked,
                    error,
                };
                if checked != Checked::Plausible {
                    report.implausible += 1;
                    report.clipped += u32::from(checked == Checked::Clipped);
                    log!(warn, "patch implausible: decoded again");
                }
                if !flags.is_empty() {
                    report.flagged += 1;
                    log!(warn, "patch flagged: {} samples left out", excluded);
                }
                match done.outcome.ended {
                    Ended::Interpolated => report.interpolated += 1,
                    Ended::Flat => report.flat += 1,
                    _ => {}
                }
                report.decoded += 1;
                sink.accept(origin, ws.patch(), &r).map_err(TileError::Sink)
            }
            Err(e) => {
                report.failed += 1;
                log!(warn, "patch not decoded: {}", e);
                sink.reject(origin, e).map_err(TileError::Sink)
            }
        }
    }

    /// Decodes every tile of the sensor (see [`tiles`](Self::tiles)); a tile that fails
    /// is counted and the next one is decoded.
    pub fn decode_frame<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource, K: PatchSink<N>>(
        &self,
        model: &M,
        tile_patches: (u16, u16),
        source: &mut S,
        sink: &mut K,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> FrameReport<S::Error, K::Error> {
        let mut frame = FrameReport { patches: TileReport::default(), tiles: 0, failed_tiles: 0, first_failure: None };
        for tile in self.tiles(tile_patches) {
            frame.tiles += 1;
            match self.decode_tile(model, tile, source, sink, ws) {
                Ok(r) => frame.patches.add(&r),
                Err(e) => {
                    frame.failed_tiles += 1;
                    log!(error, "tile abandoned");
                    if frame.first_failure.is_none() {
                        frame.first_failure = Some((tile, e));
                    }
                }
            }
        }
        frame
    }
}
