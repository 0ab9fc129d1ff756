//! One mode's matrix as a type, and the products by it that every transform is built of.
//!
//! A mode product over a mode with `inner` values after it is, for each block of the modes
//! before it, `d` output rows each a sum of `d` scaled input rows of length `inner`;
//! `block_rows` keeps all `d` output rows in registers eight columns at a time, so each
//! input vector is loaded once and each output stored once (as plain axpys over whole
//! rows, every multiply-add also loaded and stored its output: 6.1 us a transform against
//! 4.5 us). Where a mode's matrix is the DCT's (rows even or odd about their middle, found
//! when the dictionary is built) the product folds mirrored rows first and does about half
//! the multiplies ([`Fold`]: 3.9-4.0 us a DCT transform, and a quarter fewer instructions
//! on a Cortex-M4). The mode before the bands (`inner = B`) sums whole rows of `B` in
//! registers (`mode_pixel`, reached through [`crate::operators::shape::Shape::pixel`]); the last mode (bands, `inner = 1`) is a small matrix product
//! per pixel.
//!
//! The kernels take their extent as a const parameter, which is what lets the compiler
//! unroll them; code generic over a patch shape reaches them through [`Mode`], which every
//! [`Fixed`] extent implements (the one place a const extent meets a generic one).

use crate::operators::dct::dct_matrix;
use crate::sensor::extent::{Extent, Fixed, Square};

/// The matrix of mode `E`: `E::D x E::D`, row-major.
pub type ModeMatrix<E> = Square<E, f32>;

/// A mode extent whose matrices the transforms multiply by: the kernels of this file at
/// `D = Self::D`, and the mode's DCT.
pub trait Mode: Extent {
    /// The orthonormal DCT-II ([`dct_matrix`]): analysis; its transpose synthesises.
    const DCT: ModeMatrix<Self>;
    /// [`Self::DCT`] transposed.
    const DCT_T: ModeMatrix<Self>;
    /// [`transpose`].
    fn transpose(m: &ModeMatrix<Self>) -> ModeMatrix<Self>;
    /// [`has_parity`].
    fn has_parity(m: &ModeMatrix<Self>) -> bool;
    /// [`orthonormality_error`].
    fn orthonormality_error(m: &ModeMatrix<Self>) -> f32;
    /// `dst = src x_mode M` for this mode with `inner > 1` values after it.
    fn rows(m: &ModeMatrix<Self>, fold: Fold, src: &[f32], dst: &mut [f32], inner: usize);
    /// `dst += scale * (src x_mode M)`.
    fn rows_add(m: &ModeMatrix<Self>, fold: Fold, scale: f32, src: &[f32], dst: &mut [f32], inner: usize);
    /// `buf = buf x_mode M` in place, a strip of stack scratch at a time.
    fn rows_in_place(m: &ModeMatrix<Self>, buf: &mut [f32], inner: usize);
    /// `dst = src x_last M` for the last mode (`inner = 1`), given `mt = M^T`.
    fn last(mt: &ModeMatrix<Self>, src: &[f32], dst: &mut [f32]);
    /// `buf = buf x_last M` in place, one fibre at a time.
    fn last_in_place(m: &ModeMatrix<Self>, buf: &mut [f32]);
}

impl<const D: usize> Mode for Fixed<D> {
    const DCT: Matrix<D> = dct_matrix::<D>();
    const DCT_T: Matrix<D> = transpose(&dct_matrix::<D>());
    fn transpose(m: &Matrix<D>) -> Matrix<D> {
        transpose(m)
    }
    fn has_parity(m: &Matrix<D>) -> bool {
        has_parity(m)
    }
    fn orthonormality_error(m: &Matrix<D>) -> f32 {
        orthonormality_error(m)
    }
    #[inline(always)]
    fn rows(m: &Matrix<D>, fold: Fold, src: &[f32], dst: &mut [f32], inner: usize) {
        mode_rows(m, fold, src, dst, inner);
    }
    #[inline(always)]
    fn rows_add(m: &Matrix<D>, fold: Fold, scale: f32, src: &[f32], dst: &mut [f32], inner: usize) {
        mode_rows_add(m, fold, scale, src, dst, inner);
    }
    #[inline(always)]
    fn rows_in_place(m: &Matrix<D>, buf: &mut [f32], inner: usize) {
        mode_rows_in_place(m, buf, inner);
    }
    #[inline(always)]
    fn last(mt: &Matrix<D>, src: &[f32], dst: &mut [f32]) {
        mode_last(mt, src, dst);
    }
    #[inline(always)]
    fn last_in_place(m: &Matrix<D>, buf: &mut [f32]) {
        mode_last_in_place(m, buf);
    }
}

