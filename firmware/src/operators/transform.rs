//! Separable transforms of one patch: synthesis `X = S x1 D1 .. x5 D5` and analysis
//! `S = X x1 D1^T .. x5 D5^T`, and the mode products the solver's projection is built of.
//!
//! These are most of the cost of a solve, so they are written for the compiler to
//! vectorise. A mode product over a mode with `inner` values after it is, for each block of
//! the modes before it, `d` output rows each a sum of `d` scaled input rows of length
//! `inner`; `block_rows` keeps all `d` output rows in registers eight columns at a time,
//! so each input vector is loaded once and each output stored once (as plain axpys over
//! whole rows, every multiply-add also loaded and stored its output: 6.1 us a transform
//! against 4.5 us). Where a mode's matrix is the DCT's (rows even or odd about their
//! middle, found when the dictionary is built) the product folds mirrored rows first and
//! does about half the multiplies (`Fold`: 3.9-4.0 us a DCT transform, and a quarter fewer
//! instructions on a Cortex-M4). The mode before the bands (`inner = B`) sums whole rows of
//! `B` in registers (`mode_pixel`); the last mode (bands, `inner = 1`) is a small matrix
//! product per pixel. The five products ping-pong between two caller-owned buffers: no
//! allocation, no set-up. Host and device run the same sums in the same order, so both
//! give the same bits. Each transform costs `N * (PS + PT + PU + PV + B)` multiply-adds
//! without folding ([`crate::PatchShape::TRANSFORM_MACS`]).

use crate::operators::dictionary::{Dictionary, Factors, Fold, Matrix};
use crate::operators::shape::PatchShape;

/// Columns of one register block: one AVX2 register of f32 on the host. A Cortex-M has 32
/// single registers and no vectors: eight columns of a 5-row block (40 inputs, their
/// folds and the sums) spill, and four took 12.5 % fewer instructions a screened patch
/// than eight and 2 % fewer than two (`scripts/budgets.sh`; the same sums in the same
/// order, so the same bits as the host), and 39 KB less flash.
#[cfg(not(target_arch = "arm"))]
const LANES: usize = 8;
#[cfg(target_arch = "arm")]
const LANES: usize = 4;

const PLAIN: u8 = 0;
const ROWS: u8 = 1;
const COLUMNS: u8 = 2;

/// The mode product of one block of `D` rows of `inner` values, `LANES` columns at a time
/// with all `D` output rows in registers: each input vector is loaded once for its `D`
/// multiply-adds and each output vector stored once (written as `D` axpys over whole rows,
/// every multiply-add also loaded and stored its output). `dst = src x M`, or with `ADD`
/// `dst += scale * (src x M)` (`w` holds the scaled matrix).
#[inline(always)]
fn block_rows<const D: usize, const ADD: bool, const FOLD: u8>(
    w: &Matrix<D>,
    sb: &[f32],
    db: &mut [f32],
    inner: usize,
) {
    let full = inner / LANES * LANES;
    block_columns::<D, ADD, FOLD, LANES>(w, sb, db, inner, 0, full);
    // The rest of a row (e.g. 4 of `inner = 52`) a half register, then one at a time.
    let half = full + (inner - full) / (LANES / 2) * (LANES / 2);
    block_columns::<D, ADD, FOLD, { LANES / 2 }>(w, sb, db, inner, full, half);
    block_columns::<D, ADD, FOLD, 1>(w, sb, db, inner, half, inner);
}

/// `out = (ADD ? out : 0) + x`, for `L` lanes at `db[at..]`.
///
/// The callers keep `at + L` within `db`; the `get` states it so the compiler needs no
/// panic path (a miss, which cannot happen, would skip the store).
#[inline(always)]
fn put<const ADD: bool, const L: usize>(db: &mut [f32], at: usize, x: &[f32; L]) {
    debug_assert!(at + L <= db.len());
    let Some(out) = db.get_mut(at..).and_then(|d| d.first_chunk_mut::<L>()) else {
        return;
    };
    if ADD {
        for (o, &x) in out.iter_mut().zip(x) {
            *o += x;
        }
    } else {
        out.copy_from_slice(x);
    }
}

