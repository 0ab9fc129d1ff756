//! The caller-owned workspace: every buffer the decoder needs for one patch.
//!
//! `size_of::<Workspace<..>>()` is the decoder's whole RAM need besides the stack (a test
//! pins it at or under 96 KiB for the paper's patch). It is four patch-sized buffers and
//! one flag per patch value: coefficients, signal, the measurements and their weights in a
//! noise ball. `new` is a
//! `const fn`, so a device can place it in a `static`.

use crate::operators::disparity::HalfViews;
use crate::operators::shape::MAX_BANDS;
use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands, Extent};
use crate::sensor::response::Response;
use crate::solver::error::SolveError;

/// The measurements of one patch, dense in the patch layout: entry `i` is measured (with
/// its value in normalised units) or not. A one-hot mask measures each entry at most once.
///
/// The values of the entries that are not measured are zero between decodes; during a
/// screened ensemble decode they hold the DCT's solution while the chosen member solves
/// (see [`crate::MemberChoice::Screened`]): a solution that meets the measurements is known
/// from its unmeasured entries alone, so it needs no buffer of its own.
///
/// Values may be white-balanced: band `b`'s values divided by a gain `g_b`
/// ([`crate::sensor::gains`]), so that the decode works on spectra with the illuminant's tilt
/// taken out. The gains travel with the values because the noise ball needs them: a value
/// divided by `g_b` has its noise divided by `g_b` too ([`crate::solver::ball::Ball::weight`]).
/// Gains are 1 unless set, and [`clear`](Self::clear) keeps them (they are the unit of
/// the values, not a measurement).
#[derive(Clone, Debug)]
pub struct Measurements<V: Extent> {
    pub(crate) values: V::Per<f32>,
    pub(crate) measured: V::Per<bool>,
    pub(crate) count: u32,
    /// Gain of each band (the first `B` entries; 1 beyond them).
    pub(crate) gains: [f32; MAX_BANDS],
    /// Whether any gain differs from 1.
    pub(crate) balanced: bool,
    /// The views whose measurements interpolate the patch (a half-pixel shear,
    /// [`crate::operators::disparity`]); none: every measurement is one value.
    pub(crate) half: HalfViews,
    /// Behind a turned lenslet grid: each measurement is the shares of the view cells its
    /// pixel covers ([`crate::solver::shares`]); `None`: each is its own cell's value.
    pub(crate) shares: Option<CellShares>,
    /// With [`Self::shares`]: where each measured pixel's centre sits in its view cell, in
    /// [`PLACE_UNIT`]s off the cell's centre (rows, columns), by patch pixel (a pixel's
    /// snapshots all come from the one pixel). Two bytes a pixel for up to [`MAX_PLACES`]
    /// pixels: 1,250 B, where a byte a patch value would have taken 8,125 and cut a camera
    /// frame's strip by a column (the patch type cannot name its pixel count alone).
    pub(crate) place: [[i8; 2]; MAX_PLACES],
}

/// Places per view cell: a measured pixel's centre lies within half a cell of its cell's
/// centre, stored as `round(offset * PLACE_UNIT)` in an `i8` (steps of 1/254 cell, 0.02 of
/// a 5-pixel lenslet's pixel, the calibration's own accuracy).
pub const PLACE_UNIT: f32 = 254.0;

/// The largest views per lenslet along an axis a patch behind a lenslet grid may have.
pub const MAX_SHARE_VIEWS: usize = 8;

/// The most pixels (`PS * PT * PU * PV`) of a patch whose measurements share view cells:
/// the full-view patch's 625. A larger patch reads each view at the pixel under its cell's
/// centre.
pub const MAX_PLACES: usize = 625;

/// How a lenslet grid's pixels lie over a patch's view cells ([`crate::solver::shares`]):
/// the same for every measurement of the patch, apart from each one's place
/// ([`Measurements::set_place`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CellShares {
    /// A pixel's side in view cells along the patch's rows and columns: the views per
    /// lenslet over the grid's pitch (pixels per lenslet). Within `[1/2, 2]`.
    pub width: (f32, f32),
    /// The lenslet shift of each view row and view column in the patch's shear
    /// ([`crate::operators::disparity::shift`]; all 0 unsheared): view row `u` of grid
    /// position `s` is sensor lenslet row `origin + s + rows[u]`. A pixel's neighbouring
    /// cells on the sensor are found through it.
    pub shift: ([i8; MAX_SHARE_VIEWS], [i8; MAX_SHARE_VIEWS]),
    /// Whether the shares of cells outside the patch are already taken out of the
    /// measurements (each value less those cells' estimates by their shares, read from a
    /// decode of the frame): then they are no part of the model. Otherwise each such share
    /// is given to the pixel's own cell.
    pub known_outside: bool,
}

