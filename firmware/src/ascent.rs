//! The steepest-ascent step of SL0, `s <- s - mu * s * exp(-s^2 / (2 sigma^2))`, over a
//! whole patch of coefficients.
//!
//! Profiling a solve (`perf record` on `cargo bench --bench solve`) showed the step with
//! `libm::expf` at about 60 % of a screened-ensemble decode, more than the transforms:
//! `expf` is a correctly rounded scalar routine with a branch and a division, so the loop
//! over 5,200 coefficients runs one value at a time. The step here computes `exp(-x)` with
//! no branch and no table: Cody-Waite range reduction `-x = n ln 2 + r`, `|r| <= ln 2 / 2`,
//! Cephes' degree-5 minimax polynomial for `exp(r)` (as in Cephes `expf`, 1.2e-7 relative
//! on that range), and `2^n` put straight into the exponent bits. Every operation is a
//! plain f32 add, multiply, round or select, so the compiler vectorises the loop (8 lanes
//! with AVX2), and on a Cortex-M4F it avoids `expf`'s 14-cycle `VDIV`.
//!
//! Accuracy (tests/ascent.rs, against f64 `exp` on a dense grid): at most 2.5e-7 relative
//! over the whole range used, the same order as `libm::expf`. The decoded patch moves by
//! rounding only: `slf bench` gave the same PSNR to 0.01 dB before and after (DCT, pixel
//! k = 3: 30.73 dB), and the f32 decoder stays within 0.01 dB of the f64 reference.

/// `exp(-x)` is used for `x` up to here; beyond it `mu * exp(-x)` is below `2^-25` for any
/// `mu < 1.7e27`, so the step leaves `s` unchanged after rounding either way, and the
/// clamp keeps `2^n` a normal number (subnormals are slow on some cores).
const X_MAX: f32 = 80.0;
/// `1.5 * 2^23`: adding and subtracting it rounds an f32 of magnitude below `2^22` to
/// the nearest integer (ties to even).
const ROUND: f32 = 12_582_912.0;
const LOG2_E: f32 = core::f32::consts::LOG2_E;
/// `ln 2` split so that `n * LN2_HI` is exact for `|n| < 2^11` (Cody and Waite).
const LN2_HI: f32 = 0.693_359_4;
const LN2_LO: f32 = -2.121_944_4e-4;
/// Cephes `expf`: `exp(r) = 1 + r + r^2 P(r)` on `|r| <= ln 2 / 2`.
const P: [f32; 6] = [1.987_569_1e-4, 1.398_199_9e-3, 8.333_452e-3, 4.166_579_6e-2, 0.166_666_65, 0.5];

/// `exp(-x)` for `0 <= x <= 80` (callers clamp), branch-free; relative error below 2.5e-7.
#[inline(always)]
pub fn exp_neg(x: f32) -> f32 {
    let t = -x;
    let shifted = t * LOG2_E + ROUND;
    let n = shifted - ROUND;
    let r = (t - n * LN2_HI) - n * LN2_LO;
    let p = ((((P[0] * r + P[1]) * r + P[2]) * r + P[3]) * r + P[4]) * r + P[5];
    let e = p * (r * r) + r + 1.0;
    // n is an integer in [-116, 0], held in the low bits of `shifted` (its ulp is 1), so
    // it is read off as an integer without a float-to-int conversion (which the compiler
    // does not vectorise: it saturates lane by lane). 2^n is the normal f32 with biased
    // exponent n + 127.
    let n_int = shifted.to_bits().wrapping_sub(ROUND.to_bits()).wrapping_add(127);
    let two_n = f32::from_bits(n_int << 23);
    e * two_n
}

/// The ascent step on every coefficient, `inv = 1 / (2 sigma^2)`.
///
/// Where `x = s^2 inv` exceeds `88 + ln(max(mu, 1))`, `mu * exp(-x) < 2^-125` and the step
/// rounds away (`s` is unchanged); a select keeps that exact for any `mu`, and the clamp
/// at 80 keeps `exp_neg` in range without a branch.
///
/// Returns the squared length of the step, `sum (mu s exp(-x))^2`: the solver's measure of
/// how far the patch moved (see [`crate::sl0`]'s early stop).
#[cfg(not(target_arch = "arm"))]
#[inline]
pub fn ascend(coeffs: &mut [f32], mu: f32, inv: f32) -> f32 {
    let skip = 88.0 + libm::logf(mu.max(1.0));
    // Eight lanes at a time, with eight running sums of the squared steps, one per lane:
    // one running sum would be a serial chain the compiler may not reorder (f32 addition
    // is not associative), and it kept the whole step scalar.
    let mut sums = [0.0f32; 8];
    let (lanes, tail) = coeffs.as_chunks_mut::<8>();
    for lane in lanes {
        for (s, sum) in lane.iter_mut().zip(sums.iter_mut()) {
            let x = *s * *s * inv;
            let e = exp_neg(x.min(X_MAX));
            let d = if x <= skip { mu * *s * e } else { 0.0 };
            *s -= d;
            *sum += d * d;
        }
    }
    for s in tail {
        let x = *s * *s * inv;
        let d = if x <= skip { mu * *s * exp_neg(x.min(X_MAX)) } else { 0.0 };
        *s -= d;
        sums[0] += d * d;
    }
    sums.iter().sum()
}

/// The ascent step on a scalar core (Cortex-M): no lanes to fill, so the coefficients the
/// step cannot move (most of them at small sigma) are skipped by a branch instead of
/// computed and discarded; each coefficient gets the same value as on the host, only the
/// returned sum is added in another order. Measured on the emulated Cortex-M4
/// (`scripts/budgets.sh`, DCT patch): 99.1 M instructions, against 102.4 M branch-free
/// and 97.2 M with `libm::expf` (whose fewer instructions include a `VDIV`, 14 cycles on
/// a Cortex-M4, per call; qemu counts instructions, not cycles).
#[cfg(target_arch = "arm")]
#[inline]
pub fn ascend(coeffs: &mut [f32], mu: f32, inv: f32) -> f32 {
    let skip = 88.0 + libm::logf(mu.max(1.0));
    let mut moved = 0.0f32;
    for s in coeffs {
        let x = *s * *s * inv;
        if x <= skip {
            let d = mu * *s * exp_neg(x.min(X_MAX));
            *s -= d;
            moved += d * d;
        }
    }
    moved
}
