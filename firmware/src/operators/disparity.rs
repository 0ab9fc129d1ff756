//! Disparity: sheared patches, which align a patch's views on a depth before the 5D basis.
//!
//! A Lambertian point at disparity `d` (pixels of shift per view step, the convention of
//! the HCI benchmark and of the host's scenes) is seen by view `u` at lenslet
//! `x - d (u - uc)`, with `uc` the lenslet's centre view. The 5D DCT and the learned
//! members align the views only at `d = 0`, so a patch of a surface at another depth is
//! less sparse in them than it is. A **sheared patch** reads view `u` of its lenslet `s` from
//! lenslet `s + shift(d, u)` with [`shift`] `= -d (u - uc)`: the surface's views line up and
//! the same basis codes it in fewer coefficients. For integer `d` the shear only changes
//! which sensor pixels the patch reads, so each measurement is still one value of the
//! patch (a one-hot selection) and the orthonormal fast path holds; the decoded values
//! belong to the pixels that were read, and a sink puts them there
//! ([`crate::decode::tile::PatchOrigin::lenslet`]).
//!
//! The disparity is chosen per spatial block, before any solve, from the measurements
//! themselves ([`Consistency`]): with the views aligned, the samples of one point that
//! went through the same filter must agree, so the candidate whose same-band samples
//! differ least is the block's depth. With a per-pixel one-hot mask the 25 views of a
//! point see about two samples per band, so a 5 x 5-lenslet block compares a few hundred
//! pairs per candidate.
//!
//! **Half-pixel disparities.** At `d = n + 1/2` the views an odd number of steps from the
//! centre are shifted by half a lenslet: no sensor pixel lies on the patch's grid. Such a
//! view's measurement is then the mean of the two patch values on either side of its pixel
//! (four on views odd in both axes: bilinear at the centre of four), so the operator is no
//! longer a selection and the projection solves a small system per view and band
//! ([`crate::solver::fractional`]). Rounding each view's shift to a whole lenslet instead measured
//! no better than the integers, and exact interpolation 2.6 to 3.6 dB better than the
//! better integer on blocks near a half-integer (dense f64 reference,
//! `host-sim/examples/fractional_shear.rs`); an orthonormal half-pixel shift put in the
//! dictionary instead (selection reads kept) measured 1 to 8 dB worse than that. Half
//! candidates are chosen by the same [`Consistency`] with each view's shift rounded away
//! from zero. A decoded half-pixel patch is handed to sinks at its sensor pixels: the
//! interpolated values ([`crate::solver::fractional::to_sensor`]), the last grid position of a
//! half view naming no pixel ([`crate::decode::tile::PatchOrigin::lenslet`]).

use crate::operators::shape::MAX_BANDS;
use crate::sensor::mask::MaskFamily;

/// The largest disparity magnitude a decoder searches (pixels per view step): a shear of
/// `d` reaches `d (U - 1) / 2` lenslets beyond the patch, and sinks keep that halo.
pub const MAX_DISPARITY: i8 = 3;

/// The weight, relative to a sheared patch's, of an unsheared fallback estimate
/// ([`crate::decode::tile::PatchReport::fallback`]): small enough to change a value a sheared patch
/// reached by about a thousandth of the two estimates' difference, and the whole value
/// where none did.
pub const FALLBACK_WEIGHT: f32 = 1e-3;

/// A disparity in half pixels per view step: whole pixels and halves, within
/// `±MAX_DISPARITY`. Copied into every [`crate::decode::tile::PatchOrigin`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Disparity(i8);

impl Disparity {
    /// No shear.
    pub const ZERO: Self = Self(0);

    /// `d` whole pixels, clamped to `±MAX_DISPARITY`.
    pub const fn pixels(d: i8) -> Self {
        let m = MAX_DISPARITY;
        Self(
            2 * if d > m {
                m
            } else if d < -m {
                -m
            } else {
                d
            },
        )
    }

    /// `h / 2` pixels, clamped to `±MAX_DISPARITY`.
    pub const fn halves(h: i8) -> Self {
        let m = 2 * MAX_DISPARITY;
        Self(if h > m {
            m
        } else if h < -m {
            -m
        } else {
            h
        })
    }