/// Which symmetry of a mode's matrix a mode product uses; found when its dictionary is
/// built ([`Dictionary::dct`](crate::operators::dictionary::Dictionary::dct), or checked in [`Dictionary::new`](crate::operators::dictionary::Dictionary::new)).
///
/// The DCT-II's rows are even or odd about their middle, `C[a][D-1-c] = (-1)^a C[a][c]`.
/// A product by such a matrix first adds and subtracts the input's mirrored rows and then
/// needs about half the multiplies (13 instead of 25 for `D = 5`, 8 instead of 16 for
/// `D = 4`); on a core whose multiplier is the bottleneck that is about half the time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fold {
    /// No symmetry used: `D^2` multiply-adds per column.
    Plain,
    /// Rows even or odd, `M[a][D-1-c] = (-1)^a M[a][c]` (the DCT-II: analysis).
    Rows,
    /// Columns even or odd, `M[D-1-n][k] = (-1)^k M[n][k]` (its transpose: synthesis).
    Columns,
}

/// A `D x D` matrix, row-major.
pub type Matrix<const D: usize> = [[f32; D]; D];

/// How far from even / odd a row may be for the transforms to use the symmetry: the
/// symmetric half of the row is what they read, so this bounds what they change.
pub const PARITY_TOLERANCE: f32 = 1e-6;

/// Whether every row `a` of `m` is even (`a` even) or odd about its middle to
/// [`PARITY_TOLERANCE`]: `m[a][D-1-c] = (-1)^a m[a][c]`, and so the middle entry of an odd
/// row of odd length is 0.
pub fn has_parity<const D: usize>(m: &Matrix<D>) -> bool {
    m.iter().enumerate().all(|(a, row)| {
        let sign = if a % 2 == 0 { 1.0 } else { -1.0 };
        (0..D).all(|c| (row[D - 1 - c] - sign * row[c]).abs() <= PARITY_TOLERANCE)
    })
}

/// The transpose of a square matrix.
pub const fn transpose<const D: usize>(m: &Matrix<D>) -> Matrix<D> {
    let mut t = [[0.0f32; D]; D];
    let mut i = 0;
    while i < D {
        let mut j = 0;
        while j < D {
            t[j][i] = m[i][j];
            j += 1;
        }
        i += 1;
    }
    t
}

/// The largest entry of `|M M^T - I|` (NaN if `M` holds NaN).
pub fn orthonormality_error<const D: usize>(m: &Matrix<D>) -> f32 {
    let mut worst = 0.0f32;
    for (i, ri) in m.iter().enumerate() {
        for (j, rj) in m.iter().enumerate() {
            let dot: f32 = ri.iter().zip(rj).map(|(a, b)| a * b).sum();
            let target = if i == j { 1.0 } else { 0.0 };
            let e = (dot - target).abs();
            if e.is_nan() || e > worst {
                worst = e; // also carries NaN out
            }
        }
    }
    worst
}

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
pub(crate) fn mode_last<const D: usize>(mt: &Matrix<D>, src: &[f32], dst: &mut [f32]) {
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

/// Columns the in-place mode product copies to the stack at a time.
const STRIP: usize = 64;

/// `buf = buf x_mode M` in place for a mode of size `D` with `inner` values after it
/// (`inner > 1`). Each block's `D` rows are copied a strip of at most [`STRIP`] columns at
/// a time to a `D x STRIP` stack array (3.3 KiB for `D = 13`), then written back as
/// the unfolded [`mode_rows`] writes them: the same sums in the same order, contiguous axpys the
/// compiler vectorises. No second patch buffer.
#[inline(always)]
pub(crate) fn mode_rows_in_place<const D: usize>(m: &Matrix<D>, buf: &mut [f32], inner: usize) {
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

/// `buf = buf x5 M` in place for the last (band) mode, one fibre at a time.
pub(crate) fn mode_last_in_place<const D: usize>(m: &Matrix<D>, buf: &mut [f32]) {
    for fibre in buf.as_chunks_mut::<D>().0 {
        let x = *fibre;
        for (y, row) in fibre.iter_mut().zip(m) {
            *y = row.iter().zip(&x).map(|(w, x)| w * x).sum();
        }
    }
}
