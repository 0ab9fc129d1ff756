//! The projection of a half-pixel sheared patch, whose measurements interpolate it.
//!
//! In a patch sheared to `d = n + 1/2` ([`crate::operators::disparity`]) a view half a lenslet off
//! the grid measures, at its entry `(s, t, u, v, b)`, the mean of the patch's values at
//! `s` and `s + 1` (and of `t` and `t + 1` for a half column: the mean of four). Call
//! that operator `M`. Its rows are not orthonormal, so SL0's projection
//! `S <- S + D^T M^T (M M^T)^-1 (I - M D S)` needs `(M M^T)^-1`. A measurement only
//! touches values of its own view and band, so `M M^T` is block diagonal with one block
//! per view and band: a dense system of the band's measured grid positions in that view
//! (at most `PS * PT`, a few for one-hot masks). Its entries are products of one factor
//! per axis: 1 on a whole axis at the same position, 1/2 on a half axis at the same
//! position and 1/4 at neighbouring ones, 0 otherwise. Most blocks of a one-hot mask are
//! diagonal (a band's positions in a view are rarely neighbours), a division each; the
//! rest are factored as `L D L^T` on the stack at every step. The blocks depend on the
//! mask only, but keeping their factors would cost RAM a patch does not have.
//!
//! The pixel modes' synthesis and analysis are the fast path's; what differs is that a
//! view's grid spans every spatial slice, so the synthesis of all slices is finished
//! before the band step and the band step goes view by view. Against the fast path this
//! costs one copy of the patch per direction and the band values of every pixel of a
//! view a band is measured in: measured, about 1.5 times the fast path's projection.

use crate::operators::dictionary::Dictionary;
use crate::operators::mode::ModeMatrix;
use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Extent};
use crate::solver::ball::Ball;
use crate::solver::projection::{band_bits, dot, measured_weight, project_whole};
use crate::solver::workspace::Measurements;

/// The largest view grid (`PS * PT`) a half-pixel patch may have: one band's system of a
/// view is a dense `PS * PT` square on the stack (2.5 KiB at 25). The tile decoder offers
/// half-pixel disparities only to patches within it.
pub const MAX_GRID: usize = 25;

/// Moves the coefficients `coeffs` (of `dict`) onto the interpolating measurements `m`
/// (exactly, or onto the noise [`Ball`]); `scratch` is clobbered. Returns the residual
/// norm before the move. [`crate::solver::projection::project_coefficients`] for patches with
/// half views ([`Measurements::half_views`]). A weighted ball's weights are read from
/// `weights` when given ([`crate::solver::projection::weigh`] of the same measurements and
/// ball), else computed (two divisions a measurement): the same sums.
pub fn project_fractional<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
    weights: Option<&PerValue<S, f32>>,
) -> f32 {
    // The pixel modes' synthesis (the fast path's), every slice back in place: each
    // pixel's band coefficients; then the band step view by view.
    let mut step = |scratch: &mut PerValue<S, f32>| {
        let (mut r2, mut w2) = (0.0f32, 0.0f32);
        for u in 0..S::PU {
            for v in 0..S::PV {
                let (r, w) = view_step::<S>(&dict.d.m5, scratch, m, (ball, weights), (u, v));
                (r2, w2) = (r2 + r, w2 + w);
            }
        }
        (r2, w2)
    };
    project_whole(dict, coeffs, scratch, ball, &mut step)
}