impl CellShares {
    /// An unsheared patch's shares for pixels `width` cells wide.
    pub const fn unsheared(width: (f32, f32)) -> Self {
        Self { width, shift: ([0; MAX_SHARE_VIEWS], [0; MAX_SHARE_VIEWS]), known_outside: false }
    }
}

impl<V: Extent> Measurements<V> {
    /// Nothing measured.
    pub const fn new() -> Self {
        Self {
            values: V::ZEROS,
            measured: V::NONE,
            count: 0,
            gains: [1.0; MAX_BANDS],
            balanced: false,
            half: HalfViews::NONE,
            shares: None,
            place: [[0; 2]; MAX_PLACES],
        }
    }

    /// Makes the measurements of `half`'s views interpolations of the patch: entry
    /// `(s, t, u, v, b)` of a view whose row `u` is half measures the mean of the patch's
    /// `(s, ..)` and `(s + 1, ..)` (and likewise along `t` for a half column `v`); the last
    /// grid position of a half axis is then no measurement, and is ignored if set.
    /// [`clear`](Self::clear) puts every view back on the grid.
    pub fn set_half_views(&mut self, half: HalfViews) {
        self.half = half;
    }

    /// The views whose measurements interpolate the patch.
    pub fn half_views(&self) -> HalfViews {
        self.half
    }

    /// Makes the measurements shares of the view cells their pixels cover, behind a turned
    /// lenslet grid ([`crate::solver::shares`]); `None`: each measures its own cell (the
    /// aligned sensor). Set each measured pixel's place with [`Self::set_place`].
    /// [`clear`](Self::clear) puts the patch back on the aligned sensor.
    ///
    /// # Errors
    /// [`SolveError::InvalidConfig`] for widths outside `[1/2, 2]`; nothing changes then.
    pub fn set_shares(&mut self, shares: Option<CellShares>) -> Result<(), SolveError> {
        if let Some(c) = &shares {
            let fits = |w: f32| (0.5..=2.0).contains(&w);
            if !fits(c.width.0) || !fits(c.width.1) {
                return Err(SolveError::InvalidConfig { field: "shares.width" });
            }
        }
        self.shares = shares;
        Ok(())
    }

    /// How the measurements share view cells, if behind a lenslet grid.
    pub fn shares(&self) -> Option<&CellShares> {
        self.shares.as_ref()
    }

    /// Records where patch pixel `pixel` (`PatchShape::pixel_index / B`) lies in its view
    /// cell: its centre `offset` (rows, columns) cells off the cell's centre, each within
    /// `[-1/2, 1/2]` (clamped to `127 / PLACE_UNIT` either side).
    ///
    /// # Errors
    /// [`SolveError::IndexOutOfRange`] for a pixel at or past [`MAX_PLACES`];
    /// [`SolveError::NonFiniteMeasurement`] for a place that is not finite.
    pub fn set_place(&mut self, pixel: usize, offset: (f32, f32)) -> Result<(), SolveError> {
        if !(offset.0.is_finite() && offset.1.is_finite()) {
            return Err(SolveError::NonFiniteMeasurement);
        }
        let code = |x: f32| {
            // Constant bounds: `clamp`'s check of them folds away (no panic site).
            let y = (x * PLACE_UNIT).clamp(-127.0, 127.0);
            // Round half away from zero; `as` of a value in [-127.5, 127.5] is exact.
            (if y < 0.0 { y - 0.5 } else { y + 0.5 }) as i8
        };
        let Some(place) = self.place.get_mut(pixel) else {
            return Err(SolveError::IndexOutOfRange);
        };
        *place = [code(offset.0), code(offset.1)];
        Ok(())
    }

    /// Whether a measurement may read more than one patch value: a half-pixel shear
    /// ([`Self::half_views`]) or shares of view cells ([`Self::shares`]).
    pub fn interpolates(&self) -> bool {
        !self.half.is_none() || self.shares.is_some()
    }

