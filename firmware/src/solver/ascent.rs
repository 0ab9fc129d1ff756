//! The steepest-ascent step of SL0, `s <- s - mu * s * exp(-s^2 / (2 sigma^2))`, over a
//! whole patch of coefficients.
//!
//! Profiling a solve (`perf record` on `cargo bench --bench solve`) showed the step with
//! `libm::expf` at about 60 % of a screened-ensemble decode, more than the transforms:
//! `expf` is a correctly rounded scalar routine with a branch and a division, so the loop
//! over 5,200 coefficients runs one value at a time. The step here computes the weight
//! `exp(-s^2 / (2 sigma^2))` as `2^t` with `t = s^2 c`, `c = -log2(e) / (2 sigma^2)`
//! computed once per step: `t = n + f` with `n` the nearest integer and `|f| <= 1/2`, a
//! degree-5 minimax polynomial for `2^f` (2.2e-7 relative on that range, evaluated in
//! Estrin's order so its multiplies overlap), and `2^n` put straight into the exponent
//! bits. No branch, no table, no division, and no base-e range reduction: `t` carries the
//! same rounding as `x = s^2 / (2 sigma^2)` in the base-e form, so the weight is as
//! accurate either way, with 7 fewer operations per coefficient (27 instead of 34; the
//! step `mu` is folded into the polynomial's coefficients). Every operation is a plain f32
//! add, multiply, round or select, so the compiler vectorises the loop (8 lanes with
//! AVX2), and on a Cortex-M4F it avoids `expf`'s 14-cycle `VDIV`.
//!
//! Accuracy (tests/ascent.rs): [`exp2`] within 2.5e-7 relative of f64 over its whole
//! range; the step within 3e-7 of the `libm::expf` step's size.

use crate::operators::schedule::Weights;
use crate::operators::shape::{Scratch, Shape};
use crate::sensor::extent::{Array, Extent};

/// `t` is clamped here: `2^-115` is a normal f32, and beyond it `mu * 2^t` is below
/// `2^-25` for any `mu < 1e27`, so the step would leave `s` unchanged after rounding (the
/// select in [`ascend`] makes that exact for any `mu`).
const T_MIN: f32 = -115.0;
/// `1.5 * 2^23`: adding and subtracting it rounds an f32 of magnitude below `2^22` to
/// the nearest integer (ties to even).
const ROUND: f32 = 12_582_912.0;
const LOG2_E: f32 = core::f32::consts::LOG2_E;
/// `2^f = 1 + Q[0] f + .. + Q[4] f^5` on `|f| <= 1/2`, minimax in relative error
/// (9.2e-8 in exact arithmetic, 2.2e-7 evaluated in f32).
/// (`Q[0]` is near `ln 2` but not it: the minimax fit trades its last digits for the
/// error at the ends of the range.)
#[allow(clippy::approx_constant)]
const Q: [f32; 5] = [0.693_147, 0.240_222_42, 0.055_507_336, 0.009_671_506, 0.001_326_470_6];

/// `k[0] + k[1] f + .. + k[5] f^5` in Estrin's order.
#[inline(always)]
fn poly(k: &[f32; 6], f: f32) -> f32 {
    let f2 = f * f;
    (k[0] + k[1] * f) + f2 * ((k[2] + k[3] * f) + f2 * (k[4] + k[5] * f))
}

/// `scale * 2^t` for `T_MIN <= t <= 0` (callers clamp), given `k = scale * [1, Q..]`.
#[inline(always)]
fn scaled_exp2(k: &[f32; 6], t: f32) -> f32 {
    let shifted = t + ROUND;
    let n = shifted - ROUND;
    let f = t - n;
    // n is an integer in [-115, 0], held in the low bits of `shifted` (its ulp is 1), so
    // it is read off as an integer without a float-to-int conversion (which the compiler
    // does not vectorise: it saturates lane by lane). 2^n is the normal f32 with biased
    // exponent n + 127.
    let n_int = shifted.to_bits().wrapping_sub(ROUND.to_bits()).wrapping_add(127);
    poly(k, f) * f32::from_bits(n_int << 23)
}

