//! The projection of a patch's coefficients onto its measurements, in coefficient space.
//!
//! SL0's projection `S <- S - A^+ (A S - I)` with an orthonormal dictionary `D` and one-hot
//! (selection) measurements `P` is `S <- S + D^T P^T (I - P D S)`: the rows of `P D` are
//! orthonormal, so `A^+ = (P D)^T`. Only the measured entries of the synthesis are needed,
//! and the correction `P^T r` is zero everywhere else. Both facts are used per pixel on
//! the band axis, which is the last (contiguous) axis of the patch and the largest mode
//! (13 of the paper's 5 + 5 + 4 + 4 + 13 multiply-adds per value):
//!
//! 1. synthesis over the four pixel modes (space and view), `N (PS + PT + PU + PV)`
//!    multiply-adds;
//! 2. per pixel, each measured band's value as one dot product with a row of `D5`, its
//!    residual `r`, and the pixel's band coefficients of the correction as the sum of
//!    `r` times those rows: `2 B` multiply-adds per measurement;
//! 3. analysis of the correction over the four pixel modes, added to `S`.
//!
//! Against a full synthesis, overwrite and full analysis (`2 N (PS + PT + PU + PV + B)`)
//! this saves the band mode's `2 N B` except `2 B` per measurement: for the paper's patch
//! at one measurement per pixel, 197,600 multiply-adds a step instead of 322,400.
//!
//! The first mode goes from the coefficients to the signal buffer and back; the other
//! modes and the band step work one spatial slice at a time between the signal buffer and
//! a `Slice` on the stack (4 KiB), so the workspace does not grow and the slice stays
//! in the L1 cache from the synthesis to the analysis.

use crate::operators::dictionary::Dictionary;
use crate::operators::mode::{Mode, ModeMatrix};
use crate::operators::shape::{PerBand, PerValue, Scratch, Shape};
use crate::sensor::extent::{Array, Extent};
use crate::solver::ball::{Ball, Move};
use crate::solver::workspace::Measurements;

/// Multiply-adds of one projection with `measured` measurements: the pixel-mode synthesis
/// and analysis, and `2 B` per measurement on the band axis.
pub const fn projection_macs<S: Shape>(measured: usize) -> usize {
    let pixels = S::PS * S::PT * S::PU * S::PV;
    2 * pixels * S::B * (S::PS + S::PT + S::PU + S::PV) + 2 * S::B * measured
}

/// Moves the coefficients `coeffs` (of `dict`) onto the measurements `m`: exactly, or onto
/// the noise [`Ball`] (a point inside it is left alone, one outside moves to its surface).
/// `scratch` is clobbered. Returns the residual norm `||I - P D S||` before the move. This
/// is the projection of every step of [`crate::solve`].
///
/// A weighted ball ([`Ball::is_weighted`]) weighs each residual by [`Ball::weight`]: read
/// from `weights` when given ([`weigh`] of the same measurements and ball, as the solver
/// makes them once a solve), else computed, two divisions a measurement; the same sums
/// either way.
///
/// Kept out of line: inlined into the solver's step loop, the band step ran about twice
/// as slow as in this function alone (`perf annotate` of `slf bench`), and a decode with
/// the DCT took 0.80 against 0.68 ms a patch at pixel k = 3 (0.49 against 0.47 at k = 1).
pub fn project_coefficients<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
    weights: Option<&PerValue<S, f32>>,
) -> f32 {
    let weighted = ball.is_weighted();
    let mut parts = weights.map(|w| w.as_ref().chunks_exact(S::PT * S::PU * S::PV * S::B));
    let mut step = |fibres: &mut [PerBand<S, f32>], values: &[f32], measured: &[bool]| {
        let (m5, gains) = (&dict.d.m5, &m.gains);
        match parts.as_mut().and_then(Iterator::next) {
            Some(w) if weighted => band_step::<S, TABLE>(m5, fibres, values, measured, ball, gains, w),
            _ if weighted => band_step::<S, COMPUTED>(m5, fibres, values, measured, ball, gains, values),
            _ => band_step::<S, PLAIN>(m5, fibres, values, measured, ball, gains, values),
        }
    };
    project_slices(dict, coeffs, scratch, m, ball, &mut step)
}

