//! The branch-free ascent step against `exp` in f64 and against the `libm::expf` step.

use slf_firmware::ascent::{ascend, exp2};

/// `exp2` within 2.5e-7 relative of f64 `2^t` on a dense grid of [-115, 0] (every 1/1024,
/// plus the ends and the integers, where its polynomial meets the exponent bits), and
/// clamped outside it.
#[test]
fn exp2_matches_f64() {
    let mut worst = (0.0f64, 0.0f32);
    for i in 0..=115 * 1024 {
        let t = -(i as f32) / 1024.0;
        let want = (t as f64).exp2();
        let rel = ((exp2(t) as f64 - want) / want).abs();
        if rel > worst.0 {
            worst = (rel, t);
        }
    }
    assert!(worst.0 < 2.5e-7, "relative error {:e} at t = {}", worst.0, worst.1);
    assert_eq!(exp2(0.0), 1.0);
    assert_eq!(exp2(-200.0), exp2(-115.0));
    assert_eq!(exp2(3.0), 1.0);
}

/// The step with `libm::expf`, as the solver took it before (the slow obvious code).
fn ascend_libm(coeffs: &mut [f32], mu: f32, inv: f32) {
    for s in coeffs {
        *s -= mu * *s * libm::expf(-*s * *s * inv);
    }
}

/// Over coefficients spread across 12 decades and sigmas from 10 to 1e-4, the step moves
/// each coefficient as the libm step does, to 3e-7 of the step's size `(1 + mu) |s|`, and
/// leaves exactly unchanged what the libm step leaves unchanged far out in the tail.
#[test]
fn step_matches_libm_step() {
    let coeffs: Vec<f32> = (0..4000)
        .map(|i| {
            let mag = 10f32.powf(-8.0 + 12.0 * ((i * 7919) % 4000) as f32 / 4000.0);
            if i % 2 == 0 { mag } else { -mag }
        })
        .collect();
    for sigma in [10.0f32, 1.0, 0.1, 1e-2, 1e-3, 1e-4] {
        for mu in [0.5f32, 2.0, 7.0] {
            let inv = 1.0 / (2.0 * sigma * sigma);
            let (mut fast, mut slow) = (coeffs.clone(), coeffs.clone());
            ascend(&mut fast, mu, inv);
            ascend_libm(&mut slow, mu, inv);
            for ((f, s), c) in fast.iter().zip(&slow).zip(&coeffs) {
                assert!((f - s).abs() <= 3e-7 * (1.0 + mu) * c.abs(), "sigma {sigma} mu {mu}: {c} -> {f}, libm {s}");
                if c * c * inv > 90.0 {
                    assert_eq!(f, c, "tail coefficient moved");
                }
            }
        }
    }
}

/// Non-finite coefficients stay non-finite or unchanged, and never poison the others.
#[test]
fn step_is_local_for_non_finite_values() {
    let mut c = [f32::NAN, f32::INFINITY, 0.5, -0.25, f32::NEG_INFINITY, 0.0];
    ascend(&mut c, 2.0, 1.0);
    assert!(c[0].is_nan());
    assert_eq!((c[1], c[4]), (f32::INFINITY, f32::NEG_INFINITY));
    for (got, s) in [(c[2], 0.5f32), (c[3], -0.25)] {
        let want = s - 2.0 * s * (-(s as f64) * s as f64).exp() as f32;
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }
    assert_eq!(c[5], 0.0);
}
