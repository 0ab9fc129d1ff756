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
//!
//! The decoder is one type over several files: its configuration, the tiles and the decode
//! loop here; [`sink`] where patches go; [`report`] what a decode reports and its errors;
//! `read` the sensor read (a patch's samples, balanced and placed); `checks` the checks
//! on a decoded patch (the shear check, plausibility, the error estimate) and the
//! disparity choice.

mod checks;
mod read;
pub mod report;
pub mod sink;

pub use report::{Checked, ConfigError, FrameReport, PatchFlags, PatchReport, TileError, TileReport};
pub use sink::{NoSeed, PatchSeed, PatchSink};

use core::num::NonZeroUsize;

use crate::log::log;
use crate::operators::disparity::{
    Best, Consistency, Disparity, DisparityRange, HalfViews, is_half, reach, rounded_shift, shift,
};
use crate::sensor::defects::DefectList;
use crate::sensor::extent::Array;
use crate::sensor::grid::LensletGrid;
use crate::sensor::mask::{LensletSize, Mask, MaskFamily};
use crate::sensor::raw::{Invalid, RawFormat};
use crate::sensor::response::{Response, StaticIdentity};
use crate::solver::choice::{ModelOutcome, PatchModel};
use crate::solver::fractional::{MAX_GRID, from_sensor, to_sensor};
use crate::solver::holdout::{HoldOut, estimate, hold_out};
use crate::solver::interpolate::{bands_measured, interpolate_bands};
use crate::solver::mixing::{mix_all, unmix_all};
use crate::solver::plausible::{Plausibility, clip, implausible};
use crate::solver::shares;
use crate::solver::sl0::{Ended, Outcome, Sl0Config, solve};
use crate::solver::workspace::{CellShares, MAX_PLACES, MAX_SHARE_VIEWS, Workspace};

use crate::operators::shape::{PerBand, Shape};
/// The source trait lives with the raw frames (the sensor layer); named here too, where the
/// decoder that reads it is.
pub use crate::sensor::source::TileSource;

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
    pub fn lenslet<S: Shape>(
        &self,
        s: usize,
        t: usize,
        u: usize,
        v: usize,
        views: (usize, usize),
    ) -> Option<(isize, isize)> {
        let d = self.disparity;
        let (vr, vc) = (self.view_row as usize + u, self.view_col as usize + v);
        if (is_half(d, vr, views.0) && s + 1 >= S::PS) || (is_half(d, vc, views.1) && t + 1 >= S::PT) {
            return None;
        }
        let (du, dv) = (shift(d, vr, views.0), shift(d, vc, views.1));
        Some(((self.lenslet_row as usize + s) as isize + du, (self.lenslet_col as usize + t) as isize + dv))
    }
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
pub struct TileDecoder<'a, S: Shape> {
    config: DecoderConfig<'a>,
    gains: PerBand<S, f32>,
    disparities: DisparityRange,
    edge_fallback: bool,
    sheared_fallback: bool,
    /// Borrowed (from flash on a device): by value it made every copy of the decoder
    /// 1.35 KB larger, 9.7 KB more stack in the device's run.
    response: &'a Response<S::Bands>,
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