    /// The disparity in half pixels.
    pub const fn in_halves(self) -> i8 {
        self.0
    }

    /// The disparity in pixels.
    pub fn as_f32(self) -> f32 {
        f32::from(self.0) / 2.0
    }

    /// Whether it is a whole number of pixels (the shear is a selection).
    pub const fn is_whole(self) -> bool {
        self.0 % 2 == 0
    }
}

impl core::fmt::Display for Disparity {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.is_whole() { write!(f, "{}", self.0 / 2) } else { write!(f, "{}", self.as_f32()) }
    }
}

/// The candidate disparities of a decode: `min..=max` in steps of one pixel, or of half a
/// pixel ([`with_halves`](Self::with_halves)). Config: immutable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DisparityRange {
    min: i8,
    max: i8,
    halves: bool,
}

impl DisparityRange {
    /// Only `d = 0`: the unsheared decode, bit for bit.
    pub const OFF: Self = Self { min: 0, max: 0, halves: false };

    /// The host's and the device's default: `-1..=1`. On the realistic set (three HCI
    /// light fields, four realistic scenes; `docs/results-depth.md`) it gained +1.3 to +1.8
    /// dB on average at pixel k = 1 and 3 and on the lenslet mask; `-2..=2` gained the same
    /// within 0.02 dB (their disparities lie within about 1.5) and widens the halo a sink
    /// keeps from 2 to 4 lenslets.
    pub const DEFAULT: Self = Self { min: -1, max: 1, halves: false };

    /// The default search of a capture of `snapshots` snapshots through a mask of `family`:
    /// [`DEFAULT`](Self::DEFAULT), with half-pixel disparities for a single snapshot and on
    /// the lenslet mask at any count.
    ///
    /// Measured on the realistic set with the shipped ensemble (`docs/results-depth.md`):
    /// halves gained +0.77 dB at pixel k = 1 (every scene, 1.3 times the integers' time) but
    /// lost 0.44 dB at pixel k = 3: with more snapshots a point's views are measured often
    /// enough that the interpolating measurements' lost detail outweighs the better
    /// alignment. On the lenslet mask every view of a lenslet sees one band a snapshot, so
    /// a view's other bands come only from its neighbours, through the alignment: halves
    /// with the shear trial deciding per frame gained more than 0.1 dB on 14, 15 and 11 of
    /// issue 62's 21 scenes at k = 2, 3 and 5 (up to +9.53), +1.3 to +1.7 dB on average,
    /// and lost on 3 of the 63 decodes (canopy-dim k = 2 -0.94, depth k = 3 -0.86,
    /// tungsten k = 2 -0.11), at 1.3 to 1.8 times the time (medians; up to 3.3)
    /// (`scripts/halves-check.sh`, `docs/bench/README.md`).
    pub const fn for_capture(family: MaskFamily, snapshots: u8) -> Self {
        Self::DEFAULT.with_halves(snapshots == 1 || matches!(family, MaskFamily::Lenslet))
    }

    /// The integers `min..=max`; `None` unless `-MAX_DISPARITY <= min <= 0 <= max <=
    /// MAX_DISPARITY` (0 is always a candidate: the unsheared patch).
    pub const fn new(min: i8, max: i8) -> Option<Self> {
        if min <= 0 && max >= 0 && min >= -MAX_DISPARITY && max <= MAX_DISPARITY {
            Some(Self { min, max, halves: false })
        } else {
            None
        }
    }

    /// The smallest candidate.
    pub const fn min(&self) -> i8 {
        self.min
    }

    /// The largest candidate.
    pub const fn max(&self) -> i8 {
        self.max
    }

    /// The same range with the half-pixel disparities between its integers too
    /// (`halves`), or without.
    pub const fn with_halves(self, halves: bool) -> Self {
        Self { halves, ..self }
    }

    /// Whether half-pixel disparities are candidates.
    pub const fn has_halves(&self) -> bool {
        self.halves
    }

