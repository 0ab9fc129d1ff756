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
//! ([`crate::tile::PatchOrigin::lenslet`]).
//!
//! The disparity is chosen per spatial block, before any solve, from the measurements
//! themselves ([`Consistency`]): with the views aligned, the samples of one point that
//! went through the same filter must agree, so the candidate whose same-band samples
//! differ least is the block's depth. With a per-pixel one-hot mask the 25 views of a
//! point see about two samples per band, so a 5 x 5-lenslet block compares a few hundred
//! pairs per candidate. Fractional disparities rounded to the nearest pixel measured no
//! better than the integers (`docs/results-depth.md`), so candidates are integers. (Exact
//! fractional shears, where a measurement interpolates several patch values, measured far
//! better on a slow reference; they need a projection that is not a selection.)

use crate::shape::MAX_BANDS;

/// The largest disparity magnitude a decoder searches (pixels per view step): a shear of
/// `d` reaches `d (U - 1) / 2` lenslets beyond the patch, and sinks keep that halo.
pub const MAX_DISPARITY: i8 = 3;

/// The weight, relative to a sheared patch's, of an unsheared fallback estimate
/// ([`crate::tile::PatchReport::fallback`]): small enough to change a value a sheared patch
/// reached by about a thousandth of the two estimates' difference, and the whole value
/// where none did.
pub const FALLBACK_WEIGHT: f32 = 1e-3;

/// The candidate disparities of a decode: the integers `min..=max`. Config: immutable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DisparityRange {
    min: i8,
    max: i8,
}

impl DisparityRange {
    /// Only `d = 0`: the unsheared decode, bit for bit.
    pub const OFF: Self = Self { min: 0, max: 0 };

    /// The host's and the device's default: `-1..=1`. On the realistic set (three HCI
    /// light fields, four realistic scenes; `docs/results-depth.md`) it gained +1.3 to +1.8
    /// dB on average at pixel k = 1 and 3 and on the lenslet mask; `-2..=2` gained the same
    /// within 0.02 dB (their disparities lie within about 1.5) and widens the halo a sink
    /// keeps from 2 to 4 lenslets.
    pub const DEFAULT: Self = Self { min: -1, max: 1 };

    /// The integers `min..=max`; `None` unless `-MAX_DISPARITY <= min <= 0 <= max <=
    /// MAX_DISPARITY` (0 is always a candidate: the unsheared patch).
    pub const fn new(min: i8, max: i8) -> Option<Self> {
        if min <= 0 && max >= 0 && min >= -MAX_DISPARITY && max <= MAX_DISPARITY {
            Some(Self { min, max })
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

    /// Whether only `d = 0` is searched.
    pub const fn is_off(&self) -> bool {
        self.min == 0 && self.max == 0
    }

    /// The candidates, 0 first and then by growing magnitude (negative first on a tie),
    /// the order [`Best`] prefers on equal scores.
    pub fn candidates(&self) -> impl Iterator<Item = i8> + use<> {
        let (min, max) = (self.min, self.max);
        (0..=MAX_DISPARITY).flat_map(move |m| [-m, m]).filter(move |&d| d >= min && d <= max).enumerate().filter_map(
            // `-0` and `0` are the same candidate: keep the first.
            |(i, d)| (i == 0 || d != 0).then_some(d),
        )
    }

    /// The lenslets a shear reaches beyond the patch on either side, for lenslets of
    /// `views` views along an axis: `max |d| * max |u - uc|`.
    pub const fn halo(&self, views: usize) -> usize {
        reach(if -self.min > self.max { self.min } else { self.max }, views)
    }
}

impl Default for DisparityRange {
    fn default() -> Self {
        Self::OFF
    }
}

/// The lenslets a shear to `d` reaches beyond the patch on either side, for lenslets of
/// `views` views along an axis: `|d| * max |u - uc|`.
pub const fn reach(d: i8, views: usize) -> usize {
    d.unsigned_abs() as usize * (views.saturating_sub(1) - views.saturating_sub(1) / 2)
}

/// Lenslets by which view `view` of a lenslet with `views` views (along one axis) is
/// shifted in a patch sheared to disparity `d`: `-d (view - uc)`, `uc = (views - 1) / 2`.
#[inline(always)]
pub const fn shift(d: i8, view: usize, views: usize) -> isize {
    let centre = (views.saturating_sub(1) / 2) as isize;
    -(d as isize) * (view as isize - centre)
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
    best: Option<(i8, f32)>,
}

impl Best {
    /// Offers candidate `d` with its consistency.
    pub fn offer(&mut self, d: i8, c: &Consistency) {
        if let Some(score) = c.score().filter(|s| s.is_finite())
            && self.best.is_none_or(|(_, b)| score < b)
        {
            self.best = Some((d, score));
        }
    }

    /// The winner, 0 if no candidate had a score.
    pub fn disparity(&self) -> i8 {
        self.best.map_or(0, |(d, _)| d)
    }
}