impl<'a, S: Shape> TileDecoder<'a, S> {
    /// Checks that the parts of `config` agree with each other and with the patch type.
    ///
    /// # Errors
    /// The first [`ConfigError`] found.
    pub fn new(config: DecoderConfig<'a>) -> Result<Self, ConfigError> {
        let DecoderConfig { sensor, mask, raw, sl0, .. } = &config;
        if mask.lenslet_size() != sensor.lenslet {
            return Err(ConfigError::LensletMismatch);
        }
        if S::PU > sensor.lenslet.rows as usize || S::PV > sensor.lenslet.cols as usize {
            return Err(ConfigError::PatchViews);
        }
        if mask.bands() != S::B {
            return Err(ConfigError::BandMismatch);
        }
        if mask.family() == MaskFamily::Kronecker && mask.kronecker_phi::<S::S, S::T, S::U, S::V>(0, 0).is_err() {
            return Err(ConfigError::BlockMismatch);
        }
        if !raw.is_valid() {
            return Err(ConfigError::RawFormat);
        }
        sl0.validate().map_err(ConfigError::Solver)?;
        Ok(Self {
            config,
            gains: <PerBand<S, _>>::splat(1.0),
            disparities: DisparityRange::OFF,
            edge_fallback: true,
            sheared_fallback: false,
            response: S::Bands::IDENTITY_REF,
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
    pub fn with_gains(self, gains: &PerBand<S, f32>) -> Result<Self, ConfigError> {
        if !crate::sensor::gains::valid(gains.as_ref()) {
            return Err(ConfigError::Gains);
        }
        Ok(Self { gains: *gains, ..self })
    }

    /// The band gains the decode uses.
    pub fn gains(&self) -> &PerBand<S, f32> {
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
    pub fn with_response(self, response: &'a Response<S::Bands>, model: ResponseModel) -> Result<Self, ConfigError> {
        let projected = model == ResponseModel::Projection && !response.is_identity();
        if projected && self.config.mask.family() == MaskFamily::Kronecker {
            return Err(ConfigError::Response);
        }
        let disparities = if projected { self.disparities.with_halves(false) } else { self.disparities };
        Ok(Self { response, response_model: model, disparities, ..self })
    }

    /// The response matrix the decode models, and where.
    pub fn response(&self) -> (&'a Response<S::Bands>, ResponseModel) {
        (self.response, self.response_model)
    }

    /// The response the solves model: the identity unless [`ResponseModel::Projection`].
    fn solved_response(&self) -> &'a Response<S::Bands> {
        match self.response_model {
            ResponseModel::Projection => self.response,
            ResponseModel::Unmix => S::Bands::IDENTITY_REF,
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

    /// The error estimate of the patch at `origin`, whose measurements are in `ws`
    /// ([`Self::with_error_estimate`]; `full`: from the model's whole decode, not its
    /// cheapest solve), and the solves it took; the measurements are read
    /// again from `source` after the estimating solve (with `seed`'s cells outside the patch,
    /// as [`Self::read_patch_seeded`]), and `ws.patch()` is clobbered.
    /// Out of line: its frame is not on the decode's stack when the estimate is off.
    ///
    /// # Errors
    /// The source's error.
    #[inline(never)]
    pub(super) fn estimate_error<M: PatchModel<S>, Src: TileSource, Q: PatchSeed<S> + ?Sized>(
        &self,
        model: &M,
        hold: &HoldOut,
        (origin, seed): (PatchOrigin, Option<&mut Q>),
        source: &mut Src,
        ws: &mut Workspace<S>,
        full: bool,
    ) -> Result<(Option<f32>, u16), Src::Error> {
        if !self.solved_response().is_identity() || hold_out::<S>(hold, &mut ws.measurements) == 0 {
            return Ok((None, 0));
        }
        // The model's own decode (a model trial), or its cheapest solve (the estimate).
        let solved = if full {
            model.decode(&self.config.sl0, ws).map(|d| d.solves)
        } else {
            model.estimating_solve(&self.config.sl0, ws)
        };
        self.read_patch_seeded(origin, source, ws, seed)?;
        let Ok(solves) = solved else { return Ok((None, 0)) };
        let half = ws.measurements().half_views();
        if !half.is_none() && ws.measurements().shares().is_none() {
            to_sensor::<S>(half, &mut ws.signal);
        }
        // Behind a lenslet grid, the held-out pixels as they measured the decode, half views
        // by their two grid positions (the coefficients are not needed after the solve).
        let Workspace { signal, coeffs, measurements, .. } = ws;
        shares::to_sensor::<S>(measurements, signal, coeffs);
        let cfg = &self.config.sl0;
        // Each entry's flat, at the pixel the patch read it from (the shear's lenslet): its
        // view's gain, times the flat the source had already divided it by.
        let views = (usize::from(self.config.sensor.lenslet.rows), usize::from(self.config.sensor.lenslet.cols));
        let source = &*source;
        let pixels = self.view_gains.is_some() || source.divided();
        let flat = |i: usize| {
            // Without view gains or a source's flat every flat is 1: no pixel to look up.
            if !pixels {
                return 1.0;
            }
            let [s, t, u, v, _] = S::coordinates(i);
            let (vr, vc) = (usize::from(origin.view_row) + u, usize::from(origin.view_col) + v);
            origin
                .lenslet::<S>(s, t, u, v, views)
                .and_then(|l| self.sensor_pixel(l, vr, vc))
                .map_or(1.0, |(row, col)| self.view_gain(row, col) * source.flat(row, col))
        };
        Ok((estimate::<S>(hold, ws.measurements(), ws.patch(), (cfg.noise, cfg.shot), flat), solves))
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
            && S::PS * S::PT <= MAX_GRID
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

    /// Patch origins of one spatial block: every angular window.
    pub fn windows(&self) -> impl Iterator<Item = (u8, u8)> + use<'a, S> {
        let l = self.config.sensor.lenslet;
        window_origins(l.rows as usize, S::PU)
            .flat_map(move |u| window_origins(l.cols as usize, S::PV).map(move |v| (u as u8, v as u8)))
    }

    /// The sensor cut into tiles of at most `patches` = (rows, cols) patches each, row by
    /// row: first the patch grid from lenslet (0, 0), then, where the lenslet count is not a
    /// multiple of the patch, one strip of patches aligned to the last lenslet row or
    /// column (overlapping the grid), so every lenslet is covered. Empty if the sensor is
    /// smaller than one patch.
    pub fn tiles(&self, patches: (u16, u16)) -> impl Iterator<Item = Tile> + use<'a, S> {
        let (rows, cols) = (self.config.sensor.lenslets.0 as usize, self.config.sensor.lenslets.1 as usize);
        let nonzero = |n: usize| NonZeroUsize::new(n).unwrap_or(NonZeroUsize::MIN);
        let per = (nonzero(patches.0 as usize), nonzero(patches.1 as usize));
        let (ps, pt) = (nonzero(S::PS), nonzero(S::PT));
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
            && (tile.lenslet_rows as usize).is_multiple_of(S::PS)
            && (tile.lenslet_cols as usize).is_multiple_of(S::PT)
            && tile.lenslet_row as u32 + tile.lenslet_rows as u32 <= rows as u32
            && tile.lenslet_col as u32 + tile.lenslet_cols as u32 <= cols as u32
    }

    /// Decodes every patch of `tile` with `model` (a dictionary or an ensemble), sending
    /// each to `sink`, clamped to the sensor's physical range ([`RawFormat::range`]).
    ///
    /// # Errors
    /// [`TileError::Geometry`] before anything is read; [`TileError::Source`] or
    /// [`TileError::Sink`] abandon the rest of the tile (what was sent stays sent).
    pub fn decode_tile<M: PatchModel<S>, Src: TileSource, K: PatchSink<S>>(
        &self,
        model: &M,
        tile: Tile,
        source: &mut Src,
        sink: &mut K,
        ws: &mut Workspace<S>,
    ) -> Result<TileReport, TileError<Src::Error, K::Error>> {
        self.decode_tile_seeded(model, tile, source, &mut NoSeed, sink, ws)
    }

    /// [`decode_tile`](Self::decode_tile), each patch `seed` has an estimate of decoded
    /// from it ([`PatchModel::decode_seeded`]: one seeded solve where the screened
    /// ensemble takes a cold one and a warm one).
    ///
    /// # Errors
    /// As [`decode_tile`](Self::decode_tile).
    pub fn decode_tile_seeded<M: PatchModel<S>, Src: TileSource, Q: PatchSeed<S> + ?Sized, K: PatchSink<S>>(
        &self,
        model: &M,
        tile: Tile,
        source: &mut Src,
        seed: &mut Q,
        sink: &mut K,
        ws: &mut Workspace<S>,
    ) -> Result<TileReport, TileError<Src::Error, K::Error>> {
        if !self.check_tile(&tile) {
            return Err(TileError::Geometry);
        }
        let mut report = TileReport::default();
        for bs in 0..tile.lenslet_rows as usize / S::PS {
            for bt in 0..tile.lenslet_cols as usize / S::PT {
                let (row, col) = (tile.lenslet_row + (bs * S::PS) as u16, tile.lenslet_col + (bt * S::PT) as u16);
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

    /// Reads, decodes and sends the patch at `origin` (a fallback: see
    /// [`PatchReport::fallback`]), counting it in `report`.
    #[allow(clippy::too_many_arguments)]
    fn decode_patch<M: PatchModel<S>, Src: TileSource, Q: PatchSeed<S> + ?Sized, K: PatchSink<S>>(
        &self,
        model: &M,
        origin: PatchOrigin,
        fallback: bool,
        source: &mut Src,
        seed: &mut Q,
        sink: &mut K,
        ws: &mut Workspace<S>,
        report: &mut TileReport,
    ) -> Result<(), TileError<Src::Error, K::Error>> {
        let (lo, hi) = self.config.raw.range();
        // Whether the frame's decode holds this patch (its shifted patches' seeds): then its
        // cells outside the patch are read from it too.
        let seeded = self.grid.is_some() && seed.seed(origin, &mut ws.signal);
        let (flags, excluded) =
            self.read_patch_seeded(origin, source, ws, seeded.then_some(&mut *seed)).map_err(TileError::Source)?;
        let cfg = &self.config.sl0;
        let bands = bands_measured::<S>(ws.measurements());
        let (error, estimating, clobbered) = match &self.holdout {
            Some(hold) if bands >= u32::from(cfg.min_bands) => {
                let (error, solves) = self
                    .estimate_error(model, hold, (origin, seeded.then_some(&mut *seed)), source, ws, false)
                    .map_err(TileError::Source)?;
                (error, solves, true)
            }
            _ => (None, 0, false),
        };
        // Behind a grid the probe's seed is still in the patch unless the estimate's solve
        // clobbered it: it is read once.
        let reseed = self.grid.is_none() || clobbered;
        // No band at all is no measurement: the model reports it.
        let decoded = if bands > 0 && bands < u32::from(cfg.min_bands) {
            let Workspace { signal, measurements, .. } = ws;
            interpolate_bands::<S>(measurements, signal);
            // Each pixel's interpolated bands are as its filters saw them: `R x`.
            unmix_all::<S>(&self.solved_response().balanced(self.gains.as_ref()), signal);
            Ok(ModelOutcome { outcome: Outcome::interpolated(), member: None, solves: 0 })
        } else if (if reseed { seed.seed(origin, &mut ws.signal) } else { seeded })
            && ws.signal.iter().all(|x| x.is_finite())
        {
            // (A seed with a NaN or an infinity is no estimate: the patch decodes from nothing.)
            let half = ws.measurements().half_views();
            if self.response_model == ResponseModel::Unmix {
                // The seed is decoded light; the solve decodes it as the filters saw it.
                mix_all::<S>(self.response, &mut ws.signal);
            }
            if !half.is_none() {
                from_sensor::<S>(half, &mut ws.signal);
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
                    to_sensor::<S>(half, &mut ws.signal);
                }
                ws.unbalance_patch(&self.gains);
                if self.response_model == ResponseModel::Unmix {
                    // Each decoded spectrum is as the filters saw it: `x = R^-1 z`.
                    unmix_all::<S>(self.response, &mut ws.signal);
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
    pub fn decode_frame<M: PatchModel<S>, Src: TileSource, K: PatchSink<S>>(
        &self,
        model: &M,
        tile_patches: (u16, u16),
        source: &mut Src,
        sink: &mut K,
        ws: &mut Workspace<S>,
    ) -> FrameReport<Src::Error, K::Error> {
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
