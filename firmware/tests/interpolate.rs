//! Per-pixel spectral interpolation (the decode of a patch that measures too few bands)
//! against a slow obvious f64 reference, and the tile decoder's choice of it.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::PatchShape;
use slf_firmware::interpolate::{bands_measured, interpolate_bands};
use slf_firmware::shape::ValueCount;
use slf_firmware::{Ended, Measurements};

/// One pixel in f64: for each band, the nearest measured band below and above; linear
/// between them, the one there is beyond.
fn reference_pixel(measured: &[(usize, f32)], b: usize) -> f64 {
    let below = measured.iter().filter(|m| m.0 <= b).max_by_key(|m| m.0);
    let above = measured.iter().filter(|m| m.0 >= b).min_by_key(|m| m.0);
    match (below, above) {
        (Some(&(lo, a)), Some(&(hi, c))) if hi > lo => {
            f64::from(a) + (b - lo) as f64 / (hi - lo) as f64 * (f64::from(c) - f64::from(a))
        }
        (Some(&(_, a)), _) => f64::from(a),
        (None, Some(&(_, c))) => f64::from(c),
        (None, None) => unreachable!("a measured pixel"),
    }
}

#[test]
fn interpolation_matches_the_reference_and_fills_unmeasured_pixels_with_the_mean() {
    const B: usize = 13;
    const N: usize = 40 * B;
    for seed in 0..20u64 {
        let mut r = rng(seed);
        let mut m = Measurements::<ValueCount<N>>::new();
        let mut per_pixel = Vec::new();
        let mut union = [false; B];
        for p in 0..N / B {
            // 0..=4 random bands; every fifth pixel none.
            let count = if p % 5 == 4 { 0 } else { r.random_range(1..=4usize) };
            let mut bands: Vec<usize> = (0..B).collect();
            let mut pixel = Vec::new();
            for _ in 0..count {
                let b = bands.swap_remove(r.random_range(0..bands.len()));
                let y = r.random_range(0.0f32..1.0);
                m.set(p * B + b, y).unwrap();
                pixel.push((b, y));
                union[b] = true;
            }
            per_pixel.push(pixel);
        }
        assert_eq!(
            bands_measured::<PatchShape<1, 1, 1, { N / B }, B, N>>(&m),
            union.iter().filter(|&&u| u).count() as u32
        );
        let mut out = [f32::NAN; N];
        let missing = interpolate_bands::<PatchShape<1, 1, 1, { N / B }, B, N>>(&m, &mut out);
        assert_eq!(missing, per_pixel.iter().filter(|p| p.is_empty()).count());
        let spectra: Vec<Vec<f64>> = per_pixel
            .iter()
            .filter(|p| !p.is_empty())
            .map(|p| (0..B).map(|b| reference_pixel(p, b)).collect())
            .collect();
        let mean: Vec<f64> = (0..B).map(|b| spectra.iter().map(|s| s[b]).sum::<f64>() / spectra.len() as f64).collect();
        for (p, pixel) in per_pixel.iter().enumerate() {
            for b in 0..B {
                let want = if pixel.is_empty() { mean[b] } else { reference_pixel(pixel, b) };
                let got = f64::from(out[p * B + b]);
                assert!((got - want).abs() <= 1e-6, "seed {seed} pixel {p} band {b}: {got} vs {want}");
            }
            // Measured values are kept exactly.
            for &(b, y) in pixel {
                assert_eq!(out[p * B + b], y);
            }
        }
    }
    // Nothing measured: nothing to interpolate from, all zeros.
    let mut out = [1.0f32; N];
    assert_eq!(
        interpolate_bands::<PatchShape<1, 1, 1, { N / B }, B, N>>(&Measurements::<ValueCount<N>>::new(), &mut out),
        N / B
    );
    assert!(out.iter().all(|&x| x == 0.0));
    assert_eq!(Ended::Interpolated, slf_firmware::Outcome::interpolated().ended);
}