    /// Whether only `d = 0` is searched.
    pub const fn is_off(&self) -> bool {
        self.min == 0 && self.max == 0
    }

    /// The candidates, 0 first and then by growing magnitude (negative first on a tie),
    /// the order [`Best`] prefers on equal scores.
    pub fn candidates(&self) -> impl Iterator<Item = Disparity> + use<> {
        let (min, max, step) = (2 * self.min, 2 * self.max, if self.halves { 1 } else { 2 });
        (0..=2 * MAX_DISPARITY)
            .step_by(step)
            .flat_map(move |m| [-m, m])
            .filter(move |&h| h >= min && h <= max)
            .enumerate()
            // `-0` and `0` are the same candidate: keep the first.
            .filter_map(|(i, h)| (i == 0 || h != 0).then_some(Disparity(h)))
    }

    /// The lenslets a shear reaches beyond the patch on either side, for lenslets of
    /// `views` views along an axis: `max |d| * max |u - uc|`.
    pub const fn halo(&self, views: usize) -> usize {
        reach(Disparity::pixels(if -self.min > self.max { self.min } else { self.max }), views)
    }
}

impl Default for DisparityRange {
    fn default() -> Self {
        Self::OFF
    }
}

/// The lenslets a shear to `d` reaches beyond the patch on either side, for lenslets of
/// `views` views along an axis: `|d| * max |u - uc|`, rounded up.
pub const fn reach(d: Disparity, views: usize) -> usize {
    (d.0.unsigned_abs() as usize * (views.saturating_sub(1) - views.saturating_sub(1) / 2)).div_ceil(2)
}

/// Half lenslets by which view `view` of a lenslet with `views` views (along one axis) is
/// shifted in a patch sheared to `d`: `-d (view - uc)`, `uc = (views - 1) / 2`.
#[inline(always)]
pub const fn shift_halves(d: Disparity, view: usize, views: usize) -> isize {
    let centre = (views.saturating_sub(1) / 2) as isize;
    -(d.0 as isize) * (view as isize - centre)
}

/// The lenslet a sheared patch reads its grid position 0 of view `view` from, relative to
/// its own: the view's shift [`shift_halves`] rounded up. A whole shift is that shift; a
/// half one (`is_half`) puts the pixel half a lenslet past grid position 0, so the pixel
/// at lenslet `shift + s` measures the mean of positions `s` and `s + 1`.
#[inline(always)]
pub const fn shift(d: Disparity, view: usize, views: usize) -> isize {
    let h = shift_halves(d, view, views);
    h.div_euclid(2) + h.rem_euclid(2)
}

/// Whether view `view` sits half a lenslet off the grid in a patch sheared to `d`.
#[inline(always)]
pub const fn is_half(d: Disparity, view: usize, views: usize) -> bool {
    shift_halves(d, view, views) % 2 != 0
}

/// The shift by which [`Consistency`] scores `d` for view `view`: [`shift_halves`] rounded
/// to a whole lenslet, halves away from zero.
#[inline(always)]
pub const fn rounded_shift(d: Disparity, view: usize, views: usize) -> isize {
    let h = shift_halves(d, view, views);
    if h >= 0 { (h + 1) / 2 } else { -((1 - h) / 2) }
}

/// How well one candidate disparity aligns a block's views: the mean squared difference
/// of every pair of samples that saw the same point through the same band. Fed one
/// point (a lenslet of the sheared block, all its views) at a time; no buffer beyond a
/// few sums per band.
#[derive(Clone, Copy, Debug)]
pub struct Consistency {
    /// Per band of the current point: samples, their sum and their sum of squares.
    count: [u32; MAX_BANDS],
    sum: [f32; MAX_BANDS],
    squares: [f32; MAX_BANDS],
    /// Over the finished points: sum of squared pair differences, and pairs.
    total: f32,
    pairs: u32,
}

impl Default for Consistency {
    fn default() -> Self {
        Self::new()
    }
}

impl Consistency {
    /// Nothing seen.
    pub const fn new() -> Self {
        Self { count: [0; MAX_BANDS], sum: [0.0; MAX_BANDS], squares: [0.0; MAX_BANDS], total: 0.0, pairs: 0 }
    }

