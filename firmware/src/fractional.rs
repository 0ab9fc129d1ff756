//! The projection of a half-pixel sheared patch, whose measurements interpolate it.
//!
//! In a patch sheared to `d = n + 1/2` ([`crate::disparity`]) a view half a lenslet off
//! the grid measures, at its entry `(s, t, u, v, b)`, the mean of the patch's values at
//! `s` and `s + 1` (and of `t` and `t + 1` for a half column: the mean of four). Call
//! that operator `M`. Its rows are not orthonormal, so SL0's projection
//! `S <- S + D^T M^T (M M^T)^-1 (I - M D S)` needs `(M M^T)^-1`. A measurement only
//! touches values of its own view and band, so `M M^T` is block diagonal with one block
//! per view and band: a dense system of the band's measured grid positions in that view
//! (at most `PS * PT`, a few for one-hot masks). Its entries are products of one factor
//! per axis: 1 on a whole axis at the same position, 1/2 on a half axis at the same
//! position and 1/4 at neighbouring ones, 0 otherwise. Each step solves every block by
//! Cholesky on the stack; the blocks depend on the mask only, but keeping their factors
//! would cost RAM a patch does not have.
//!
//! The pixel modes' synthesis and analysis are the fast path's; what differs is that a
//! view's grid spans every spatial slice, so the synthesis of all slices is finished
//! before the band step and the band step goes view by view. Against the fast path this
//! costs one copy of the patch per direction and the band values of every pixel of a
//! view a band is measured in: measured, about 1.5 times the fast path's projection.

use crate::ball::Ball;
use crate::dictionary::Dictionary;
use crate::projection::{apply_move, band_bits, dot, slice_analysis, slice_synthesis};
use crate::shape::PatchShape;
use crate::transform::{Slice, flat, mode_rows, slice};
use crate::workspace::Measurements;

/// The largest view grid (`PS * PT`) a half-pixel patch may have: one band's system of a
/// view is a dense `PS * PT` square on the stack (2.5 KiB at 25). The tile decoder offers
/// half-pixel disparities only to patches within it.
pub const MAX_GRID: usize = 25;

/// Moves the coefficients `coeffs` (of `dict`) onto the interpolating measurements `m`
/// (exactly, or onto the noise [`Ball`]); `scratch` is clobbered. Returns the residual
/// norm before the move. [`crate::projection::project_coefficients`] for patches with
/// half views ([`Measurements::half_views`]).
pub fn project_fractional<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>(
    dict: &Dictionary<PS, PT, PU, PV, B>,
    coeffs: &mut [f32; N],
    scratch: &mut [f32; N],
    m: &Measurements<N>,
    ball: &Ball,
) -> f32 {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    let part_len = PT * PU * PV * B;
    // The pixel modes' synthesis (the fast path's), every slice back in place: each
    // pixel's band coefficients.
    mode_rows(&dict.d.m1, dict.synthesis_folds()[0], coeffs, scratch, part_len);
    let mut tmp: Slice<PT, PU, PV, B> = slice();
    for part in scratch.chunks_exact_mut(part_len) {
        let tmp = flat(&mut tmp);
        slice_synthesis(dict, part, tmp);
        part.copy_from_slice(tmp);
    }
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    for u in 0..PU {
        for v in 0..PV {
            let (r, w) = view_step::<PS, PT, PU, PV, B, N>(&dict.d.m5, scratch, m, ball, (u, v));
            (r2, w2) = (r2 + r, w2 + w);
        }
    }
    for part in scratch.chunks_exact_mut(part_len) {
        let tmp = flat(&mut tmp);
        tmp.copy_from_slice(part);
        slice_analysis(dict, tmp, part);
    }
    apply_move(dict, ball, (r2, w2), scratch, coeffs)
}