/// [`block_rows`] on columns `from..to` of the block, `L` at a time (`to - from` a
/// multiple of `L`).
#[inline(always)]
fn block_columns<const D: usize, const ADD: bool, const FOLD: u8, const L: usize>(
    w: &Matrix<D>,
    sb: &[f32],
    db: &mut [f32],
    inner: usize,
    from: usize,
    to: usize,
) {
    let half = D / 2;
    for i in (from..to).step_by(L) {
        let mut x = [[0.0f32; L]; D];
        for (c, x) in x.iter_mut().enumerate() {
            debug_assert!(c * inner + i + L <= sb.len());
            if let Some(src) = sb.get(c * inner + i..).and_then(|s| s.first_chunk::<L>()) {
                *x = *src;
            }
        }
        match FOLD {
            ROWS => {
                // Even rows see the sums of mirrored inputs (and the middle one), odd rows
                // their differences.
                let (mut even, mut odd) = ([[0.0f32; L]; D], [[0.0f32; L]; D]);
                for h in 0..half {
                    for l in 0..L {
                        even[h][l] = x[h][l] + x[D - 1 - h][l];
                        odd[h][l] = x[h][l] - x[D - 1 - h][l];
                    }
                }
                if D % 2 == 1 {
                    even[half] = x[half];
                }
                for (a, weights) in w.iter().enumerate() {
                    let (terms, n) = if a % 2 == 0 { (&even, D - half) } else { (&odd, half) };
                    let mut acc = [0.0f32; L];
                    for (t, &wc) in terms.iter().zip(weights).take(n) {
                        for (o, &t) in acc.iter_mut().zip(t) {
                            *o += wc * t;
                        }
                    }
                    put::<ADD, L>(db, a * inner + i, &acc);
                }
            }
            COLUMNS => {
                // Output n and its mirror share the sums over even and odd inputs.
                for (n, weights) in w.iter().enumerate().take(D - half) {
                    let (mut ev, mut o) = ([0.0f32; L], [0.0f32; L]);
                    for k in (0..D).step_by(2) {
                        for (a, &x) in ev.iter_mut().zip(&x[k]) {
                            *a += weights[k] * x;
                        }
                    }
                    if n < half {
                        for k in (1..D).step_by(2) {
                            for (a, &x) in o.iter_mut().zip(&x[k]) {
                                *a += weights[k] * x;
                            }
                        }
                        let (sum, diff): ([f32; L], [f32; L]) =
                            (core::array::from_fn(|l| ev[l] + o[l]), core::array::from_fn(|l| ev[l] - o[l]));
                        put::<ADD, L>(db, n * inner + i, &sum);
                        put::<ADD, L>(db, (D - 1 - n) * inner + i, &diff);
                    } else {
                        put::<ADD, L>(db, n * inner + i, &ev); // the middle output of an odd D
                    }
                }
            }
            _ => {
                let mut acc = [[0.0f32; L]; D];
                for (c, x) in x.iter().enumerate() {
                    for (acc, weights) in acc.iter_mut().zip(w) {
                        let wc = weights[c];
                        for (o, &x) in acc.iter_mut().zip(x) {
                            *o += wc * x;
                        }
                    }
                }
                for (a, acc) in acc.iter().enumerate() {
                    put::<ADD, L>(db, a * inner + i, acc);
                }
            }
        }
    }
}

/// `dst = src x_mode M` for a mode of size `D` with `inner` values after it (`inner > 1`).
#[inline(always)]
pub(crate) fn mode_rows<const D: usize>(m: &Matrix<D>, fold: Fold, src: &[f32], dst: &mut [f32], inner: usize) {
    mode_product::<D, false>(m, fold, src, dst, inner);
}

