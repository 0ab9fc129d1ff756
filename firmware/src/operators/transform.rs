//! Separable transforms of one patch: synthesis `X = S x1 D1 .. x5 D5` and analysis
//! `S = X x1 D1^T .. x5 D5^T`.
//!
//! These are most of the cost of a solve; each is five mode products
//! ([`crate::operators::mode`], where the kernels and their measurements are). The five
//! products ping-pong between two caller-owned buffers: no allocation, no set-up. Host and
//! device run the same sums in the same order, so both give the same bits. Each transform
//! costs `N * (PS + PT + PU + PV + B)` multiply-adds without folding
//! ([`Shape::TRANSFORM_MACS`]).

use crate::operators::dictionary::{Dictionary, Factors};
use crate::operators::mode::{Fold, Mode, ModeMatrix};
use crate::operators::shape::{PerValue, Scratch, Shape};

/// The five mode products `m` (with `mt5 = m.m5^T`) from `a` into `b`; `a` is clobbered.
///
/// Kept out of line: synthesis and analysis share one copy per patch shape, which keeps
/// the device image small (inlined at each call site it tripled `solve` to 79 KB).
#[inline(never)]
fn chain<S: Shape>(
    m: &Factors<S>,
    mt5: &ModeMatrix<S::Bands>,
    f: [Fold; 4],
    a: &mut PerValue<S, f32>,
    b: &mut PerValue<S, f32>,
) {
    let (a, b) = (a.as_mut(), b.as_mut());
    S::S::rows(&m.m1, f[0], a, b, S::PT * S::PU * S::PV * S::B);
    S::T::rows(&m.m2, f[1], b, a, S::PU * S::PV * S::B);
    S::U::rows(&m.m3, f[2], a, b, S::PV * S::B);
    S::pixel(&m.m4, f[3], b, a);
    S::Bands::last(mt5, a, b);
}

/// Synthesis: `signal = coeffs x1 D1 .. x5 D5`. `coeffs` is the scratch and is clobbered.
pub fn synthesize<S: Shape>(dict: &Dictionary<S>, coeffs: &mut PerValue<S, f32>, signal: &mut PerValue<S, f32>) {
    chain(&dict.d, &dict.t.m5, dict.synthesis_folds(), coeffs, signal);
}

/// Analysis: `coeffs = signal x1 D1^T .. x5 D5^T`. `signal` is the scratch and is clobbered.
pub fn analyze<S: Shape>(dict: &Dictionary<S>, signal: &mut PerValue<S, f32>, coeffs: &mut PerValue<S, f32>) {
    chain(&dict.t, &dict.d.m5, dict.analysis_folds(), signal, coeffs);
}

/// `dst = src x1 M1 .. x5 M5` (with `mt5 = M5^T`) with `src` only read: the first mode
/// goes from `src` to `dst`, the other four work one spatial slice at a time between
/// `dst` and a [`Shape::Slice`] on the stack. Scores a solution in a member without a copy.
#[inline(never)]
fn apply_preserving<S: Shape>(
    m: &Factors<S>,
    mt5: &ModeMatrix<S::Bands>,
    f: [Fold; 4],
    src: &PerValue<S, f32>,
    dst: &mut PerValue<S, f32>,
) {
    let part_len = S::PT * S::PU * S::PV * S::B;
    S::S::rows(&m.m1, f[0], src.as_ref(), dst.as_mut(), part_len);
    let mut scratch = S::Slice::ZERO;
    for part in dst.as_mut().chunks_exact_mut(part_len) {
        let tmp = scratch.values();
        S::T::rows(&m.m2, f[1], part, tmp, S::PU * S::PV * S::B);
        S::U::rows(&m.m3, f[2], tmp, part, S::PV * S::B);
        S::pixel(&m.m4, f[3], part, tmp);
        S::Bands::last(mt5, tmp, part);
    }
}

/// Analysis that keeps its input: `coeffs = signal x1 D1^T .. x5 D5^T`, `signal` only read
/// (a spatial slice of stack scratch instead of a clobbered input; a little slower than
/// [`analyze`]). Scores a solution in each member of an ensemble.
pub fn analyze_preserving<S: Shape>(dict: &Dictionary<S>, signal: &PerValue<S, f32>, coeffs: &mut PerValue<S, f32>) {
    apply_preserving(&dict.t, &dict.d.m5, dict.analysis_folds(), signal, coeffs);
}

/// `buf = buf x1 M1 .. x5 M5` in place, with a strip of stack scratch and no second patch
/// buffer. Used to score a solution in a member and by the paper's general path.
pub(crate) fn apply_in_place<S: Shape>(m: &Factors<S>, buf: &mut PerValue<S, f32>) {
    let buf = buf.as_mut();
    S::S::rows_in_place(&m.m1, buf, S::PT * S::PU * S::PV * S::B);
    S::T::rows_in_place(&m.m2, buf, S::PU * S::PV * S::B);
    S::U::rows_in_place(&m.m3, buf, S::PV * S::B);
    S::V::rows_in_place(&m.m4, buf, S::B);
    S::Bands::last_in_place(&m.m5, buf);
}