/// Each measured entry's weight in `ball` ([`Ball::weight`]) into `weights`, in patch
/// order (the other entries are left as they are): what [`project_coefficients`] reads.
pub fn weigh<S: Shape>(m: &Measurements<S::Values>, ball: &Ball, weights: &mut PerValue<S, f32>) {
    let measured = S::Bands::chunks(m.values.as_ref()).iter().zip(S::Bands::chunks(m.measured.as_ref()));
    for (ws, (ys, flags)) in S::Bands::chunks_mut(weights.as_mut()).iter_mut().zip(measured) {
        for b in set_flags(flags.as_ref()) {
            let (Some(w), Some(&y)) = (ws.get_mut(b), ys.get(b)) else { continue };
            *w = ball.weight(y, m.gains.get(b).copied().unwrap_or(1.0));
        }
    }
}

/// The weight in a weighted `ball` of the measurement `y` at patch entry `entry` in a band
/// of gain `gain`: read from the solve's table `weights` ([`weigh`]) when given, else
/// computed ([`Ball::weight`], two divisions); the same value either way. The interpolating
/// projections' steps ([`crate::solver::shares`], [`crate::solver::fractional`]) call it
/// per measurement.
#[inline(always)]
pub(crate) fn measured_weight<S: Shape>(
    weights: Option<&PerValue<S, f32>>,
    entry: usize,
    ball: &Ball,
    y: f32,
    gain: Option<&f32>,
) -> f32 {
    match weights {
        Some(t) => t.get(entry).copied().unwrap_or(0.0),
        None => ball.weight(y, gain.copied().unwrap_or(1.0)),
    }
}

/// A band step: one spatial slice's pixels, their band coefficients in `fibres` (after the
/// pixel modes' synthesis), become the correction's; `values` / `measured` are the
/// slice's measurements in patch order. Returns the sums of squared residuals, plain and
/// weighted ([`Ball::weight`]).
pub(crate) type BandStep<'s, S> = dyn FnMut(&mut [PerBand<S, f32>], &[f32], &[bool]) -> (f32, f32) + 's;

/// The projection's frame shared by the one-hot band step ([`project_coefficients`]) and
/// the mixed one ([`crate::solver::mixing::project_mixed`]): the pixel modes' synthesis,
/// `step` per spatial slice, the analysis and the ball's move. The band step is called
/// through a pointer (five calls a projection), so the transforms are compiled once: with
/// a copy per band step the mixed projection added 20 KB of flash to the device image.
#[inline(never)]
pub(crate) fn project_slices<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
    step: &mut BandStep<'_, S>,
) -> f32 {
    let part_len = S::PT * S::PU * S::PV * S::B;
    S::S::rows(&dict.d.m1, dict.synthesis_folds()[0], coeffs.as_ref(), scratch.as_mut(), part_len);
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let mut tmp = S::Slice::ZERO;
    let parts = scratch.as_mut().chunks_exact_mut(part_len).zip(m.values.as_ref().chunks_exact(part_len));
    for ((part, values), measured) in parts.zip(m.measured.as_ref().chunks_exact(part_len)) {
        let tmp = tmp.values();
        slice_synthesis(dict, part, tmp);
        let (r, w) = step(S::Bands::chunks_mut(tmp), values, measured);
        (r2, w2) = (r2 + r, w2 + w);
        slice_analysis(dict, tmp, part);
    }
    apply_move(dict, ball, (r2, w2), scratch.as_ref(), coeffs.as_mut())
}

/// A step on the whole patch's band coefficients: `scratch` (every pixel's band
/// coefficients after the pixel modes' synthesis) becomes the correction's. Returns the sums
/// of squared residuals, plain and weighted.
pub(crate) type PatchStep<'s, S> = dyn FnMut(&mut PerValue<S, f32>) -> (f32, f32) + 's;