/// [`mode_rows`], or with `ADD` `dst += src x_mode w`.
#[inline(always)]
fn mode_product<const D: usize, const ADD: bool>(
    w: &Matrix<D>,
    fold: Fold,
    src: &[f32],
    dst: &mut [f32],
    inner: usize,
) {
    debug_assert_eq!(src.len(), dst.len());
    debug_assert_eq!(src.len() % (D * inner), 0);
    // Plain `for` loops, not `for_each`: `Zip::fold` is not always inlined, and inside it
    // `inner` is no longer the constant it is at the call site (the bounds then need
    // checks at run time).
    let blocks = src.chunks_exact(D * inner).zip(dst.chunks_exact_mut(D * inner));
    match fold {
        Fold::Plain => {
            for (sb, db) in blocks {
                block_rows::<D, ADD, PLAIN>(w, sb, db, inner);
            }
        }
        Fold::Rows => {
            for (sb, db) in blocks {
                block_rows::<D, ADD, ROWS>(w, sb, db, inner);
            }
        }
        Fold::Columns => {
            for (sb, db) in blocks {
                block_rows::<D, ADD, COLUMNS>(w, sb, db, inner);
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
    f: [Fold; 4],
    a: &mut [f32; N],
    b: &mut [f32; N],
) {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    mode_rows(&m.m1, f[0], a, b, PT * PU * PV * B);
    mode_rows(&m.m2, f[1], b, a, PU * PV * B);
    mode_rows(&m.m3, f[2], a, b, PV * B);
    mode_pixel(&m.m4, f[3], b.as_chunks::<B>().0, a.as_chunks_mut::<B>().0);
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
    chain(&dict.d, &dict.t.m5, dict.synthesis_folds(), coeffs, signal);
}

/// Analysis: `coeffs = signal x1 D1^T .. x5 D5^T`. `signal` is the scratch and is clobbered.
pub fn analyze<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    dict: &Dictionary<PS, PT, PU, PV, B>,
    signal: &mut [f32; N],
    coeffs: &mut [f32; N],
) {
    chain(&dict.t, &dict.d.m5, dict.analysis_folds(), signal, coeffs);
}

/// Columns the in-place mode product copies to the stack at a time.
const STRIP: usize = 64;

/// `buf = buf x_mode M` in place for a mode of size `D` with `inner` values after it
/// (`inner > 1`). Each block's `D` rows are copied a strip of at most [`STRIP`] columns at
/// a time to a `D x STRIP` stack array (3.3 KiB for `D = 13`), then written back as
/// the unfolded [`mode_rows`] writes them: the same sums in the same order, contiguous axpys the
/// compiler vectorises. No second patch buffer.
#[inline(always)]
fn mode_rows_in_place<const D: usize>(m: &Matrix<D>, buf: &mut [f32], inner: usize) {
    debug_assert_eq!(buf.len() % (D * inner), 0);
    let mut strip = [[0.0f32; STRIP]; D];
    for block in buf.chunks_exact_mut(D * inner) {
        for i0 in (0..inner).step_by(STRIP) {
            let w = STRIP.min(inner - i0);
            for (s, row) in strip.iter_mut().zip(block.chunks_exact(inner)) {
                s[..w].copy_from_slice(&row[i0..i0 + w]);
            }
            for (weights, row) in m.iter().zip(block.chunks_exact_mut(inner)) {
                let out = &mut row[i0..i0 + w];
                let mut terms = strip.iter().zip(weights);
                if let Some((x0, &w0)) = terms.next() {
                    for (o, &x) in out.iter_mut().zip(&x0[..w]) {
                        *o = w0 * x;
                    }
                }
                for (xs, &wc) in terms {
                    for (o, &x) in out.iter_mut().zip(&xs[..w]) {
                        *o += wc * x;
                    }
                }
            }
        }
    }
}

/// `dst += scale * (src x_mode M)` for a mode of size `D` with `inner` values after it.
#[inline(always)]
pub(crate) fn mode_rows_add<const D: usize>(
    m: &Matrix<D>,
    fold: Fold,
    scale: f32,
    src: &[f32],
    dst: &mut [f32],
    inner: usize,
) {
    let w: Matrix<D> = core::array::from_fn(|a| core::array::from_fn(|c| scale * m[a][c]));
    mode_product::<D, true>(&w, fold, src, dst, inner);
}

/// `dst = src x_mode M` for the mode just before the band axis (`inner = B`): each block's
/// output rows of `B` values are summed in registers and stored once. (As [`mode_rows`]
/// with `inner = 13` the sums went through memory in overlapping 8 + 4 + 1 lane pieces, and
/// the stores stalled the loads after them.)
#[inline(always)]
pub(crate) fn mode_pixel<const D: usize, const B: usize>(
    m: &Matrix<D>,
    fold: Fold,
    src: &[[f32; B]],
    dst: &mut [[f32; B]],
) {
    debug_assert_eq!(src.len(), dst.len());
    let blocks = src.as_flattened().chunks_exact(D * B).zip(dst.as_flattened_mut().chunks_exact_mut(D * B));
    match fold {
        Fold::Plain => blocks.for_each(|(sb, db)| block_columns::<D, false, PLAIN, B>(m, sb, db, B, 0, B)),
        Fold::Rows => blocks.for_each(|(sb, db)| block_columns::<D, false, ROWS, B>(m, sb, db, B, 0, B)),
        Fold::Columns => blocks.for_each(|(sb, db)| block_columns::<D, false, COLUMNS, B>(m, sb, db, B, 0, B)),
    }
}

/// One spatial slice of a patch (all of its values with the first index fixed): the
/// stack scratch of the slice-wise transforms, `N / PS` values (4,160 bytes for the
/// paper's patch).
pub(crate) type Slice<const PT: usize, const PU: usize, const PV: usize, const B: usize> = [[[[f32; B]; PV]; PU]; PT];

/// A zeroed [`Slice`].
pub(crate) const fn slice<const PT: usize, const PU: usize, const PV: usize, const B: usize>() -> Slice<PT, PU, PV, B> {
    [[[[0.0; B]; PV]; PU]; PT]
}

/// A [`Slice`] as its values in patch order.
pub(crate) fn flat<const PT: usize, const PU: usize, const PV: usize, const B: usize>(
    s: &mut Slice<PT, PU, PV, B>,
) -> &mut [f32] {
    s.as_flattened_mut().as_flattened_mut().as_flattened_mut()
}

/// `dst = src x1 M1 .. x5 M5` (with `mt5 = M5^T`) with `src` only read: the first mode
/// goes from `src` to `dst`, the other four work one spatial slice at a time between
/// `dst` and a [`Slice`] on the stack. Scores a solution in a member without a copy.
#[inline(never)]
fn apply_preserving<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>(
    m: &Factors<PS, PT, PU, PV, B>,
    mt5: &Matrix<B>,
    f: [Fold; 4],
    src: &[f32; N],
    dst: &mut [f32; N],
) {
    const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
    mode_rows(&m.m1, f[0], src, dst, PT * PU * PV * B);
    let mut scratch = slice::<PT, PU, PV, B>();
    for part in dst.chunks_exact_mut(PT * PU * PV * B) {
        let tmp = flat(&mut scratch);
        mode_rows(&m.m2, f[1], part, tmp, PU * PV * B);
        mode_rows(&m.m3, f[2], tmp, part, PV * B);
        mode_pixel(&m.m4, f[3], part.as_chunks::<B>().0, tmp.as_chunks_mut::<B>().0);
        mode_last(mt5, tmp, part);
    }
}

/// Analysis that keeps its input: `coeffs = signal x1 D1^T .. x5 D5^T`, `signal` only read
/// (a spatial slice of stack scratch instead of a clobbered input; a little slower than
/// [`analyze`]). Scores a solution in each member of an ensemble.
pub fn analyze_preserving<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>(
    dict: &Dictionary<PS, PT, PU, PV, B>,
    signal: &[f32; N],
    coeffs: &mut [f32; N],
) {
    apply_preserving(&dict.t, &dict.d.m5, dict.analysis_folds(), signal, coeffs);
}

/// `buf = buf x5 M` in place for the last (band) mode, one fibre at a time.
fn mode_last_in_place<const D: usize>(m: &Matrix<D>, buf: &mut [f32]) {
    for fibre in buf.as_chunks_mut::<D>().0 {
        let x = *fibre;
        for (y, row) in fibre.iter_mut().zip(m) {
            *y = row.iter().zip(&x).map(|(w, x)| w * x).sum();
        }
    }
}

/// `buf = buf x1 M1 .. x5 M5` in place, with a strip of stack scratch and no second patch
/// buffer. Used to score a solution in a member and by the paper's general path.
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
    mode_rows_in_place(&m.m1, buf, PT * PU * PV * B);
    mode_rows_in_place(&m.m2, buf, PU * PV * B);
    mode_rows_in_place(&m.m3, buf, PV * B);
    mode_rows_in_place(&m.m4, buf, B);
    mode_last_in_place(&m.m5, buf);
}