/// The band step of view `(u, v)`: its pixels' band coefficients in `fibres` become the
/// correction's `M^T (M M^T)^-1 r`, band by measured band. Returns the sums of squared
/// residuals, plain and (weighted balls) over their variances.
///
/// One pass over the view's grid positions sums each measurement's two to four pixels
/// (a model value is `D5`'s band row against that sum, one dot product however many pixels
/// it interpolates) and files its residual under its band. Each band's block is solved,
/// then the view's pixels are rebuilt from the corrections alone: a measurement adds its
/// `weight * z` times its band's row of `D5` to the pixels it read, about 1,000
/// multiply-adds a view each way at one measurement per pixel.
#[inline(never)]
fn view_step<S: Shape>(
    m5: &ModeMatrix<S::Bands>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    (ball, weights): (&Ball, Option<&PerValue<S, f32>>),
    (u, v): (usize, usize),
) -> (f32, f32) {
    let (hs, ht) = (usize::from(m.half.row(u)), usize::from(m.half.col(v)));
    let fibres = S::Bands::chunks_mut(scratch.as_mut());
    let pixel = |s: usize, t: usize| ((s * S::PT + t) * S::PU + u) * S::PV + v;
    // The diagonal of M M^T: a measurement's own overlap.
    let weight = overlap(hs, 0) * overlap(ht, 0);
    // Per band: its measured grid positions (`s * PT + t`) and their residuals.
    let mut count = <PerBand<S, usize>>::splat(0);
    let mut at = <PerBand<S, [u8; MAX_GRID]>>::splat([0; MAX_GRID]);
    let mut r = <PerBand<S, [f32; MAX_GRID]>>::splat([0.0; MAX_GRID]);
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let weighted = ball.is_weighted();
    for s in 0..S::PS - hs {
        for t in 0..S::PT - ht {
            let base = pixel(s, t) * S::B;
            let (Some(flags), Some(ys)) = (m.measured.get(base..base + S::B), m.values.get(base..base + S::B)) else {
                continue;
            };
            let mut bits = band_bits(flags);
            if bits == 0 {
                continue;
            }
            // The values this position's measurements interpolate, summed.
            let mut sum = <PerBand<S, f32>>::splat(0.0);
            for a in 0..=hs {
                for c in 0..=ht {
                    if let Some(f) = fibres.get(pixel(s + a, t + c)) {
                        for (o, &x) in sum.iter_mut().zip(f.iter()) {
                            *o += x;
                        }
                    }
                }
            }
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (Some(row), Some(&y), Some(n)) = (m5.get(b), ys.get(b), count.get_mut(b)) else { continue };
                let res = y - weight * dot(row.as_ref(), sum.as_ref());
                r2 += res * res;
                if weighted {
                    w2 += res * res * measured_weight::<S>(weights, base + b, ball, y, m.gains.get(b));
                }
                let (Some(p), Some(q), Ok(pos)) = (
                    at.get_mut(b).and_then(|x| x.get_mut(*n)),
                    r.get_mut(b).and_then(|x| x.get_mut(*n)),
                    u8::try_from(s * S::PT + t),
                ) else {
                    continue;
                };
                (*p, *q) = (pos, res);
                *n += 1;
            }
        }
    }
    // The view's pixels become the correction, built from each band's solved block.
    for s in 0..S::PS {
        for t in 0..S::PT {
            if let Some(f) = fibres.get_mut(pixel(s, t)) {
                *f = <PerBand<S, f32>>::splat(0.0);
            }
        }
    }
    for (b, ((&n, at), r)) in count.iter().zip(at.iter()).zip(r.iter_mut()).enumerate() {
        let (Some(at), Some(row)) = (at.get(..n), m5.get(b)) else { continue };
        solve_block(at, r, (hs, ht), S::PT);
        for (&p, &z) in at.iter().zip(r.iter()) {
            let (s, t) = grid_position(p, S::PT);
            let z = weight * z;
            for a in 0..=hs {
                for c in 0..=ht {
                    if let Some(f) = fibres.get_mut(pixel(s + a, t + c)) {
                        for (o, &w) in f.iter_mut().zip(row.iter()) {
                            *o += z * w;
                        }
                    }
                }
            }
        }
    }
    (r2, w2)
}

/// Blocks of up to this many measurements are solved in an `8 x 8` factor, so the common
/// small ones do not clear the `MAX_GRID` square's 2.5 KiB each time.
const SMALL_BLOCK: usize = 8;

