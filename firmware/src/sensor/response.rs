//! The filters' response matrix: what a real filter lets through of each band.
//!
//! A one-hot mask assumes a pixel behind filter `f` sees band `f` alone. A real filter (a
//! Fabry-Perot pixel filter of a snapshot mosaic sensor) is 10-40 nm wide, has secondary
//! peaks and a floor, so the pixel measures a weighted sum `R[f] . x` of the pixel's
//! spectrum `x`, with `R` the `B x B` response matrix (filter x band) a calibration
//! measures (`slf calibrate`). The decode puts that sum in its model: a pixel with filters
//! `F` measures `R_F x`, and the solver's projection onto the pixel's measurements is
//! `x <- x + R_F^T (R_F R_F^T)^-1 (y - R_F x)`, a `k x k` solve per pixel for its `k`
//! filters ([`crate::solver::mixing`]). The identity response is the one-hot mask.
//!
//! A response is checked once, at [`Response::new`]: finite, rows that sum to a positive
//! amount, and invertible with a condition number (1-norm) of at most [`MAX_CONDITION`],
//! the inverse kept for the decode's short paths (a flat patch's band means and a patch
//! interpolated per pixel are `R x`, not `x`). The decode trusts it afterwards.
//!
//! White balance ([`crate::sensor::gains`]) divides filter `f`'s measurements by `g_f`
//! and decodes `x_b / g_b`: in those units the response is `G^-1 R G`
//! ([`Response::balanced`]).

use crate::sensor::mask::SensingError;

/// The largest condition number (1-norm) a response may have: beyond it the filters do not
/// tell the bands apart, and the decode would amplify noise by as much. The host's
/// calibration refuses the same bound (in the 2-norm, which is at most as large).
pub const MAX_CONDITION: f32 = 1e3;

/// A checked `B x B` response matrix (row `f`: filter `f`'s transmission of each band) with
/// its inverse.
///
/// Both are held as their difference from the identity, so that the identity is all
/// zeros: a [`crate::solver::workspace::Workspace`] holding one stays zero-initialised,
/// which is what lets a device's `static` workspace be built in place (with the identity
/// stored as ones on the diagonal, the emulated Cortex-M7 built the 107 KB workspace on the
/// stack and copied it: the painted stack peak went from 27 to 104 KB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response<const B: usize> {
    /// `R - I`.
    leak: [[f32; B]; B],
    /// `R^-1 - I`.
    unleak: [[f32; B]; B],
    mixed: bool,
}

impl<const B: usize> Response<B> {
    /// The ideal filters: each pixel sees its band alone.
    pub const IDENTITY: Self = Self { leak: [[0.0; B]; B], unleak: [[0.0; B]; B], mixed: false };

    /// A checked response.
    ///
    /// # Errors
    /// [`SensingError::Response`] for a matrix with an entry that is not finite, a row
    /// whose sum is not positive, or a condition number above [`MAX_CONDITION`] (singular
    /// included).
    pub fn new(r: &[[f32; B]; B]) -> Result<Self, SensingError> {
        if !r.iter().all(|row| row.iter().all(|x| x.is_finite()) && row.iter().sum::<f32>() > 0.0) {
            return Err(SensingError::Response);
        }
        let inverse = invert(r).ok_or(SensingError::Response)?;
        let condition = norm1(r) * norm1(&inverse);
        // (`is_finite` first: a NaN condition is refused too.)
        if !condition.is_finite() || condition > MAX_CONDITION || !inverse.iter().flatten().all(|x| x.is_finite()) {
            return Err(SensingError::Response);
        }
        let less = |m: &[[f32; B]; B]| map(m, |i, j, x| x - id(i, j));
        let mixed = (0..B).any(|i| (0..B).any(|j| r[i][j] != id(i, j)));
        Ok(Self { leak: less(r), unleak: less(&inverse), mixed })
    }

    /// Whether this is the identity (the one-hot model: the decode's fast path as it was).
    pub fn is_identity(&self) -> bool {
        !self.mixed
    }

    /// The matrix, row `f` for filter `f`.
    pub fn matrix(&self) -> [[f32; B]; B] {
        map(&self.leak, |i, j, x| x + id(i, j))
    }

