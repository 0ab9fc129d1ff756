//! The measured-entries projection and the input-keeping analysis against dense f64
//! references: `S + K^T P^T (I - P K S)` with `K` the dense Kronecker matrix.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::PatchShape;
use slf_firmware::ball::Ball;
use slf_firmware::projection::{project_coefficients, weigh};
use slf_firmware::shape::ValueCount;
use slf_firmware::transform::analyze_preserving;
use slf_firmware::{Dictionary, Measurements};

/// Measures `per_pixel` random bands of each pixel (none for every seventh pixel) with
/// random values; returns the measurements and the measured indices.
fn random_measurements<const B: usize, const N: usize>(
    seed: u64,
    per_pixel: usize,
) -> (Measurements<ValueCount<N>>, Vec<usize>) {
    let mut r = rng(seed);
    let mut m = Measurements::new();
    let mut idx = Vec::new();
    for p in 0..N / B {
        if p % 7 == 3 {
            continue;
        }
        let mut bands: Vec<usize> = (0..B).collect();
        for _ in 0..per_pixel {
            let b = bands.swap_remove(r.random_range(0..bands.len()));
            m.set(p * B + b, r.random_range(0.0f32..1.0)).unwrap();
            idx.push(p * B + b);
        }
    }
    (m, idx)
}

/// The projection in f64 with dense matrices onto the ball `sum r_i^2 / var_i <= m`,
/// `var_i = (noise^2 + shot * max(y_i g, 0)) / g^2` with `g` the gain of entry `i`'s band
/// (white-balanced values; both 0: exactly): returns the projected coefficients and the
/// residual norm before the move.
fn dense_projection(
    k: &[f64],
    n: usize,
    s: &[f32],
    m_idx: &[usize],
    y: &[f32],
    (noise, shot): (f64, f64),
    gains: &[f64],
) -> (Vec<f64>, f64) {
    let x = dense_apply(k, n, s);
    let mut r = vec![0.0f64; n];
    let mut white2 = 0.0;
    for &i in m_idx {
        r[i] = f64::from(y[i]) - x[i];
        let g = gains[i % gains.len()];
        white2 += r[i] * r[i] * g * g / (noise * noise + shot * (f64::from(y[i]) * g).max(0.0));
    }
    let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let m = m_idx.len() as f64;
    let scale = if noise == 0.0 && shot == 0.0 {
        1.0
    } else if white2 > m {
        1.0 - (m / white2).sqrt()
    } else {
        0.0
    };
    // K^T r: column i of K is row i of K^T.
    let out = (0..n).map(|c| f64::from(s[c]) + scale * (0..n).map(|i| k[i * n + c] * r[i]).sum::<f64>()).collect();
    (out, norm)
}

