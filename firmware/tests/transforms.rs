//! Separable transforms against the dense Kronecker matrix in f64, and adjointness.

mod common;

use common::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use slf_firmware::Dictionary;
use slf_firmware::PaperShape;
use slf_firmware::PatchShape;
use slf_firmware::transform::{analyze, synthesize};

/// Synthesis and analysis of random patches with a random orthonormal dictionary and with
/// the DCT match `K s` and `K^T x` (K built densely in f64) to 1e-5 relative.
fn check_against_dense<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>() {
    for (dseed, dict) in [(0u64, Dictionary::<PatchShape<PS, PT, PU, PV, B, N>>::dct()), (7, random_dictionary(7))] {
        let (k, n) = dense_kronecker(dict.synthesis());
        assert_eq!(n, N);
        let (kt, _) = dense_kronecker(dict.analysis());
        let mut r = rng(100 + dseed);
        for _ in 0..3 {
            let s: Vec<f32> = (0..N).map(|_| rand::Rng::random_range(&mut r, -1.0f32..1.0)).collect();
            let mut a: Box<[f32; N]> = Box::new(s.clone().try_into().unwrap());
            let mut x = Box::new([0.0f32; N]);
            synthesize(&dict, &mut a, &mut x);
            let e = rel_err(&x[..], &dense_apply(&k, n, &s));
            assert!(e <= 1e-5, "synthesis rel err {e} (dict {dseed})");

            let mut a: Box<[f32; N]> = Box::new(s.clone().try_into().unwrap());
            analyze(&dict, &mut a, &mut x);
            let e = rel_err(&x[..], &dense_apply(&kt, n, &s));
            assert!(e <= 1e-5, "analysis rel err {e} (dict {dseed})");
        }
    }
}

#[test]
fn paper_patch_transforms_match_dense_kronecker() {
    check_against_dense::<5, 5, 4, 4, 13, 5200>();
}

#[test]
fn full_view_patch_transforms_match_dense_kronecker() {
    check_against_dense::<5, 5, 5, 5, 13, 8125>();
}

#[test]
fn synthesis_then_analysis_is_identity() {
    let dict = random_dictionary::<PaperShape>(3);
    let mut r = rng(4);
    let s: Vec<f32> = (0..5200).map(|_| rand::Rng::random_range(&mut r, -1.0f32..1.0)).collect();
    let mut a: Box<[f32; 5200]> = Box::new(s.clone().try_into().unwrap());
    let mut x = Box::new([0.0f32; 5200]);
    synthesize(&dict, &mut a, &mut x);
    analyze(&dict, &mut x, &mut a);
    assert!(rel_err32(&a[..], &s) < 1e-6);
}

fn dot(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(&x, &y)| f64::from(x) * f64::from(y)).sum()
}

/// `<A x, y> = <x, A^T y>` for synthesis A and analysis A^T, with a dictionary and
/// vectors drawn by proptest from a fixed seed.
fn adjoint_case<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>(
    dict_seed: u64,
    x: &[f32],
    y: &[f32],
) -> Result<(), TestCaseError> {
    let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(dict_seed);
    let mut xa: Box<[f32; N]> = Box::new(x.try_into().unwrap());
    let mut ax = Box::new([0.0f32; N]);
    synthesize(&dict, &mut xa, &mut ax);
    let mut ya: Box<[f32; N]> = Box::new(y.try_into().unwrap());
    let mut aty = Box::new([0.0f32; N]);
    analyze(&dict, &mut ya, &mut aty);
    let lhs = dot(&ax[..], y);
    let rhs = dot(x, &aty[..]);
    let scale = dot(x, x).sqrt() * dot(y, y).sqrt();
    prop_assert!((lhs - rhs).abs() <= 1e-5 * scale, "lhs {lhs} rhs {rhs} scale {scale}");
    Ok(())
}

fn config() -> Config {
    Config { cases: 24, rng_seed: RngSeed::Fixed(0x51f_5eed), failure_persistence: None, ..Config::default() }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn adjoint_paper_patch(seed in any::<u64>(),
                           x in prop::collection::vec(-10.0f32..10.0, 5200),
                           y in prop::collection::vec(-1.0f32..1.0, 5200)) {
        adjoint_case::<5, 5, 4, 4, 13, 5200>(seed, &x, &y)?;
    }

    #[test]
    fn adjoint_full_view_patch(seed in any::<u64>(),
                               x in prop::collection::vec(-1.0f32..1.0, 8125),
                               y in prop::collection::vec(-10.0f32..10.0, 8125)) {
        adjoint_case::<5, 5, 5, 5, 13, 8125>(seed, &x, &y)?;
    }
}
