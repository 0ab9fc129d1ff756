//! Measurements that mix bands: SL0's projection for filters with a response matrix.
//!
//! A pixel behind filters `F` (one per snapshot) measures `y = R_F x` of its spectrum `x`
//! ([`crate::sensor::response`]): `k` rows of the response matrix, not `k` of the
//! spectrum's entries. The patch's measurement operator is then `M D` with `D` the
//! orthonormal dictionary and `M` block diagonal, one `k x 13` block `R_F` per pixel, so
//! SL0's projection `S <- S + A^+ (y - A S)` with `A^+ = D^T M^T (M M^T)^-1` stays per
//! pixel: `(M M^T)^-1` is one `k x k` inverse of the Gram matrix `R_F R_F^T` per pixel,
//! read off `R R^T` (one `B x B` product per solve) and solved in place ([`BandModel::solve`]:
//! a division at `k = 1`, `L D L^T` above). Between the pixel modes' synthesis and analysis
//! the fast path already does, the band step reads each measurement as a dot product with a
//! row of `R D5` instead of `D5` (one `B x B x B` product per solve) and adds back
//! `R D5`'s rows weighted by the solved residuals: `2 B` multiply-adds a measurement as
//! before, plus the pixel's `k x k` solve. With the identity response it is the fast path.
//!
//! The solve's other steps change with it: the minimum-norm start is `R_F^T (R_F R_F^T)^-1 y`
//! per pixel, the band-gain fill and a flat patch's band means estimate `R x` and are
//! unmixed by `R^-1`, and the final put-back of the measurements is the per-pixel
//! projection ([`project_signal`]), since a measured entry is no longer the measurement.

use crate::operators::dictionary::Dictionary;
use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands, Square};
use crate::sensor::response::Response;
use crate::solver::ball::{Ball, Move};
use crate::solver::projection::{band_bits, dot, project_slices};
use crate::solver::workspace::Measurements;

/// What one solve needs of a response in the decode's (white-balanced) units: the response
/// itself, its rows through the dictionary's band mode, and its Gram matrix, over the bands
/// `C`.
pub struct BandModel<C: Bands> {
    /// `R`: filter `f`'s transmission of each band (signal space).
    r: Square<C, f32>,
    /// `R D5`: filter `f`'s measurement of the band coefficients (coefficient space).
    rows: Square<C, f32>,
    /// `R R^T`.
    gram: Square<C, f32>,
}

impl<C: Bands> BandModel<C> {
    /// The model of `response` (already balanced, [`Response::balanced`]) for a
    /// dictionary whose band mode's synthesis rows are `m5` (value `b` = `m5[b] . c`).
    pub fn new(response: &Response<C>, m5: &Square<C, f32>) -> Self {
        let r = response.matrix();
        let mut rows = Square::<C, f32>::splat(C::Per::<f32>::splat(0.0));
        for (row, rf) in rows.as_mut().iter_mut().zip(r.as_ref()) {
            for (&w, m) in rf.as_ref().iter().zip(m5.as_ref()) {
                for (o, &x) in row.as_mut().iter_mut().zip(m.as_ref()) {
                    *o += w * x;
                }
            }
        }
        let mut gram = Square::<C, f32>::splat(C::Per::<f32>::splat(0.0));
        for (g, ri) in gram.as_mut().iter_mut().zip(r.as_ref()) {
            for (o, rj) in g.as_mut().iter_mut().zip(r.as_ref()) {
                *o = dot(ri.as_ref(), rj.as_ref());
            }
        }
        Self { r, rows, gram }
    }

