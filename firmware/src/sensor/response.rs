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

use crate::sensor::extent::{Array, BandCount, Bands, Fixed, Square};
use crate::sensor::mask::SensingError;

/// The largest condition number (1-norm) a response may have: beyond it the filters do not
/// tell the bands apart, and the decode would amplify noise by as much. The host's
/// calibration refuses the same bound (in the 2-norm, which is at most as large).
pub const MAX_CONDITION: f32 = 1e3;

/// A checked `B x B` response matrix (row `f`: filter `f`'s transmission of each band) with
/// its inverse, over the bands `C` ([`crate::sensor::extent::BandCount`]).
///
/// Both are held as their difference from the identity, so that the identity is all
/// zeros: a [`crate::solver::workspace::Workspace`] holding one stays zero-initialised,
/// which is what lets a device's `static` workspace be built in place (with the identity
/// stored as ones on the diagonal, the emulated Cortex-M7 built the 107 KB workspace on the
/// stack and copied it: the painted stack peak went from 27 to 104 KB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response<C: Bands> {
    /// `R - I`.
    leak: Square<C, f32>,
    /// `R^-1 - I`.
    unleak: Square<C, f32>,
    mixed: bool,
}

impl<C: Bands> Response<C> {
    /// The ideal filters: each pixel sees its band alone.
    pub const IDENTITY: Self = Self { leak: C::ZERO_MATRIX, unleak: C::ZERO_MATRIX, mixed: false };

    /// A checked response ([`Response::new`]).
    fn checked(r: &Square<C, f32>) -> Result<Self, SensingError> {
        let rows = r.as_ref();
        if !rows.iter().all(|row| row.as_ref().iter().all(|x| x.is_finite()) && row.as_ref().iter().sum::<f32>() > 0.0)
        {
            return Err(SensingError::Response);
        }
        let inverse = invert::<C>(r).ok_or(SensingError::Response)?;
        let condition = norm1::<C>(r) * norm1::<C>(&inverse);
        // (`is_finite` first: a NaN condition is refused too.)
        let finite = inverse.as_ref().iter().all(|row| row.as_ref().iter().all(|x| x.is_finite()));
        if !condition.is_finite() || condition > MAX_CONDITION || !finite {
            return Err(SensingError::Response);
        }
        let less = |m: &Square<C, f32>| map::<C, f32, f32>(m, |i, j, x| x - id(i, j));
        let mixed =
            rows.iter().enumerate().any(|(i, row)| row.as_ref().iter().enumerate().any(|(j, &x)| x != id(i, j)));
        Ok(Self { leak: less(r), unleak: less(&inverse), mixed })
    }

    /// Whether this is the identity (the one-hot model: the decode's fast path as it was).
    pub fn is_identity(&self) -> bool {
        !self.mixed
    }

    /// The matrix, row `f` for filter `f`.
    pub fn matrix(&self) -> Square<C, f32> {
        map::<C, f32, f32>(&self.leak, |i, j, x| x + id(i, j))
    }

    /// Its inverse: `x = R^-1 z` for `z` one value per filter.
    pub fn inverse(&self) -> Square<C, f32> {
        map::<C, f32, f32>(&self.unleak, |i, j, x| x + id(i, j))
    }

    /// The response in white-balanced units, for band gains `g` (each positive, as
    /// [`crate::sensor::gains::valid`] checks): `G^-1 R G` and its inverse `G^-1 R^-1 G`.
    /// The identity is its own balance, so only the differences scale.
    pub fn balanced(&self, g: &[f32]) -> Self {
        if !self.mixed {
            return *self;
        }
        let gain = |b: usize| g.get(b).copied().unwrap_or(1.0);
        let scale = |m: &Square<C, f32>| map::<C, f32, f32>(m, |f, b, x| x * gain(b) / gain(f));
        Self { leak: scale(&self.leak), unleak: scale(&self.unleak), mixed: true }
    }

    /// One pixel's spectrum as its filters see it, in place: `z = R x`.
    pub fn mix(&self, x: &mut C::Per<f32>) {
        if self.mixed {
            *x = apply::<C>(&self.leak, x);
        }
    }

    /// One pixel's values, one per filter, unmixed in place: `x = R^-1 z`.
    pub fn unmix(&self, z: &mut C::Per<f32>) {
        if self.mixed {
            *z = apply::<C>(&self.unleak, z);
        }
    }
}