/// The band step of view `(u, v)`: its pixels' band coefficients in `fibres` become the
/// correction's `M^T (M M^T)^-1 r`, band by measured band. Returns the sums of squared
/// residuals, plain and (weighted balls) over their variances.
///
/// A measurement's model value is the dot products of its two to four pixels with the
/// band's row of `D5`, and a pixel's correction goes back through the rows of the bands it
/// was corrected in only: with one measurement per pixel that is about 1,000 multiply-adds
/// a view each way, where every pixel's every measured band took 4,000.
#[inline(never)]
fn view_step<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    m5: &[[f32; B]; B],
    scratch: &mut [f32; N],
    m: &Measurements<N>,
    ball: &Ball,
    (u, v): (usize, usize),
) -> (f32, f32) {
    let (hs, ht) = (usize::from(m.half.row(u)), usize::from(m.half.col(v)));
    let fibres = scratch.as_chunks_mut::<B>().0;
    let pixel = |s: usize, t: usize| ((s * PT + t) * PU + u) * PV + v;
    // The bands measured anywhere in the view.
    let mut bands = 0u64;
    for s in 0..PS {
        for t in 0..PT {
            let at = pixel(s, t) * B;
            if let Some(flags) = m.measured.get(at..at + B) {
                bands |= band_bits(flags);
            }
        }
    }
    let mut correction = [[0.0f32; B]; MAX_GRID];
    let mut touched = [0u64; MAX_GRID];
    let weight = if hs + ht == 0 {
        1.0
    } else if hs + ht == 1 {
        0.5
    } else {
        0.25
    };
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let mut bits = bands;
    while bits != 0 {
        let b = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let Some(row) = m5.get(b) else { continue };
        // The band's measured grid positions and their residuals.
        let mut at = [(0usize, 0usize); MAX_GRID];
        let mut r = [0.0f32; MAX_GRID];
        let mut n = 0usize;
        for s in 0..PS - hs {
            for t in 0..PT - ht {
                let i = pixel(s, t) * B + b;
                let (Some(true), Some(&y)) = (m.measured.get(i).copied(), m.values.get(i)) else { continue };
                let mut model = 0.0f32;
                for a in 0..=hs {
                    for c in 0..=ht {
                        if let Some(f) = fibres.get(pixel(s + a, t + c)) {
                            model += dot(row, f);
                        }
                    }
                }
                let res = y - weight * model;
                r2 += res * res;
                if ball.is_weighted() {
                    w2 += res * res * ball.weight(y, m.gains.get(b).copied().unwrap_or(1.0));
                }
                if let (Some(p), Some(q)) = (at.get_mut(n), r.get_mut(n)) {
                    (*p, *q) = ((s, t), res);
                    n += 1;
                }
            }
        }
        let at = at.get(..n).unwrap_or(&[]);
        if n <= SMALL_BLOCK {
            solve_block::<SMALL_BLOCK>(at, &mut r, (hs, ht));
        } else {
            solve_block::<MAX_GRID>(at, &mut r, (hs, ht));
        }
        for (&(s, t), &z) in at.iter().zip(&r) {
            for a in 0..=hs {
                for c in 0..=ht {
                    let p = (s + a) * PT + t + c;
                    if let (Some(o), Some(k)) = (correction.get_mut(p).and_then(|x| x.get_mut(b)), touched.get_mut(p)) {
                        *o += weight * z;
                        *k |= 1 << b;
                    }
                }
            }
        }
    }
    // Back to band coefficients: each pixel's correction in the bands it was corrected in.
    for s in 0..PS {
        for t in 0..PT {
            let p = s * PT + t;
            let (Some(f), Some(c), Some(&k)) = (fibres.get_mut(pixel(s, t)), correction.get(p), touched.get(p)) else {
                continue;
            };
            let mut out = [0.0f32; B];
            let mut bits = k;
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (Some(row), Some(&z)) = (m5.get(b), c.get(b)) else { continue };
                for (o, &w) in out.iter_mut().zip(row) {
                    *o += z * w;
                }
            }
            *f = out;
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

/// Solves `G z = r` in place for one view and band's measurements at grid positions `at`
/// (`G = M M^T`, [`overlap`] per axis; at most `L` of them), by Cholesky in an `L x L`
/// square on the stack. A pivot that is not
/// positive (it cannot be for distinct positions; rounding could only make one tiny)
/// zeroes its unknown instead of dividing by it.
#[allow(clippy::needless_range_loop)] // Cholesky reads best with its indices
fn solve_block<const L: usize>(at: &[(usize, usize)], r: &mut [f32; MAX_GRID], (hs, ht): (usize, usize)) {
    let n = at.len().min(L).min(MAX_GRID);
    if n == 1 {
        r[0] /= overlap(hs, 0) * overlap(ht, 0);
        return;
    }
    // Lower triangle of G, overwritten by its Cholesky factor L.
    let mut l = [[0.0f32; L]; L];
    for (i, &(si, ti)) in at.iter().enumerate().take(n) {
        for (j, &(sj, tj)) in at.iter().enumerate().take(i + 1) {
            l[i][j] = overlap(hs, si.abs_diff(sj)) * overlap(ht, ti.abs_diff(tj));
        }
    }
    for j in 0..n {
        let mut d = l[j][j];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        let pivot = if d > f32::MIN_POSITIVE { libm::sqrtf(d) } else { 0.0 };
        l[j][j] = pivot;
        for i in j + 1..n {
            let mut x = l[i][j];
            for k in 0..j {
                x -= l[i][k] * l[j][k];
            }
            l[i][j] = if pivot > 0.0 { x / pivot } else { 0.0 };
        }
    }
    // L y = r, then L^T z = y.
    for i in 0..n {
        let mut x = r[i];
        for k in 0..i {
            x -= l[i][k] * r[k];
        }
        r[i] = if l[i][i] > 0.0 { x / l[i][i] } else { 0.0 };
    }
    for i in (0..n).rev() {
        let mut x = r[i];
        for k in i + 1..n {
            x -= l[k][i] * r[k];
        }
        r[i] = if l[i][i] > 0.0 { x / l[i][i] } else { 0.0 };
    }
}

/// A decoded half-pixel patch at the sensor pixels its grid positions name: along every
/// half axis, position `s` becomes the mean of `s` and `s + 1`, the value the pixel it
/// read measured (the last position keeps its value; it names no pixel). In place.
pub fn to_sensor<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    half: crate::disparity::HalfViews,
    patch: &mut [f32; N],
) {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    let index = PatchShape::<PS, PT, PU, PV, B, N>::index;
    for u in 0..PU {
        for v in 0..PV {
            let (hs, ht) = (half.row(u), half.col(v));
            for b in 0..B {
                if hs {
                    for t in 0..PT {
                        for s in 0..PS - 1 {
                            let next = patch.get(index(s + 1, t, u, v, b)).copied().unwrap_or(0.0);
                            if let Some(x) = patch.get_mut(index(s, t, u, v, b)) {
                                *x = 0.5 * (*x + next);
                            }
                        }
                    }
                }
                if ht {
                    for s in 0..PS {
                        for t in 0..PT - 1 {
                            let next = patch.get(index(s, t + 1, u, v, b)).copied().unwrap_or(0.0);
                            if let Some(x) = patch.get_mut(index(s, t, u, v, b)) {
                                *x = 0.5 * (*x + next);
                            }
                        }
                    }
                }
            }
        }
    }
}
