//! The orthonormal DCT-II matrix, computed at compile time.
//!
//! The device never evaluates a cosine: [`dct_matrix`] is a `const fn`, so
//! `Dictionary::dct()` in a `static` or `const` lands in flash as a table. The cosines come
//! from a Taylor series in f64 on `[0, pi/2]` after exact integer range reduction, accurate
//! to the last bit of f32.

/// pi to f64 precision.
const PI: f64 = core::f64::consts::PI;

/// `cos(pi * m / (2 * d))` for integers `m >= 0`, `d > 0`, in f64.
const fn cos_half_pi_ratio(m: usize, d: usize) -> f64 {
    // Reduce m modulo the period 4d, then fold onto [0, d] (angle [0, pi/2]) with a sign.
    let period = 4 * d;
    let mut m = m % period;
    if m > 2 * d {
        m = period - m; // cos(2pi - x) = cos(x)
    }
    let mut sign = 1.0;
    if m > d {
        m = 2 * d - m; // cos(pi - x) = -cos(x)
        sign = -1.0;
    }
    let x = PI * (m as f64) / (2.0 * d as f64);
    // Taylor series; x <= pi/2, so 14 terms reach below 1e-17.
    let x2 = x * x;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1;
    while k < 15 {
        term = -term * x2 / ((2 * k - 1) as f64 * (2 * k) as f64);
        sum += term;
        k += 1;
    }
    sign * sum
}

/// Square root by Newton's method, for compile-time constants (`a > 0`).
const fn const_sqrt(a: f64) -> f64 {
    let mut x = if a > 1.0 { a } else { 1.0 };
    let mut i = 0;
    while i < 64 {
        x = 0.5 * (x + a / x);
        i += 1;
    }
    x
}

/// The `D x D` orthonormal DCT-II matrix, rows are atoms:
/// `C[k][n] = a_k cos(pi (2n + 1) k / (2D))`, `a_0 = sqrt(1/D)`, `a_k = sqrt(2/D)`.
///
/// Synthesis with a dictionary multiplies by `C^T` (columns are atoms) in the paper's
/// notation; see [`crate::Dictionary`] for which way round the decoder stores it.
pub const fn dct_matrix<const D: usize>() -> [[f32; D]; D] {
    let mut m = [[0.0f32; D]; D];
    let a0 = const_sqrt(1.0 / D as f64);
    let ak = const_sqrt(2.0 / D as f64);
    let mut k = 0;
    while k < D {
        let a = if k == 0 { a0 } else { ak };
        let mut n = 0;
        while n < D {
            m[k][n] = (a * cos_half_pi_ratio((2 * n + 1) * k, D)) as f32;
            n += 1;
        }
        k += 1;
    }
    m
}