/// The polynomial's coefficients times `scale`.
fn scaled(scale: f32) -> [f32; 6] {
    [scale, scale * Q[0], scale * Q[1], scale * Q[2], scale * Q[3], scale * Q[4]]
}

/// `2^t` for `-115 <= t <= 0` (clamped into that range otherwise), branch-free; relative
/// error below 2.5e-7.
pub fn exp2(t: f32) -> f32 {
    scaled_exp2(&scaled(1.0), t.clamp(T_MIN, 0.0))
}

/// The exponent `t = s^2 c` of the step's weight `2^t`, and the `t` below which the step
/// rounds away: `mu * exp(-x) < 2^-125` for `x > 88 + ln(max(mu, 1))`.
fn exponents(mu: f32, inv: f32) -> (f32, f32) {
    (-inv * LOG2_E, -(88.0 + libm::logf(mu.max(1.0))) * LOG2_E)
}

/// The ascent step on every coefficient, `inv = 1 / (2 sigma^2)`.
///
/// Where `x = s^2 inv` exceeds `88 + ln(max(mu, 1))`, `mu * exp(-x) < 2^-125` and the step
/// rounds away (`s` is unchanged); a select keeps that exact for any `mu`, and a clamp
/// keeps the weight's exponent in range without a branch.
///
/// Returns the squared length of the step, `sum (mu s exp(-x))^2`: the solver's measure of
/// how far the patch moved (see [`crate::solver::sl0`]'s early stop).
#[cfg(not(target_arch = "arm"))]
#[inline]
pub fn ascend(coeffs: &mut [f32], mu: f32, inv: f32) -> f32 {
    let (c, skip) = exponents(mu, inv);
    let k = scaled(mu);
    // Eight lanes at a time, with eight running sums of the squared steps, one per lane:
    // one running sum would be a serial chain the compiler may not reorder (f32 addition
    // is not associative), and it kept the whole step scalar.
    let mut sums = [0.0f32; 8];
    let (lanes, tail) = coeffs.as_chunks_mut::<8>();
    for lane in lanes {
        for (s, sum) in lane.iter_mut().zip(sums.iter_mut()) {
            let d = step(&k, c, skip, *s);
            *s -= d;
            *sum += d * d;
        }
    }
    for s in tail {
        let d = step(&k, c, skip, *s);
        *s -= d;
        sums[0] += d * d;
    }
    sums.iter().sum()
}

/// The step `mu s 2^t` of one coefficient `s`, 0 where it rounds away (`t < skip`, and a
/// non-finite `s`, whose `t` is NaN or `-inf`: it stays as it is).
#[cfg(not(target_arch = "arm"))]
#[inline(always)]
fn step(k: &[f32; 6], c: f32, skip: f32, s: f32) -> f32 {
    let t = s * s * c;
    let d = s * scaled_exp2(k, t.max(T_MIN));
    if t >= skip { d } else { 0.0 }
}

/// The ascent step on a scalar core (Cortex-M): no lanes to fill, so the coefficients the
/// step cannot move (most of them at small sigma) are skipped by a branch instead of
/// computed and discarded; each coefficient gets the same value as on the host, only the
/// returned sum is added in another order. Measured on the emulated Cortex-M4
/// (`scripts/budgets.sh`, DCT patch, with the earlier base-e form of the weight): 99.1 M
/// instructions, against 102.4 M branch-free and 97.2 M with `libm::expf` (whose fewer
/// instructions include a `VDIV`, 14 cycles on a Cortex-M4, per call; qemu counts
/// instructions, not cycles).
#[cfg(target_arch = "arm")]
#[inline]
pub fn ascend(coeffs: &mut [f32], mu: f32, inv: f32) -> f32 {
    let (c, skip) = exponents(mu, inv);
    let k = scaled(mu);
    let mut moved = 0.0f32;
    for s in coeffs {
        let t = *s * *s * c;
        if t >= skip {
            // `t` is not NaN here (`t >= skip` held); a comparison, not `f32::max`, which
            // this core (no `VMAXNM`) calls `fmaxf` for: 5.6 % of a screened patch.
            let d = *s * scaled_exp2(&k, if t > T_MIN { t } else { T_MIN });
            *s -= d;
            moved += d * d;
        }
    }
    moved
}