    /// Sets the gain of each band (`gains[b]` for band `b`; bands beyond `gains.len()` get
    /// 1): the values set from now on are the sensor's divided by their band's gain.
    ///
    /// # Errors
    /// [`SolveError::BadGains`] for more than [`MAX_BANDS`] gains or a gain that is not
    /// finite and positive; the gains are left as they were.
    pub fn set_gains(&mut self, gains: &[f32]) -> Result<(), SolveError> {
        if gains.len() > MAX_BANDS || !gains.iter().all(|g| g.is_finite() && *g > 0.0) {
            return Err(SolveError::BadGains);
        }
        self.gains = [1.0; MAX_BANDS];
        for (o, g) in self.gains.iter_mut().zip(gains.iter()) {
            *o = *g;
        }
        self.balanced = gains.iter().any(|&g| g != 1.0);
        Ok(())
    }

    /// The gain of each band ([`MAX_BANDS`] entries; 1 for bands not set).
    pub fn gains(&self) -> &[f32; MAX_BANDS] {
        &self.gains
    }

    /// Forgets every measurement.
    pub fn clear(&mut self) {
        self.values.as_mut().fill(0.0);
        self.measured.as_mut().fill(false);
        self.count = 0;
        self.half = HalfViews::NONE;
        self.shares = None;
    }

    /// Records that patch entry `index` measured `value` (normalised units).
    ///
    /// # Errors
    /// [`SolveError::IndexOutOfRange`] or [`SolveError::NonFiniteMeasurement`]; nothing is
    /// recorded then.
    pub fn set(&mut self, index: usize, value: f32) -> Result<(), SolveError> {
        if !value.is_finite() {
            return Err(SolveError::NonFiniteMeasurement);
        }
        let (Some(v), Some(m)) = (self.values.as_mut().get_mut(index), self.measured.as_mut().get_mut(index)) else {
            return Err(SolveError::IndexOutOfRange);
        };
        *v = value;
        if !*m {
            *m = true;
            self.count += 1;
        }
        Ok(())
    }

    /// The value measured at `index`, if any.
    pub fn get(&self, index: usize) -> Option<f32> {
        match self.measured.as_ref().get(index) {
            Some(true) => self.values.as_ref().get(index).copied(),
            _ => None,
        }
    }

    /// Number of measured entries.
    pub fn count(&self) -> usize {
        self.count as usize
    }

    /// Keeps the unmeasured entries of `patch` in the unmeasured slots of the values.
    pub(crate) fn stash(&mut self, patch: &V::Per<f32>) {
        for ((v, &k), &x) in self.values.as_mut().iter_mut().zip(self.measured.as_ref()).zip(patch.as_ref()) {
            if !k {
                *v = x;
            }
        }
    }

    /// Makes each unmeasured entry `x` of `patch` the weighted mean `w s + (1 - w) x` with
    /// its stashed value `s`, and forgets the stash. Measured entries are left as they are.
    pub(crate) fn blend_stash(&mut self, patch: &mut V::Per<f32>, w: f32) {
        for ((v, &k), x) in self.values.as_mut().iter_mut().zip(self.measured.as_ref()).zip(patch.as_mut()) {
            if !k {
                *x = w * *v + (1.0 - w) * *x;
                *v = 0.0;
            }
        }
    }

    /// Forgets the stash: the unmeasured values are zero again.
    pub(crate) fn drop_stash(&mut self) {
        for (v, &k) in self.values.as_mut().iter_mut().zip(self.measured.as_ref()) {
            if !k {
                *v = 0.0;
            }
        }
    }
}

impl<V: Extent> Default for Measurements<V> {
    fn default() -> Self {
        Self::new()
    }
}

/// Every buffer of one patch decode. Mutable state, apart from the immutable config.
#[derive(Clone, Debug)]
pub struct Workspace<S: Shape> {
    pub(crate) coeffs: PerValue<S, f32>,
    pub(crate) signal: PerValue<S, f32>,
    pub(crate) measurements: Measurements<S::Values>,
    /// Each measurement's weight in a noise ball that weighs them
    /// ([`crate::solver::ball::Ball::weight`], in patch order; other entries are stale):
    /// made once a solve, read by every step's
    /// projection. Computed in each step instead, its two divisions a measurement held the
    /// projection's band step up (`perf annotate`: a fifth of a default decode's samples in
    /// the step stood on the division's result at pixel k = 3).
    pub(crate) weights: PerValue<S, f32>,
    /// The filters' response matrix the measurements are taken through (in the sensor's
    /// units; the solve balances it by the measurements' gains): the identity for one-hot
    /// filters ([`crate::solver::mixing`]).
    pub(crate) response: Response<S::Bands>,
}