/// The frame of the interpolating projections ([`crate::solver::fractional`],
/// [`crate::solver::shares`]), whose measurements read values of several spatial slices:
/// the pixel modes' synthesis of every slice back in place, `step` on the whole patch, the
/// analysis and the ball's move. One copy for both (through a pointer, as
/// [`project_slices`]): a copy each took 19 KB more flash on the device.
#[inline(never)]
pub(crate) fn project_whole<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    ball: &Ball,
    step: &mut PatchStep<'_, S>,
) -> f32 {
    let part_len = S::PT * S::PU * S::PV * S::B;
    S::S::rows(&dict.d.m1, dict.synthesis_folds()[0], coeffs.as_ref(), scratch.as_mut(), part_len);
    let mut tmp = S::Slice::ZERO;
    for part in scratch.as_mut().chunks_exact_mut(part_len) {
        let tmp = tmp.values();
        slice_synthesis(dict, part, tmp);
        part.copy_from_slice(tmp.as_ref());
    }
    let moved = step(scratch);
    for part in scratch.as_mut().chunks_exact_mut(part_len) {
        let tmp = tmp.values();
        tmp.copy_from_slice(part.as_ref());
        slice_analysis(dict, tmp, part);
    }
    apply_move(dict, ball, moved, scratch.as_ref(), coeffs.as_mut())
}

/// The synthesis of one spatial slice over the pixel modes after the first: `part` (its
/// first mode already synthesised) to each pixel's band coefficients in `fibres`; `part`
/// is clobbered. Shared by both projections ([`crate::solver::fractional`]).
#[inline(always)]
pub(crate) fn slice_synthesis<S: Shape>(dict: &Dictionary<S>, part: &mut [f32], fibres: &mut [f32]) {
    let (d, fd) = (&dict.d, dict.synthesis_folds());
    S::T::rows(&d.m2, fd[1], part, fibres, S::PU * S::PV * S::B);
    S::U::rows(&d.m3, fd[2], fibres, part, S::PV * S::B);
    S::pixel(&d.m4, fd[3], part, fibres);
}

/// The inverse of [`slice_synthesis`]: a slice's corrections as band coefficients in
/// `fibres` analysed over the pixel modes after the first into `part`; `fibres` is
/// clobbered.
#[inline(always)]
pub(crate) fn slice_analysis<S: Shape>(dict: &Dictionary<S>, fibres: &mut [f32], part: &mut [f32]) {
    let (t, ft) = (&dict.t, dict.analysis_folds());
    S::pixel(&t.m4, ft[3], fibres, part);
    S::U::rows(&t.m3, ft[2], part, fibres, S::PV * S::B);
    S::T::rows(&t.m2, ft[1], fibres, part, S::PU * S::PV * S::B);
}

/// The end of a projection: the ball's move for squared residual norms `(r2, w2)` (plain,
/// weighted), and the correction in `scratch` (all but the first mode analysed) added to
/// `coeffs` at that scale through the first mode's analysis. Returns the residual norm.
#[inline(always)]
pub(crate) fn apply_move<S: Shape>(
    dict: &Dictionary<S>,
    ball: &Ball,
    (r2, w2): (f32, f32),
    scratch: &[f32],
    coeffs: &mut [f32],
) -> f32 {
    let norm = libm::sqrtf(r2);
    let Move::Scale(scale) = ball.move_for(r2, w2) else {
        return norm; // inside the ball: no move
    };
    S::S::rows_add(&dict.t.m1, dict.analysis_folds()[0], scale, scratch, coeffs, S::PT * S::PU * S::PV * S::B);
    norm
}

/// How a band step weighs a residual: not at all (an exact or uniform ball), by
/// [`Ball::weight`] computed from the value and its band's gain, or read from a table.
const PLAIN: u8 = 0;
const COMPUTED: u8 = 1;
const TABLE: u8 = 2;