    /// Its inverse: `x = R^-1 z` for `z` one value per filter.
    pub fn inverse(&self) -> [[f32; B]; B] {
        map(&self.unleak, |i, j, x| x + id(i, j))
    }

    /// The response in white-balanced units, for band gains `g` (each positive, as
    /// [`crate::sensor::gains::valid`] checks): `G^-1 R G` and its inverse `G^-1 R^-1 G`.
    /// The identity is its own balance, so only the differences scale.
    pub fn balanced(&self, g: &[f32]) -> Self {
        if !self.mixed {
            return *self;
        }
        let gain = |b: usize| g.get(b).copied().unwrap_or(1.0);
        let scale = |m: &[[f32; B]; B]| map(m, |f, b, x| x * gain(b) / gain(f));
        Self { leak: scale(&self.leak), unleak: scale(&self.unleak), mixed: true }
    }

    /// One pixel's spectrum as its filters see it, in place: `z = R x`.
    pub fn mix(&self, x: &mut [f32; B]) {
        if self.mixed {
            *x = apply(&self.leak, x);
        }
    }

    /// One pixel's values, one per filter, unmixed in place: `x = R^-1 z`.
    pub fn unmix(&self, z: &mut [f32; B]) {
        if self.mixed {
            *z = apply(&self.unleak, z);
        }
    }
}

/// `(I + d) x`.
fn apply<const B: usize>(d: &[[f32; B]; B], x: &[f32; B]) -> [f32; B] {
    let mut out = *x;
    for (o, row) in out.iter_mut().zip(d) {
        *o += row.iter().zip(x).map(|(a, v)| a * v).sum::<f32>();
    }
    out
}

/// `f(i, j, m[i][j])` for every entry, by iterators: indexing inside `array::from_fn`
/// left bounds checks (panic call sites) in the device's release build.
fn map<const B: usize, T: Copy, U: Copy + Default>(m: &[[T; B]; B], f: impl Fn(usize, usize, T) -> U) -> [[U; B]; B] {
    let mut out = [[U::default(); B]; B];
    for (i, (o, row)) in out.iter_mut().zip(m).enumerate() {
        for (j, (x, &v)) in o.iter_mut().zip(row).enumerate() {
            *x = f(i, j, v);
        }
    }
    out
}

/// Entry `(i, j)` of the identity.
fn id(i: usize, j: usize) -> f32 {
    if i == j { 1.0 } else { 0.0 }
}

/// The 1-norm (largest column sum of magnitudes).
fn norm1<const B: usize>(m: &[[f32; B]; B]) -> f32 {
    (0..B).map(|c| m.iter().map(|row| row[c].abs()).sum::<f32>()).fold(0.0, |a, s| if s > a { s } else { a })
}

/// `m^-1` by Gauss-Jordan elimination with partial pivoting in f64 (a one-off at set-up:
/// f64 keeps the inverse's rounding far below the condition bound's), or `None` for a
/// pivot below `1e-12` of the matrix's largest entry.
#[allow(clippy::needless_range_loop)] // elimination reads best with its indices
fn invert<const B: usize>(m: &[[f32; B]; B]) -> Option<[[f32; B]; B]> {
    let mut a: [[f64; B]; B] = map(m, |_, _, x| f64::from(x));
    let mut inv: [[f64; B]; B] = map(m, |i, j, _| if i == j { 1.0 } else { 0.0 });
    let top = a.iter().flatten().fold(0.0f64, |t, x| if x.abs() > t { x.abs() } else { t });
    for c in 0..B {
        let mut p = c;
        for r in c + 1..B {
            if a[r][c].abs() > a[p][c].abs() {
                p = r;
            }
        }
        if a[p][c].is_nan() || a[p][c].abs() <= 1e-12 * top {
            return None;
        }
        a.swap(c, p);
        inv.swap(c, p);
        let pivot = 1.0 / a[c][c];
        for j in 0..B {
            a[c][j] *= pivot;
            inv[c][j] *= pivot;
        }
        for r in 0..B {
            if r != c {
                let f = a[r][c];
                if f != 0.0 {
                    for j in 0..B {
                        a[r][j] -= f * a[c][j];
                        inv[r][j] -= f * inv[c][j];
                    }
                }
            }
        }
    }
    Some(map(&inv, |_, _, x| x as f32))
}