    /// Solves `(R_F R_F^T) w = res` in place for the filters `filters` (the first `k` of
    /// `res`): a division at `k = 1`, an `L D L^T` factorisation on the stack above. A
    /// pivot that is not positive (it cannot be for distinct filters of a checked response;
    /// rounding could only make one tiny) zeroes its unknown.
    pub fn solve(&self, filters: &[u8], res: &mut [f32]) {
        let n = filters.len().min(res.len()).min(C::D);
        let g = |i: usize, j: usize| {
            let (Some(&a), Some(&b)) = (filters.get(i), filters.get(j)) else { return 0.0 };
            self.gram
                .as_ref()
                .get(usize::from(a))
                .and_then(|row| row.as_ref().get(usize::from(b)))
                .copied()
                .unwrap_or(0.0)
        };
        if n == 1 {
            let d = g(0, 0);
            if let Some(x) = res.first_mut() {
                *x = if d > f32::MIN_POSITIVE { *x / d } else { 0.0 };
            }
            return;
        }
        let mut l = Square::<C, f32>::splat(C::Per::<f32>::splat(0.0));
        let (mut d, mut inv) = (C::Per::<f32>::splat(0.0), C::Per::<f32>::splat(0.0));
        for j in 0..n {
            let mut pivot = g(j, j);
            for k in 0..j {
                pivot -= l[j][k] * l[j][k] * d[k];
            }
            if pivot > f32::MIN_POSITIVE {
                (d[j], inv[j]) = (pivot, 1.0 / pivot);
            }
            for i in j + 1..n {
                let mut x = g(i, j);
                for k in 0..j {
                    x -= l[i][k] * l[j][k] * d[k];
                }
                l[i][j] = x * inv[j];
            }
        }
        let Some(res) = res.get_mut(..n) else { return };
        for i in 0..n {
            let mut x = res[i];
            for k in 0..i {
                x -= l[i][k] * res[k];
            }
            res[i] = x;
        }
        for i in (0..n).rev() {
            let mut x = res[i] * inv[i];
            for k in i + 1..n {
                x -= l[k][i] * res[k];
            }
            res[i] = if inv[i] > 0.0 { x } else { 0.0 };
        }
    }

    /// One pixel's residuals `y - rows_F x` in filter order, with the filters; returns how
    /// many. `rows` is `R` for a spectrum `x`, `R D5` for its band coefficients.
    fn residuals(
        rows: &Square<C, f32>,
        x: &C::Per<f32>,
        ys: &[f32],
        bits: u64,
        filters: &mut C::Per<u8>,
        res: &mut C::Per<f32>,
    ) -> usize {
        let mut bits = bits;
        let mut k = 0;
        while bits != 0 {
            let f = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let (Some(row), Some(&y), Some(o), Some(r)) =
                (rows.as_ref().get(f), ys.get(f), filters.as_mut().get_mut(k), res.as_mut().get_mut(k))
            else {
                break;
            };
            (*o, *r) = (f as u8, y - dot(row.as_ref(), x.as_ref()));
            k += 1;
        }
        k
    }

    /// `x += scale R_F^T w` for solved residuals `w` of `filters`.
    fn add_rows(rows: &Square<C, f32>, x: &mut C::Per<f32>, filters: &[u8], w: &[f32], scale: f32) {
        for (&f, &w) in filters.iter().zip(w.iter()) {
            if let Some(row) = rows.as_ref().get(usize::from(f)) {
                for (o, &a) in x.as_mut().iter_mut().zip(row.as_ref()) {
                    *o += scale * w * a;
                }
            }
        }
    }

    /// One pixel's residuals under `rows` (`R` for a spectrum `x`, `R D5` for its band
    /// coefficients), with their filters.
    fn pixel(rows: &Square<C, f32>, x: &C::Per<f32>, ys: &[f32], measured: &[bool]) -> PixelResiduals<C> {
        let (mut filters, mut res) = (C::Per::<u8>::splat(0), C::Per::<f32>::splat(0.0));
        let k = Self::residuals(rows, x, ys, band_bits(measured), &mut filters, &mut res);
        PixelResiduals { filters, res, k }
    }

    /// `x += scale R_F^T (R_F R_F^T)^-1 r` for a pixel's residuals `r` under `rows`.
    fn correct(&self, rows: &Square<C, f32>, x: &mut C::Per<f32>, p: &mut PixelResiduals<C>, scale: f32) {
        let (Some(filters), Some(res)) = (p.filters.get(..p.k), p.res.get_mut(..p.k)) else { return };
        self.solve(filters, res);
        Self::add_rows(rows, x, filters, res, scale);
    }
}

/// One pixel's residuals `y - rows_F x` in filter order ([`BandModel::pixel`]).
struct PixelResiduals<C: Bands> {
    filters: C::Per<u8>,
    res: C::Per<f32>,
    k: usize,
}

impl<C: Bands> PixelResiduals<C> {
    /// Adds the residuals' squares to `r2`, and (a weighted `ball`) each over its
    /// measurement's variance ([`Ball::weight`] of its value in `ys` and its band's gain) to
    /// `w2`, in filter order.
    fn add_squares(&self, ys: &[f32], gains: &[f32], ball: &Ball, (r2, w2): (&mut f32, &mut f32)) {
        for (&f, &r) in self.filters.iter().zip(self.res.iter()).take(self.k) {
            *r2 += r * r;
            if ball.is_weighted() {
                let f = usize::from(f);
                *w2 += r * r * ball.weight(ys.get(f).copied().unwrap_or(0.0), gains.get(f).copied().unwrap_or(1.0));
            }
        }
    }
}