/// The band step on a slice's pixels: `fibres` hold each pixel's band coefficients after
/// the pixel modes' synthesis and become the correction's; `values` / `measured` are the
/// slice's measurements in patch order. Returns the sum of squared residuals and, unless
/// `PLAIN`, of each over its measurement's variance ([`Ball::weight`]: `COMPUTED` from the
/// value and the band's gain in `gains`, two divisions; `TABLE` read from `weights`, the
/// slice's weights in patch order).
///
/// A pixel's measured bands are found from a bit mask of its flags ([`band_bits`]),
/// lowest set bit first: scanning the flags one by one took a data-dependent branch per
/// band, mispredicted about once per pixel where each pixel measures a different band.
/// With the dot product's sums paired ([`dot`]) and the flags read as one 128-bit integer
/// the step went from 2.2 to 1.2 us per projection at one measurement per pixel (3.8 to
/// 3.1 us at three; criterion, paper patch); the bit mask (two multiplies a pixel instead
/// of 128-bit arithmetic a band) took the projection from 5.98 to 5.75 us at one.
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the band step's inputs, inlined into its one caller
fn band_step<S: Shape, const WEIGH: u8>(
    m5: &ModeMatrix<S::Bands>,
    fibres: &mut [PerBand<S, f32>],
    values: &[f32],
    measured: &[bool],
    ball: &Ball,
    gains: &[f32],
    weights: &[f32],
) -> (f32, f32) {
    const { assert!(S::B <= 64, "a pixel's flags fit one mask (S::B <= MAX_BANDS)") };
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let pixels = fibres.iter_mut().zip(S::Bands::chunks(values)).zip(S::Bands::chunks(measured));
    for (((fibre, values), measured), weights) in pixels.zip(S::Bands::chunks(weights)) {
        let mut correction = <PerBand<S, f32>>::splat(0.0);
        let mut bits = band_bits(measured.as_ref());
        while bits != 0 {
            let b = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let (Some(row), Some(&y)) = (m5.get(b), values.get(b)) else { break };
            let r = y - dot(row.as_ref(), fibre.as_ref());
            r2 += r * r;
            if WEIGH == COMPUTED {
                w2 += r * r * ball.weight(y, gains.get(b).copied().unwrap_or(1.0));
            } else if WEIGH == TABLE {
                w2 += r * r * weights.get(b).copied().unwrap_or(0.0);
            }
            for (c, &w) in correction.iter_mut().zip(row.iter()) {
                *c += r * w;
            }
        }
        *fibre = correction;
    }
    (r2, w2)
}

/// The indices of the set flags among the first 64 of `flags`, in order: [`band_bits`]
/// walked lowest bit first (a pixel's measured bands, without a branch a band).
#[inline(always)]
pub(crate) fn set_flags(flags: &[bool]) -> impl Iterator<Item = usize> {
    let mut bits = band_bits(flags);
    core::iter::from_fn(move || {
        if bits == 0 {
            return None;
        }
        let b = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        Some(b)
    })
}

/// Up to 64 flags as a bit mask, bit `j` for flag `j` (any further flags are not read):
/// eight flags at a time, read as
/// the bytes of a `u64` (each 0 or 1) and gathered into one byte by a multiply whose
/// partial products never overlap (byte `i` lands on bit `56 + i`).
#[inline(always)]
pub(crate) fn band_bits(flags: &[bool]) -> u64 {
    const GATHER: u64 = 0x0102_0408_1020_4080;
    let mut bits = 0u64;
    for (i, eight) in flags.chunks(8).enumerate().take(8) {
        let mut bytes = [0u8; 8];
        for (o, &k) in bytes.iter_mut().zip(eight) {
            *o = u8::from(k);
        }
        bits |= (u64::from_le_bytes(bytes).wrapping_mul(GATHER) >> 56) << (8 * i);
    }
    bits
}

/// `sum a[j] b[j]` as eight running sums added pairwise: a chain of `B / 8 + 3` additions
/// instead of `B`, so the pixels' band steps overlap.
#[inline(always)]
pub(crate) fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    for (j, (x, y)) in a.iter().zip(b).enumerate() {
        acc[j % 8] += x * y;
    }
    ((acc[0] + acc[4]) + (acc[2] + acc[6])) + ((acc[1] + acc[5]) + (acc[3] + acc[7]))
}