/// The ascent step of a trained schedule ([`crate::operators::schedule`]): as [`ascend`], with
/// each coefficient's exponent scaled by its group weight, `s <- s - mu s exp(-w s^2 inv)`,
/// `w` the product of its indices' weights (`coeffs` in the patch layout `[s, t, u, v, b]`,
/// the band last). The weights of the four pixel modes are multiplied once per pixel, the
/// band's once per step, so a coefficient costs one multiply more than in [`ascend`].
///
/// Returns the squared length of the step, as [`ascend`] does.
pub fn ascend_weighted<S: Shape>(coeffs: &mut [f32], mu: f32, inv: f32, weights: &Weights<S>) -> f32 {
    let (c, skip) = exponents(mu, inv);
    let k = scaled(mu);
    // The exponent's factor of every (view, band) of a lenslet, `c w_u w_v w_b`, on the
    // stack ([u, v, b] is a contiguous run of the patch layout): each lenslet's run is
    // then one loop over contiguous values with a per-lenslet factor, which vectorises as
    // `ascend` does (a loop per 13-band fibre stayed 4 times slower).
    let mut views = S::Lenslet::ZERO;
    let views = views.values();
    let mut fibres = S::Bands::chunks_mut(views).iter_mut();
    for wu in weights.u.iter() {
        for wv in weights.v.iter() {
            let Some(fibre) = fibres.next() else { break };
            for (x, wb) in fibre.iter_mut().zip(weights.b.iter()) {
                *x = c * wu * wv * wb;
            }
        }
    }
    let views = &*views;
    let mut sums = [0.0f32; 8];
    let mut lenslets = coeffs.chunks_exact_mut(S::PU * S::PV * S::B);
    for ws in weights.s.iter() {
        for wt in weights.t.iter() {
            let Some(run) = lenslets.next() else { return sums.iter().sum() };
            lenslet_step(run, views, ws * wt, &k, skip, &mut sums);
        }
    }
    sums.iter().sum()
}

/// One lenslet's run of coefficients, `views` its (view, band) exponent factors, `scale` the
/// lenslet's: eight lanes at a time, as [`ascend`], with each lane's factor in an array first
/// (zipped with the lanes, the loop stayed scalar: 8 times the time of [`ascend`]).
#[cfg(not(target_arch = "arm"))]
#[inline(always)]
fn lenslet_step(run: &mut [f32], views: &[f32], scale: f32, k: &[f32; 6], skip: f32, sums: &mut [f32; 8]) {
    let (lanes, tail) = run.as_chunks_mut::<8>();
    let (wlanes, wtail) = views.as_chunks::<8>();
    for (lane, w) in lanes.iter_mut().zip(wlanes) {
        let c: [f32; 8] = core::array::from_fn(|l| scale * w[l]);
        let d: [f32; 8] = core::array::from_fn(|l| step(k, c[l], skip, lane[l]));
        for l in 0..8 {
            lane[l] -= d[l];
            sums[l] += d[l] * d[l];
        }
    }
    for (s, w) in tail.iter_mut().zip(wtail) {
        let d = step(k, scale * w, skip, *s);
        *s -= d;
        sums[0] += d * d;
    }
}

/// [`lenslet_step`] on a scalar core: the coefficients the step cannot move are skipped by a
/// branch, as the Cortex-M [`ascend`] does; each gets the same value as on the host.
#[cfg(target_arch = "arm")]
#[inline(always)]
fn lenslet_step(run: &mut [f32], views: &[f32], scale: f32, k: &[f32; 6], skip: f32, sums: &mut [f32; 8]) {
    for (s, w) in run.iter_mut().zip(views) {
        let t = *s * *s * (scale * w);
        if t >= skip {
            let d = *s * scaled_exp2(k, if t > T_MIN { t } else { T_MIN });
            *s -= d;
            sums[0] += d * d;
        }
    }
}
