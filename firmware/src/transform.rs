//! Separable transforms of one patch: synthesis `X = S x1 D1 .. x5 D5` and analysis
//! `S = X x1 D1^T .. x5 D5^T`.
//!
//! These are the whole cost of a solve, so they are written for the compiler to
//! vectorise: a mode product over a mode with `inner` values after it is, for each block of
//! the modes before it, `d` output rows each a sum of `d` scaled input rows of length
//! `inner` (contiguous axpy loops). The last mode (bands, `inner = 1`) is a small
//! matrix product per pixel, written as axpys over rows of the transposed matrix. The
//! five products ping-pong between two caller-owned buffers: no allocation, no set-up.
//! Each transform costs `N * (PS + PT + PU + PV + B)` multiply-adds
//! ([`crate::PatchShape::TRANSFORM_MACS`]).

use crate::dictionary::{Dictionary, Factors, Matrix};
use crate::shape::PatchShape;

/// `dst = src x_mode M` for a mode of size `D` with `inner` values after it (`inner > 1`).
#[inline(always)]
fn mode_rows<const D: usize>(m: &Matrix<D>, src: &[f32], dst: &mut [f32], inner: usize) {
    debug_assert_eq!(src.len(), dst.len());
    debug_assert_eq!(src.len() % (D * inner), 0);
    for (sb, db) in src.chunks_exact(D * inner).zip(dst.chunks_exact_mut(D * inner)) {
        for (row, out) in m.iter().zip(db.chunks_exact_mut(inner)) {
            let mut rows = sb.chunks_exact(inner).zip(row);
            if let Some((x0, &w0)) = rows.next() {
                for (o, &x) in out.iter_mut().zip(x0) {
                    *o = w0 * x;
                }
            }
            for (xs, &w) in rows {
                for (o, &x) in out.iter_mut().zip(xs) {
                    *o += w * x;
                }
            }
        }
    }
}

/// `dst = src x_last M` for the last mode (contiguous, `inner = 1`), given `mt = M^T`.
#[inline(always)]
fn mode_last<const D: usize>(mt: &Matrix<D>, src: &[f32], dst: &mut [f32]) {
    debug_assert_eq!(src.len(), dst.len());
    let (xs, _) = src.as_chunks::<D>();
    let (ys, _) = dst.as_chunks_mut::<D>();
    for (x, y) in xs.iter().zip(ys) {
        // y = sum_c x[c] * M^T[c, :]
        let mut acc = [0.0f32; D];
        for (&xc, mrow) in x.iter().zip(mt) {
            for (a, &m) in acc.iter_mut().zip(mrow) {
                *a += xc * m;
            }
        }
        *y = acc;
    }
}

/// The five mode products `m` (with `mt5 = m.m5^T`) from `a` into `b`; `a` is clobbered.
///
/// Kept out of line: synthesis and analysis share one copy per patch shape, which keeps
/// the device image small (inlined at each call site it tripled `solve` to 79 KB).
#[inline(never)]
fn chain<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    m: &Factors<PS, PT, PU, PV, B>,
    mt5: &Matrix<B>,
    a: &mut [f32; N],
    b: &mut [f32; N],
) {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    mode_rows(&m.m1, a, b, PT * PU * PV * B);
    mode_rows(&m.m2, b, a, PU * PV * B);
    mode_rows(&m.m3, a, b, PV * B);
    mode_rows(&m.m4, b, a, B);
    mode_last(mt5, a, b);
}

/// Synthesis: `signal = coeffs x1 D1 .. x5 D5`. `coeffs` is the scratch and is clobbered.
pub fn synthesize<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>(
    dict: &Dictionary<PS, PT, PU, PV, B>,
    coeffs: &mut [f32; N],
    signal: &mut [f32; N],
) {
    chain(&dict.d, &dict.t.m5, coeffs, signal);
}

/// Analysis: `coeffs = signal x1 D1^T .. x5 D5^T`. `signal` is the scratch and is clobbered.
pub fn analyze<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    dict: &Dictionary<PS, PT, PU, PV, B>,
    signal: &mut [f32; N],
    coeffs: &mut [f32; N],
) {
    chain(&dict.t, &dict.d.m5, signal, coeffs);
}

/// `buf = buf x_mode M` in place, one fibre at a time (for the general projection path).
fn mode_in_place<const D: usize>(m: &Matrix<D>, buf: &mut [f32], inner: usize) {
    for block in buf.chunks_exact_mut(D * inner) {
        for i in 0..inner {
            let mut fibre = [0.0f32; D];
            for (c, f) in fibre.iter_mut().enumerate() {
                *f = block[c * inner + i];
            }
            for (a, row) in m.iter().enumerate() {
                block[a * inner + i] = row.iter().zip(&fibre).map(|(w, x)| w * x).sum();
            }
        }
    }
}

/// `buf = buf x1 M1 .. x5 M5` in place with one fibre of scratch; slower than the
/// ping-pong chain but needs no second buffer. Used by the paper's general path.
pub(crate) fn apply_in_place<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>(
    m: &Factors<PS, PT, PU, PV, B>,
    buf: &mut [f32; N],
) {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    mode_in_place(&m.m1, buf, PT * PU * PV * B);
    mode_in_place(&m.m2, buf, PU * PV * B);
    mode_in_place(&m.m3, buf, PV * B);
    mode_in_place(&m.m4, buf, B);
    mode_in_place(&m.m5, buf, 1);
}