impl<const B: usize> Response<BandCount<B>> {
    /// A checked response of `B` bands.
    ///
    /// # Errors
    /// [`SensingError::Response`] for a matrix with an entry that is not finite, a row
    /// whose sum is not positive, or a condition number above [`MAX_CONDITION`] (singular
    /// included).
    pub fn new(r: &[[f32; B]; B]) -> Result<Self, SensingError> {
        Self::checked(r)
    }
}

/// `(I + d) x`.
fn apply<C: Bands>(d: &Square<C, f32>, x: &C::Per<f32>) -> C::Per<f32> {
    let mut out = *x;
    for (o, row) in out.as_mut().iter_mut().zip(d.as_ref()) {
        *o += row.as_ref().iter().zip(x.as_ref()).map(|(a, v)| a * v).sum::<f32>();
    }
    out
}

/// `f(i, j, m[i][j])` for every entry, by iterators: indexing inside `array::from_fn`
/// left bounds checks (panic call sites) in the device's release build.
fn map<C: Bands, T, U>(m: &Square<C, T>, f: impl Fn(usize, usize, T) -> U) -> Square<C, U>
where
    T: Copy + core::fmt::Debug + PartialEq,
    U: Copy + core::fmt::Debug + PartialEq + Default,
{
    let mut out = Square::<C, U>::splat(C::Per::<U>::splat(U::default()));
    for (i, (o, row)) in out.as_mut().iter_mut().zip(m.as_ref()).enumerate() {
        for (j, (x, &v)) in o.as_mut().iter_mut().zip(row.as_ref()).enumerate() {
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
fn norm1<C: Bands>(m: &Square<C, f32>) -> f32 {
    (0..C::D)
        .map(|c| m.as_ref().iter().map(|row| row[c].abs()).sum::<f32>())
        .fold(0.0, |a, s| if s > a { s } else { a })
}

/// `m^-1` by Gauss-Jordan elimination with partial pivoting in f64 (a one-off at set-up:
/// f64 keeps the inverse's rounding far below the condition bound's), or `None` for a
/// pivot below `1e-12` of the matrix's largest entry.
fn invert<C: Bands>(m: &Square<C, f32>) -> Option<Square<C, f32>> {
    let mut a: Square<C, f64> = map::<C, f32, f64>(m, |_, _, x| f64::from(x));
    let mut inv: Square<C, f64> = map::<C, f32, f64>(m, |i, j, _| if i == j { 1.0 } else { 0.0 });
    let top = a.as_ref().iter().flat_map(|row| row.as_ref()).fold(0.0f64, |t, x| if x.abs() > t { x.abs() } else { t });
    let b = C::D;
    for c in 0..b {
        let mut p = c;
        for r in c + 1..b {
            if a[r][c].abs() > a[p][c].abs() {
                p = r;
            }
        }
        if a[p][c].is_nan() || a[p][c].abs() <= 1e-12 * top {
            return None;
        }
        a.as_mut().swap(c, p);
        inv.as_mut().swap(c, p);
        let pivot = 1.0 / a[c][c];
        for j in 0..b {
            a[c][j] *= pivot;
            inv[c][j] *= pivot;
        }
        for r in 0..b {
            if r != c {
                let f = a[r][c];
                if f != 0.0 {
                    for j in 0..b {
                        let (ac, ic) = (a[c][j], inv[c][j]);
                        a[r][j] -= f * ac;
                        inv[r][j] -= f * ic;
                    }
                }
            }
        }
    }
    Some(map::<C, f64, f32>(&inv, |_, _, x| x as f32))
}

/// A band count whose ideal response lives in static memory: what a decoder borrows when
/// no response is given. (A constant of a type generic over `C` is not promoted to a
/// static where it is borrowed, as the compiler cannot see that the type holds no cell;
/// for [`Fixed`] counts it can.)
pub trait StaticIdentity: Bands {
    /// [`Response::IDENTITY`], in static memory.
    const IDENTITY_REF: &'static Response<Self>;
}

impl<const B: usize> StaticIdentity for Fixed<B> {
    const IDENTITY_REF: &'static Response<Self> = &Response::IDENTITY;
}