impl<S: Shape> Workspace<S> {
    /// A zeroed workspace.
    pub const fn new() -> Self {
        const { S::CHECK };
        Self {
            coeffs: S::Values::ZEROS,
            signal: S::Values::ZEROS,
            measurements: Measurements::new(),
            weights: S::Values::ZEROS,
            response: Response::IDENTITY,
        }
    }

    /// Sets the response matrix the next solves take the measurements through (kept by
    /// [`Measurements::clear`]: a property of the sensor, not of a patch). The identity, as
    /// new, is the one-hot model. Half-pixel shears ([`Measurements::set_half_views`]) need
    /// the identity: a solve with both is [`SolveError::MixedHalfViews`].
    pub fn set_response(&mut self, response: &Response<S::Bands>) {
        self.response = *response;
    }

    /// The response matrix the solves take the measurements through.
    pub fn response(&self) -> &Response<S::Bands> {
        &self.response
    }

    /// The measurements the next solve uses.
    pub fn measurements(&self) -> &Measurements<S::Values> {
        &self.measurements
    }

    /// The measurements, to fill before a solve.
    pub fn measurements_mut(&mut self) -> &mut Measurements<S::Values> {
        &mut self.measurements
    }

    /// The coefficient buffer, e.g. to synthesise a patch from chosen coefficients.
    pub fn coefficients_mut(&mut self) -> &mut PerValue<S, f32> {
        &mut self.coeffs
    }

    /// `patch = coefficients x_i D_i`, in place in the workspace (the coefficients are the
    /// scratch and are clobbered): one transform with no buffer outside the workspace.
    pub fn synthesize(&mut self, dict: &crate::operators::dictionary::Dictionary<S>) {
        crate::operators::transform::synthesize(dict, &mut self.coeffs, &mut self.signal);
    }

    /// The decoded patch after a successful solve (layout of [`Shape::index`]).
    pub fn patch(&self) -> &PerValue<S, f32> {
        &self.signal
    }

    /// The patch buffer, to write an estimate of the patch into before a seeded decode
    /// ([`crate::solver::choice::PatchModel::decode_seeded`], in the solve's units: divided
    /// by the band gains). The tile decoder fills it from its seed.
    pub fn patch_mut(&mut self) -> &mut PerValue<S, f32> {
        &mut self.signal
    }

    /// Multiplies each band of the decoded patch by its gain: a white-balanced decode back
    /// in the sensor's units. Gains of 1 leave it as it is (and cost nothing).
    pub(crate) fn unbalance_patch(&mut self, gains: &PerBand<S, f32>) {
        self.per_band(gains, |x, g| x * g);
    }

    /// Divides each band of the patch by its gain: an estimate in the sensor's units into
    /// the white-balanced units the solve works in ([`Self::unbalance_patch`]'s reverse).
    pub(crate) fn balance_patch(&mut self, gains: &PerBand<S, f32>) {
        self.per_band(gains, |x, g| x / g);
    }

    /// Each value `x` of the patch becomes `f(x, its band's gain)`; nothing at all when
    /// every gain is 1.
    #[inline(always)]
    fn per_band(&mut self, gains: &PerBand<S, f32>, f: impl Fn(f32, f32) -> f32) {
        if gains.iter().all(|&g| g == 1.0) {
            return;
        }
        for pixel in S::Bands::chunks_mut(self.signal.as_mut()) {
            for (x, &g) in pixel.iter_mut().zip(gains.iter()) {
                *x = f(*x, g);
            }
        }
    }

    /// Limits the decoded patch to `[lo, hi]` (the sensor's physical range).
    pub(crate) fn clamp_patch(&mut self, lo: f32, hi: f32) {
        // Comparisons, not `f32::clamp` (it asserts `lo <= hi`: a panic site) nor
        // `max` / `min` (calls to `fmaxf` / `fminf` on a Cortex-M4F, 5,200 of each a patch).
        for x in self.signal.iter_mut() {
            *x = if *x < lo {
                lo
            } else if *x > hi {
                hi
            } else {
                *x
            };
        }
    }
}

impl<S: Shape> Default for Workspace<S> {
    fn default() -> Self {
        Self::new()
    }
}

/// The workspace of the paper's patch.
pub type PaperWorkspace = Workspace<crate::operators::shape::PaperShape>;

/// The workspace of the full-view patch ([`crate::FullViewShape`], 5 x 5 x 5 x 5 x 13).
pub type FullViewWorkspace = Workspace<crate::operators::shape::FullViewShape>;