/// The minimum-norm start in signal space: each pixel `R_F^T (R_F R_F^T)^-1 y`, zero where
/// nothing is measured.
pub fn min_norm<S: Shape>(model: &BandModel<S::Bands>, m: &Measurements<S::Values>, signal: &mut PerValue<S, f32>) {
    let pixels = S::Bands::chunks_mut(signal.as_mut()).iter_mut().zip(S::Bands::chunks(m.values.as_ref()));
    for ((x, ys), measured) in pixels.zip(S::Bands::chunks(m.measured.as_ref())) {
        *x = <PerBand<S, _>>::splat(0.0);
        let mut p = BandModel::<S::Bands>::pixel(&model.r, x, ys.as_ref(), measured.as_ref());
        model.correct(&model.r, x, &mut p, 1.0);
    }
}

/// Every pixel's `B` values unmixed by `response` (balanced): an estimate of `R x` (the
/// band-gain fill, a flat patch's band means) made an estimate of `x`.
pub fn unmix_all<S: Shape>(response: &Response<S::Bands>, signal: &mut PerValue<S, f32>) {
    for x in S::Bands::chunks_mut(signal.as_mut()) {
        response.unmix(x);
    }
}

/// Every pixel's spectrum as its filters see it ([`Response::mix`]): an estimate of `x` (a
/// seed from decoded neighbours) made one of `R x`, for a decode of `R x`.
pub fn mix_all<S: Shape>(response: &Response<S::Bands>, signal: &mut PerValue<S, f32>) {
    for x in S::Bands::chunks_mut(signal.as_mut()) {
        response.mix(x);
    }
}

/// The projection of a patch in signal space onto its mixed measurements (exactly, or onto
/// the noise [`Ball`]): per pixel `x += scale R_F^T (R_F R_F^T)^-1 (y - R_F x)`. Returns
/// the residual norm before the move. The put-back after a solve and before a seeded one.
pub fn project_signal<S: Shape>(
    model: &BandModel<S::Bands>,
    x: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
) -> f32 {
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let pixels = || {
        S::Bands::chunks(x.as_ref())
            .iter()
            .zip(S::Bands::chunks(m.values.as_ref()))
            .zip(S::Bands::chunks(m.measured.as_ref()))
    };
    for ((x, ys), measured) in pixels() {
        let p = BandModel::<S::Bands>::pixel(&model.r, x, ys.as_ref(), measured.as_ref());
        p.add_squares(ys.as_ref(), m.gains.as_ref(), ball, (&mut r2, &mut w2));
    }
    let scale = match ball.move_for(r2, w2) {
        Move::Scale(scale) => scale,
        Move::Stay => return libm::sqrtf(r2),
    };
    let pixels = S::Bands::chunks_mut(x.as_mut()).iter_mut().zip(S::Bands::chunks(m.values.as_ref()));
    for ((x, ys), measured) in pixels.zip(S::Bands::chunks(m.measured.as_ref())) {
        let mut p = BandModel::<S::Bands>::pixel(&model.r, x, ys.as_ref(), measured.as_ref());
        model.correct(&model.r, x, &mut p, scale);
    }
    libm::sqrtf(r2)
}

/// [`crate::solver::projection::project_coefficients`] for mixed measurements: moves the
/// coefficients `coeffs` (of `dict`) onto the measurements `m` under `model` (exactly, or
/// onto the noise [`Ball`]); `scratch` is clobbered. Returns the residual norm before the
/// move. The pixel modes' transforms are the fast path's (one frame shared with it); the band
/// step reads each measurement through a row of `R D5` and solves the pixel's `k x k`
/// Gram system.
pub fn project_mixed<S: Shape>(
    dict: &Dictionary<S>,
    model: &BandModel<S::Bands>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
) -> f32 {
    let mut step = |fibres: &mut [PerBand<S, f32>], values: &[f32], measured: &[bool]| {
        let (mut r2, mut w2) = (0.0f32, 0.0f32);
        for ((fibre, ys), measured) in fibres.iter_mut().zip(S::Bands::chunks(values)).zip(S::Bands::chunks(measured)) {
            let mut p = BandModel::<S::Bands>::pixel(&model.rows, fibre, ys.as_ref(), measured.as_ref());
            p.add_squares(ys.as_ref(), m.gains.as_ref(), ball, (&mut r2, &mut w2));
            *fibre = <PerBand<S, _>>::splat(0.0);
            model.correct(&model.rows, fibre, &mut p, 1.0);
        }
        (r2, w2)
    };
    project_slices(dict, coeffs, scratch, m, ball, &mut step)
}