fn check<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>() {
    let mut inside = 0;
    for (dseed, dict) in [(0u64, Dictionary::<PatchShape<PS, PT, PU, PV, B, N>>::dct()), (5, random_dictionary(5))] {
        let (k, n) = dense_kronecker(dict.synthesis());
        for (case, per_pixel) in [1usize, 3, B].into_iter().enumerate() {
            let (m, idx) = random_measurements::<B, N>(10 * dseed + case as u64, per_pixel);
            let y: Vec<f32> = (0..N).map(|i| m.get(i).unwrap_or(0.0)).collect();
            let mut r = rng(99 + case as u64);
            let s: Vec<f32> = (0..N).map(|_| r.random_range(-1.0f32..1.0)).collect();
            let ones = vec![1.0f64; B];
            let (_, norm0) = dense_projection(&k, n, &s, &idx, &y, (0.0, 0.0), &ones);
            // White balance: gains from 1/30 to 3 (a tungsten scene's spread), and values
            // divided by them.
            let gains: Vec<f32> = (0..B).map(|b| 3.0 / (1.0 + 89.0 * b as f32 / B as f32)).collect();
            // The residual's RMS per measurement: a noise level of half of it puts the point
            // outside the ball, twice it inside.
            let rms = norm0 / (idx.len() as f64).sqrt();
            // Exact; uniform balls the point lies outside of and inside of; weighted balls
            // (shot noise: variance rising with the value in 0..1) outside and inside.
            // With gains: uniform noise and shot noise, the point outside.
            let balls = [
                (0.0, 0.0, false),
                (0.5 * rms, 0.0, false),
                (2.0 * rms, 0.0, false),
                (0.0, 0.25 * rms * rms, false),
                (0.5 * rms, 16.0 * rms * rms, false),
                (0.0, 0.0, true),
                (0.5 * rms, 0.0, true),
                (0.5 * rms, 16.0 * rms * rms, true),
            ];
            for (noise, shot, balanced) in balls {
                let mut coeffs: Box<[f32; N]> = Box::new(s.clone().try_into().unwrap());
                let mut scratch = Box::new([0.0f32; N]);
                let mut m = m.clone();
                let g64: Vec<f64> = if balanced {
                    m.set_gains(&gains).unwrap();
                    gains.iter().map(|&g| f64::from(g)).collect()
                } else {
                    ones.clone()
                };
                let ball = Ball::new(noise as f32, shot as f32, idx.len() as u32, 0).balanced(balanced); // radius^2 = m
                let start = coeffs.clone();
                let residual = project_coefficients(&dict, &mut coeffs, &mut scratch, &m, &ball, None);
                if ball.is_weighted() {
                    // The solver's path: the weights made once, read by each step. The same
                    // sums in the same order: the same bits.
                    let mut weights = Box::new([f32::NAN; N]);
                    weigh::<PatchShape<PS, PT, PU, PV, B, N>>(&m, &ball, &mut weights);
                    let mut weighed = start.clone();
                    let r = project_coefficients(&dict, &mut weighed, &mut scratch, &m, &ball, Some(&weights));
                    assert_eq!(r.to_bits(), residual.to_bits(), "noise {noise} shot {shot}: residual");
                    assert!(weighed.iter().zip(coeffs.iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
                }
                let (reference, norm) = dense_projection(&k, n, &s, &idx, &y, (noise, shot), &g64);
                let e = rel_err(&coeffs[..], &reference);
                assert!(e <= 2e-6, "dict {dseed}, {per_pixel} per pixel, noise {noise} shot {shot}: rel err {e}");
                assert!((f64::from(residual) - norm).abs() <= 1e-5 * norm, "residual {residual} vs {norm}");
                if reference.iter().zip(&s).all(|(a, &b)| *a == f64::from(b)) {
                    assert_eq!(&coeffs[..], &s[..], "inside the ball nothing moves");
                    inside += usize::from(!balanced);
                }
                // Exactly projected coefficients synthesise to the measurements.
                if noise == 0.0 && shot == 0.0 {
                    assert!(!ball.is_weighted(), "an exact ball weighs nothing, gains or not");
                    let x = dense_apply(&k, n, &coeffs[..]);
                    let worst = idx.iter().map(|&i| (x[i] - f64::from(y[i])).abs()).fold(0.0, f64::max);
                    assert!(worst <= 1e-5, "off the measurements by {worst}");
                }
            }
        }
    }
    // The uniform ball of twice the residual's RMS holds the point for each of the 2
    // dictionaries x 3 cases; the half-RMS and weighted-outside ones never do.
    assert!((6..=12).contains(&inside), "{inside} balls hold the point");
}

#[test]
fn paper_patch_projection_matches_dense_reference() {
    check::<5, 5, 4, 4, 13, 5200>();
}

#[test]
fn odd_patch_projection_matches_dense_reference() {
    // Modes of 3 and 7 exercise the transforms' partial register blocks.
    check::<3, 2, 7, 3, 5, 630>();
}

#[test]
fn most_bands_projection_matches_dense_reference() {
    // `MAX_BANDS` bands: the band step's bit mask gathers four bytes of flags.
    check::<2, 1, 1, 2, 32, 128>();
}

#[test]
fn analysis_keeping_its_input_matches_dense_reference() {
    fn case<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>() {
        let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(8);
        let (kt, n) = dense_kronecker(dict.analysis());
        let mut r = rng(9);
        let x: Vec<f32> = (0..N).map(|_| r.random_range(-1.0f32..1.0)).collect();
        let signal: Box<[f32; N]> = Box::new(x.clone().try_into().unwrap());
        let mut coeffs = Box::new([0.0f32; N]);
        analyze_preserving(&dict, &signal, &mut coeffs);
        assert_eq!(&signal[..], &x[..], "input kept");
        let e = rel_err(&coeffs[..], &dense_apply(&kt, n, &x));
        assert!(e <= 1e-5, "rel err {e}");
    }
    case::<5, 5, 4, 4, 13, 5200>();
    case::<3, 2, 7, 3, 5, 630>();
}