/// The overlap of two measurements along one axis `delta` grid positions apart: a whole
/// axis reads one value (1 if the same), a half axis the mean of two (1/2 if the same,
/// 1/4 if neighbours).
#[inline(always)]
fn overlap(half: usize, delta: usize) -> f32 {
    match (half, delta) {
        (0, 0) => 1.0,
        (_, 0) => 0.5,
        (1, 1) => 0.25,
        _ => 0.0,
    }
}

/// A grid position `s * pt + t` as `(s, t)`. Checked division (`pt` is the patch's lenslet
/// columns, never 0): where a build does not inline the constant, `/` would link a
/// division-by-zero panic into the decoder (the release profile's thin LTO did).
#[inline(always)]
fn grid_position(p: u8, pt: usize) -> (usize, usize) {
    let p = usize::from(p);
    (p.checked_div(pt).unwrap_or(0), p.checked_rem(pt).unwrap_or(0))
}

/// Solves `G z = r` in place for one view and band's measurements at grid positions `at`
/// (`s * pt + t`; `G = M M^T`, [`overlap`] per axis). Measurements that share no value
/// leave `G` diagonal, a division each: always on a whole view, and in most blocks of a
/// one-hot mask, whose band's positions are rarely neighbours. Otherwise by [`cholesky`].
fn solve_block(at: &[u8], r: &mut [f32; MAX_GRID], (hs, ht): (usize, usize), pt: usize) {
    let position = |i: usize| grid_position(at.get(i).copied().unwrap_or(0), pt);
    let shares = |i: usize, j: usize| {
        let ((si, ti), (sj, tj)) = (position(i), position(j));
        si.abs_diff(sj) <= hs && ti.abs_diff(tj) <= ht
    };
    let n = at.len().min(MAX_GRID);
    if (1..n).all(|i| (0..i).all(|j| !shares(i, j))) {
        let weight = overlap(hs, 0) * overlap(ht, 0);
        for x in r.iter_mut().take(n) {
            *x /= weight;
        }
    } else if n <= SMALL_BLOCK {
        cholesky::<SMALL_BLOCK>(at, r, (hs, ht), pt);
    } else {
        cholesky::<MAX_GRID>(at, r, (hs, ht), pt);
    }
}

