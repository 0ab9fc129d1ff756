//! The set a projection moves a patch onto: the measurements exactly, or a noise ball
//! around them.
//!
//! A measurement `y` of a sensor with shot and read noise has variance
//! `floor + shot * max(y, 0)` in normalised units (`floor`: read and quantisation noise;
//! `shot`: `1 / electrons at white`, since a Poisson count's variance is its mean).
//!
//! The ball is `sum_i r_i^2 / var_i <= m - p + p / 16` over the `m` measurements'
//! residuals `r = y - P x`, where `p` pixels are measured at all. `m - p` is the expected
//! size of the whitened residual of a fit with one free value per measured pixel (as an
//! unbiased variance estimate subtracts the parameters fitted): a pixel's brightness is
//! what its own measurements pin down, so only its second and later measurements show
//! noise. A sixteenth of each pixel's first measurement ([`FIRST_SHARE`]) lets a one-shot
//! decode shed some noise too. Measured on real scenes (HCI, 128 x 128, pixel mask; see
//! `docs/results-noise.md`): at one snapshot and the default sensor it costs 0.03-0.06 dB
//! against the exact projection (a ball of `m / 4` cost 0.12-0.19 dB, one of `m` 0.3-0.75),
//! and gains 0.2 dB at 1,000 electrons at white and 0.5 dB at 200; at three snapshots it
//! gains 0.45-1.1 dB (a ball of `m`: 0.3-0.8).
//!
//! A point inside the ball is left alone; one outside is moved along the straight line to
//! the exact projection until it meets the surface, so every residual is scaled by the same
//! factor. With equal variances (`shot` 0) that is the Euclidean projection onto a sphere;
//! with unequal ones it is a point on the ellipsoid's surface (not the nearest, which needs
//! a root search per step), found at the cost of one division per measurement.
//!
//! White-balanced values ([`crate::sensor::gains`]) are the sensor's divided by their band's gain
//! `g`, so their variance is the sensor's over `g^2`: the ball weighs each residual by its
//! band's gain ([`Ball::weight`]), and is weighted whenever any gain differs from 1, even
//! without shot noise.

/// The share of a pixel's first measurement in the ball's squared radius (see the module
/// docs for how it was chosen).
pub const FIRST_SHARE: f32 = 1.0 / 16.0;

/// Which points meet the measurements. Built by [`Ball::new`] from a noise description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Variance every measurement has (read and quantisation), normalised units squared.
    floor: f32,
    /// Variance per unit of signal (shot noise).
    shot: f32,
    /// `m - p + p * FIRST_SHARE`: the ball's squared radius in whitened units.
    radius2: f32,
    /// The values are white-balanced with gains other than 1.
    balanced: bool,
}

/// What a projection does with a residual of a given size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Move {
    /// Leave the point (inside the ball).
    Stay,
    /// Remove this fraction of every residual: 1 is the exact projection.
    Scale(f32),
}

impl Ball {
    /// The ball for `m` measurements at `p` measured pixels (`p <= m`), of standard
    /// deviation `noise` plus `shot` variance per unit of signal; both 0 is the exact
    /// projection.
    pub fn new(noise: f32, shot: f32, m: u32, p: u32) -> Self {
        let p = p.min(m);
        Self { floor: noise * noise, shot, radius2: (m - p) as f32 + p as f32 * FIRST_SHARE, balanced: false }
    }

    /// The same ball for white-balanced values (`balanced`: some band's gain is not 1).
    pub fn balanced(self, balanced: bool) -> Self {
        Self { balanced, ..self }
    }

    /// Equality with the measurements.
    #[inline(always)]
    pub fn is_exact(&self) -> bool {
        self.floor == 0.0 && self.shot == 0.0
    }

    /// Whether measurements differ in variance, so residuals are weighted one by one.
    #[inline(always)]
    pub fn is_weighted(&self) -> bool {
        self.shot > 0.0 || (self.balanced && !self.is_exact())
    }

    /// `1 / var` of a measurement of value `y` in a band of gain `gain` (weighted balls;
    /// at least the reciprocal of the smallest normal `f32`, so a zero residual weighs 0,
    /// never NaN). The sensor saw `y * gain`, of variance `floor + shot * max(y gain, 0)`;
    /// divided by `gain` its variance is that over `gain^2`. With gain 1 this is bit for
    /// bit the unbalanced weight.
    #[inline(always)]
    pub fn weight(&self, y: f32, gain: f32) -> f32 {
        // Comparisons, not `f32::max`: on a Cortex-M4F that is a call to `fmaxf` (its NaN
        // rules), and this runs once per measurement per step.
        let seen = y * gain;
        let var = (self.floor + self.shot * if seen > 0.0 { seen } else { 0.0 }) / (gain * gain);
        1.0 / if var > f32::MIN_POSITIVE { var } else { f32::MIN_POSITIVE }
    }

    /// The move for a residual whose squared norm is `r2` (plain) and `w2` (weighted by
    /// [`Ball::weight`]; read only for weighted balls).
    #[inline(always)]
    pub fn move_for(&self, r2: f32, w2: f32) -> Move {
        if self.is_exact() {
            return Move::Scale(1.0);
        }
        // Whitened squared norm: each residual over its variance.
        let white2 = if self.is_weighted() { w2 } else { r2 / self.floor };
        if white2 > self.radius2 { Move::Scale(1.0 - libm::sqrtf(self.radius2 / white2)) } else { Move::Stay }
    }
}