    /// One sample of the current point: `y` measured through `band` (white-balanced, so
    /// bands compare in the same units; a band outside `MAX_BANDS` is ignored).
    #[inline]
    pub fn add(&mut self, band: usize, y: f32) {
        if let (Some(n), Some(s), Some(q)) =
            (self.count.get_mut(band), self.sum.get_mut(band), self.squares.get_mut(band))
        {
            *n += 1;
            *s += y;
            *q += y * y;
        }
    }

    /// Ends the current point: its same-band pairs join the totals. Per band of `n`
    /// samples, `sum over pairs (y_i - y_j)^2 = n sum y^2 - (sum y)^2`.
    pub fn end_point(&mut self) {
        for ((n, s), q) in self.count.iter_mut().zip(&mut self.sum).zip(&mut self.squares) {
            if *n >= 2 {
                let nf = *n as f32;
                self.total += (nf * *q - *s * *s).max(0.0);
                self.pairs += *n * (*n - 1) / 2;
            }
            (*n, *s, *q) = (0, 0.0, 0.0);
        }
    }

    /// Pairs compared so far.
    pub fn pairs(&self) -> u32 {
        self.pairs
    }

    /// The mean squared difference per pair (lower: better aligned); `None` without a pair.
    pub fn score(&self) -> Option<f32> {
        (self.pairs > 0).then(|| self.total / self.pairs as f32)
    }
}

/// Keeps the best-scoring candidate: lowest score, the first seen on a tie (feed
/// candidates in [`DisparityRange::candidates`] order, 0 first). A candidate without a
/// score (no pair: too few samples) never wins.
#[derive(Clone, Copy, Debug, Default)]
pub struct Best {
    best: Option<(Disparity, f32)>,
}

impl Best {
    /// Offers candidate `d` with its consistency.
    pub fn offer(&mut self, d: Disparity, c: &Consistency) {
        if let Some(score) = c.score().filter(|s| s.is_finite())
            && self.best.is_none_or(|(_, b)| score < b)
        {
            self.best = Some((d, score));
        }
    }

    /// The winner, 0 if no candidate had a score.
    pub fn disparity(&self) -> Disparity {
        self.best.map_or(Disparity::ZERO, |(d, _)| d)
    }
}

/// Which view rows and columns of a patch sit half a lenslet off its grid ([`is_half`]):
/// bit `u` of `rows` for the patch's view row `u`, bit `v` of `cols` for view column `v`.
/// A measurement of such a view is the mean of the two grid values on either side of its
/// pixel along that axis (of four where both are half); none: every measurement is one
/// value of the patch (a selection).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HalfViews {
    pub rows: u32,
    pub cols: u32,
}

impl HalfViews {
    /// Every view on the grid.
    pub const NONE: Self = Self { rows: 0, cols: 0 };

    /// The half views of a patch whose window starts at view `(row0, col0)` of lenslets of
    /// `views` views, sheared to `d` (views past the 32nd are never half).
    pub fn of(d: Disparity, (row0, col0): (usize, usize), views: (usize, usize)) -> Self {
        let mut h = Self::NONE;
        for i in 0..32usize {
            if row0 + i < views.0 && is_half(d, row0 + i, views.0) {
                h.rows |= 1 << i;
            }
            if col0 + i < views.1 && is_half(d, col0 + i, views.1) {
                h.cols |= 1 << i;
            }
        }
        h
    }

    /// Whether no view is half off the grid.
    pub const fn is_none(&self) -> bool {
        self.rows == 0 && self.cols == 0
    }

    /// Whether the patch's view row `u` is half off the grid.
    #[inline(always)]
    pub const fn row(&self, u: usize) -> bool {
        u < 32 && (self.rows >> u) & 1 != 0
    }

    /// Whether the patch's view column `v` is half off the grid.
    #[inline(always)]
    pub const fn col(&self, v: usize) -> bool {
        v < 32 && (self.cols >> v) & 1 != 0
    }
}