/// [`solve_block`] by an `L D L^T` factorisation (Cholesky without square roots: one
/// division per pivot, where the square roots' latency took a third of the band step) in
/// an `L x L` square on the stack. A pivot that is not positive (it cannot be for distinct
/// positions; rounding could only make one tiny) zeroes its unknown instead of dividing by
/// it.
#[allow(clippy::needless_range_loop)] // the factorisation reads best with its indices
fn cholesky<const L: usize>(at: &[u8], r: &mut [f32; MAX_GRID], (hs, ht): (usize, usize), pt: usize) {
    let n = at.len().min(L).min(MAX_GRID);
    // Lower triangle of G, overwritten by the unit lower factor L; D and 1 / D apart.
    let mut l = [[0.0f32; L]; L];
    let (mut d, mut inv) = ([0.0f32; L], [0.0f32; L]);
    for (i, &pi) in at.iter().enumerate().take(n) {
        let (si, ti) = grid_position(pi, pt);
        for (j, &pj) in at.iter().enumerate().take(i + 1) {
            let (sj, tj) = grid_position(pj, pt);
            l[i][j] = overlap(hs, si.abs_diff(sj)) * overlap(ht, ti.abs_diff(tj));
        }
    }
    for j in 0..n {
        let mut pivot = l[j][j];
        for k in 0..j {
            pivot -= l[j][k] * l[j][k] * d[k];
        }
        if pivot > f32::MIN_POSITIVE {
            (d[j], inv[j]) = (pivot, 1.0 / pivot);
        }
        for i in j + 1..n {
            let mut x = l[i][j];
            for k in 0..j {
                x -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = x * inv[j];
        }
    }
    // L y = r, then D L^T z = y.
    for i in 0..n {
        let mut x = r[i];
        for k in 0..i {
            x -= l[i][k] * r[k];
        }
        r[i] = x;
    }
    for i in (0..n).rev() {
        let mut x = r[i] * inv[i];
        for k in i + 1..n {
            x -= l[k][i] * r[k];
        }
        r[i] = if inv[i] > 0.0 { x } else { 0.0 };
    }
}

/// A decoded half-pixel patch at the sensor pixels its grid positions name: along every
/// half axis, position `s` becomes the mean of `s` and `s + 1`, the value the pixel it
/// read measured (the last position keeps its value; it names no pixel). In place.
pub fn to_sensor<S: Shape>(half: crate::operators::disparity::HalfViews, patch: &mut PerValue<S, f32>) {
    each_half_line::<S>(half, |line| {
        for i in 0..line.len.saturating_sub(1) {
            let next = patch.get(line.at(i + 1)).copied().unwrap_or(0.0);
            if let Some(x) = patch.get_mut(line.at(i)) {
                *x = 0.5 * (*x + next);
            }
        }
    });
}

/// One line of a patch along a half axis: `len` positions, position `i` at `at(i)`.
#[derive(Clone, Copy)]
struct Line {
    start: usize,
    stride: usize,
    len: usize,
}

impl Line {
    /// The patch index of position `i` ([`Shape::index`] along the line).
    fn at(self, i: usize) -> usize {
        self.start + i * self.stride
    }
}

/// Every line of the patch along a half axis, in one order for [`to_sensor`] and
/// [`from_sensor`]: for each view `(u, v)` and band, the lines along `s` (one for each `t`)
/// where the view's rows are half, then those along `t` where its columns are.
fn each_half_line<S: Shape>(half: crate::operators::disparity::HalfViews, mut f: impl FnMut(Line)) {
    for u in 0..S::PU {
        for v in 0..S::PV {
            let (hs, ht) = (half.row(u), half.col(v));
            for b in 0..S::B {
                if hs {
                    for t in 0..S::PT {
                        f(Line { start: S::index(0, t, u, v, b), stride: S::index(1, 0, 0, 0, 0), len: S::PS });
                    }
                }
                if ht {
                    for s in 0..S::PS {
                        f(Line { start: S::index(s, 0, u, v, b), stride: S::index(0, 1, 0, 0, 0), len: S::PT });
                    }
                }
            }
        }
    }
}

/// The reverse of [`to_sensor`], for a start: a half-pixel patch estimated from the sensor
/// pixels its grid positions name (`patch` in [`to_sensor`]'s layout; the last position of
/// a half axis names no pixel and is not read). Along every half axis, position `s`
/// between pixels `s - 1` and `s` becomes their mean, and the end positions their one
/// neighbour: linear interpolation, exact for a patch linear along the axis. In place.
pub fn from_sensor<S: Shape>(half: crate::operators::disparity::HalfViews, patch: &mut PerValue<S, f32>) {
    each_half_line::<S>(half, |line| back_along::<S>(patch, line.len, |i| line.at(i)));
}

/// [`from_sensor`] along one half axis of `len` positions, position `i` at `at(i)`: from
/// the far end, each position the mean of its two pixels before they change, the last
/// position its one neighbour's (the first keeps its pixel).
#[inline(always)]
fn back_along<S: Shape>(patch: &mut PerValue<S, f32>, len: usize, at: impl Fn(usize) -> usize) {
    if len < 2 {
        return;
    }
    let get = |p: &PerValue<S, f32>, i: usize| p.get(at(i)).copied().unwrap_or(0.0);
    let last = get(patch, len - 2);
    for i in (1..len - 1).rev() {
        let x = 0.5 * (get(patch, i - 1) + get(patch, i));
        if let Some(y) = patch.get_mut(at(i)) {
            *y = x;
        }
    }
    if let Some(y) = patch.get_mut(at(len - 1)) {
        *y = last;
    }
}
