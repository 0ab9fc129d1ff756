//! Stability on hard scenes and bad input, end to end (scene -> camera -> decode). Every
//! case asserts: no NaN or infinity in the output, the iteration bound honoured, and an
//! error bound or a typed error. Error bounds were set from measurement (noted per case).

use slf_host::decode::cs::{Basis, DecodeOptions, DecodeReport, NoiseSource, PatchViews, decode, decode_with};
use slf_host::eval::bench::F64Dct;
use slf_host::eval::metrics::psnr;
use slf_host::firmware::{Dictionary, Sl0Config};
use slf_host::io::capture::{Capture, MaskDescription, MaskSource};
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{self, SceneSize};

const SIZE: SceneSize = SceneSize { views: (5, 5), rows: 10, cols: 10 };

fn field(f: impl Fn(usize, usize, usize, usize, usize) -> f32) -> LightField {
    let mut lf = LightField::zeros(SIZE.views, SIZE.rows, SIZE.cols, 13);
    for u in 0..5 {
        for v in 0..5 {
            for y in 0..SIZE.rows {
                for x in 0..SIZE.cols {
                    for b in 0..13 {
                        let i = lf.index(u, v, y, x, b);
                        lf.data[i] = f(u, v, y, x, b);
                    }
                }
            }
        }
    }
    lf
}

/// Decodes with `basis` and `sl0` as given (its noise ball too: exact for the default
/// config, whatever noise the capture describes) and checks the invariants every case
/// shares.
fn checked(capture: &Capture, basis: &Basis, sl0: Sl0Config) -> (LightField, DecodeReport) {
    checked_with(capture, basis, &DecodeOptions { sl0, noise: NoiseSource::Config, ..DecodeOptions::disjoint() })
}

fn checked_with(capture: &Capture, basis: &Basis, opts: &DecodeOptions) -> (LightField, DecodeReport) {
    let sl0 = opts.sl0;
    let (recon, report) = decode_with(capture, basis, opts).unwrap();
    assert!(recon.data.iter().all(|x| x.is_finite()), "non-finite output");
    // Each patch's last solve within the bound.
    let max_steps = u64::from(sl0.max_iterations) * u64::from(report.patches.decoded);
    assert!(report.steps <= max_steps, "steps {} above the bound {max_steps}", report.steps);
    assert_eq!(report.failed_tiles, 0);
    (recon, report)
}

fn ensemble() -> Basis {
    Basis::default_ensemble()
}

fn peak_psnr(truth: &LightField, recon: &LightField) -> f64 {
    psnr(&truth.data, &recon.data, 1.0)
}

#[test]
fn all_black_decodes_to_black() {
    let truth = field(|_, _, _, _, _| 0.0);
    let cap = simulate(&truth, &CameraConfig::pixel(1, 3).noiseless()).unwrap();
    for basis in [Basis::Dct, ensemble()] {
        let (recon, _) = checked(&cap, &basis, Sl0Config::DEFAULT);
        assert!(recon.data.iter().all(|x| x.abs() < 1e-6), "{}", basis.name());
    }
}

#[test]
fn all_saturated_is_a_typed_error_per_patch_and_nothing_is_invented() {
    let truth = field(|_, _, _, _, _| 3.0); // three times white: every pixel clips at the top code
    let cap = simulate(&truth, &CameraConfig::pixel(1, 3).noiseless()).unwrap();
    let (recon, report) = checked(&cap, &ensemble(), Sl0Config::DEFAULT);
    assert_eq!(report.patches.decoded, 0);
    // 10 x 10 lenslets: 2 x 2 blocks, one full-view patch each (the default patch).
    assert_eq!(report.patch_views, Some(PatchViews::Five));
    assert_eq!(report.patches.failed, 4, "every patch: no valid measurement");
    assert_eq!(report.uncovered, recon.data.len());
    assert!(recon.data.iter().all(|&x| x == 0.0));
}

#[test]
fn a_hot_pixel_is_left_out_and_costs_almost_nothing() {
    let truth = scene::named("smooth").unwrap().render(SIZE);
    let clean = simulate(&truth, &CameraConfig::pixel(2, 3).noiseless()).unwrap();
    let mut hot = clean.clone();
    hot.held_frames_mut().unwrap()[1][23 * 50 + 17] = 4095;
    let (a, _) = checked(&clean, &ensemble(), Sl0Config::DEFAULT);
    let (b, report) = checked(&hot, &ensemble(), Sl0Config::DEFAULT);
    assert!(report.patches.flagged >= 1);
    // Measured: clean 34.891 dB, with the hot pixel 34.885 dB; bound: within 0.5 dB.
    assert!(peak_psnr(&truth, &b) > peak_psnr(&truth, &a) - 0.5);
}

#[test]
fn checkerboards_in_space_and_spectrum_stay_bounded() {
    let spatial = field(|_, _, y, x, _| ((y + x) % 2) as f32 * 0.9);
    let spectral = field(|_, _, _, _, b| (b % 2) as f32 * 0.9);
    for truth in [spatial, spectral] {
        let cap = simulate(&truth, &CameraConfig::pixel(3, 3)).unwrap();
        for basis in [Basis::Dct, ensemble()] {
            let (recon, _) = checked(&cap, &basis, Sl0Config::DEFAULT);
            let max = recon.data.iter().fold(0.0f32, |m, x| m.max(x.abs()));
            assert!(max <= 1.5, "{}: output up to {max}", basis.name());
        }
    }
}

#[test]
fn narrow_band_spectra_and_extreme_dynamic_range() {
    let line = field(|_, _, y, _, b| if b == 4 + y % 5 { 0.9 } else { 0.02 });
    let range = field(|_, _, y, x, b| 10f32.powf(-5.0 + 5.0 * ((y * 10 + x) * 13 + b) as f32 / 1299.0));
    for truth in [line, range] {
        let cap = simulate(&truth, &CameraConfig::pixel(4, 3).noiseless()).unwrap();
        let (recon, _) = checked(&cap, &ensemble(), Sl0Config::DEFAULT);
        let max = recon.data.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        assert!(max <= 1.5, "output up to {max}");
        assert!(peak_psnr(&truth, &recon) > 15.0, "{:.2}", peak_psnr(&truth, &recon));
    }
}

#[test]
fn patches_with_few_valid_pixels_and_bad_raw_values() {
    let truth = scene::named("depth").unwrap().render(SIZE);
    let mut cap = simulate(&truth, &CameraConfig::pixel(5, 3).noiseless()).unwrap();
    // Block (0, 0): all but 20 of its 625 pixels defective; block (1, 1) every pixel.
    let mut d = cap.description.clone();
    for r in 0..25u32 {
        for c in 0..25u32 {
            if (r * 25 + c) % 31 != 0 {
                d.defective_pixels.push([r, c]);
            }
            d.defective_pixels.push([25 + r, 25 + c]);
        }
    }
    // Out-of-range raw values elsewhere.
    cap.held_frames_mut().unwrap()[0][30 * 50 + 3] = 4095;
    cap.held_frames_mut().unwrap()[2][40 * 50 + 9] = 4095;
    let cap = Capture::with_frames(d, cap.frames).unwrap();
    let (recon, report) = checked(&cap, &ensemble(), Sl0Config::DEFAULT);
    assert_eq!(report.patches.failed, 1, "block (1, 1): a typed error for its full-view patch");
    // Block (0, 0) (its defects) and block (1, 0) (both out-of-range values) are flagged.
    assert!(report.patches.flagged >= 2, "{} flagged", report.patches.flagged);
    let max = recon.data.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    assert!(max <= 1.5, "output up to {max}");
}

#[test]
fn repeated_bands_across_snapshots_are_rejected() {
    let truth = field(|_, _, _, _, _| 0.5);
    let cam = CameraConfig::pixel(1, 2).with_mask(MaskDescription::Pixel(MaskSource {
        snapshots: None,
        seed: None,
        tile: Some(vec![vec![vec![3, 4]], vec![vec![3, 5]]]),
    }));
    let err = simulate(&truth, &cam).unwrap_err().to_string();
    assert!(err.contains("repeated"), "{err}");
}

#[test]
fn thirteen_snapshots_reproduce_the_scene() {
    let truth = scene::named("texture").unwrap().render(SIZE);
    let cap = simulate(&truth, &CameraConfig::pixel(6, 13).noiseless()).unwrap();
    for basis in [Basis::Dct, ensemble()] {
        let (recon, _) = checked(&cap, &basis, Sl0Config::DEFAULT);
        // Quantisation-limited (one DN in 3,628 per white): measured 81.85 dB for both bases.
        let p = peak_psnr(&truth, &recon);
        assert!(p > 70.0, "{}: {p:.2} dB", basis.name());
    }
}

#[test]
fn sigma_min_below_f32_resolution() {
    let truth = scene::named("depth").unwrap().render(SIZE);
    let cap = simulate(&truth, &CameraConfig::pixel(7, 3)).unwrap();
    let (base, _) = checked(&cap, &Basis::Dct, Sl0Config::DEFAULT);
    for sigma_min in [1e-30f32, 1e-45] {
        let sl0 = Sl0Config { sigma_min, max_iterations: 1000, ..Sl0Config::DEFAULT };
        let (recon, _) = checked(&cap, &Basis::Dct, sl0);
        assert!(peak_psnr(&truth, &recon) > peak_psnr(&truth, &base) - 1.0);
    }
}

#[test]
fn heavy_read_noise_with_and_without_the_noise_aware_stop() {
    let truth = scene::named("smooth").unwrap().render(SIZE);
    let mut cam = CameraConfig::pixel(8, 3);
    cam.read_noise = 60.0;
    let cap = simulate(&truth, &cam).unwrap();
    let sigma = 60.0 / (3691.9 - 64.0); // read noise in normalised units
    let (exact, _) = checked(&cap, &Basis::Dct, Sl0Config::DEFAULT);
    let (aware, _) = checked(&cap, &Basis::Dct, Sl0Config { noise: sigma, ..Sl0Config::DEFAULT });
    // The default: the capture's description (read, quantisation and shot noise).
    let (described, _) = checked_with(&cap, &Basis::Dct, &DecodeOptions::default());
    let (pe, pa, pd) = (peak_psnr(&truth, &exact), peak_psnr(&truth, &aware), peak_psnr(&truth, &described));
    // Measured: exact 31.80 dB, read noise only 32.32 dB, the capture's model 32.32 dB.
    assert!(pa > pe, "the noise-aware stop should not fit the noise: {pa:.2} vs {pe:.2}");
    assert!(pd > pe, "the capture's noise model should not fit the noise: {pd:.2} vs {pe:.2}");
}

#[test]
fn f32_decoder_within_005_db_of_the_f64_reference_on_the_test_scenes() {
    for name in scene::NAMES {
        let truth = scene::named(name).unwrap().render(SIZE);
        let cap = simulate(&truth, &CameraConfig::pixel(9, 3)).unwrap();
        // Exact projection for both: the f64 reference has no noise ball (with the capture's
        // noise model the f32 decode moves onto a ball the reference does not, which the
        // seeded shifted patches carry on: dark 56.665 against 56.606 dB).
        let opts = DecodeOptions { noise: NoiseSource::Config, ..DecodeOptions::default() };
        // Both patches: the paper's and the full-view one.
        let (f32r, _) = decode::<4, 4, 5200, _>(&cap, &Dictionary::dct(), &opts).unwrap();
        let (f64r, _) = decode::<4, 4, 5200, _>(&cap, &F64Dct::<4, 4, 5200>::default(), &opts).unwrap();
        let (a, b) = (peak_psnr(&truth, &f32r), peak_psnr(&truth, &f64r));
        assert!((a - b).abs() <= 0.05, "{name}, 4 views: f32 {a:.3} dB vs f64 {b:.3} dB");
        let (f32r, _) = decode::<5, 5, 8125, _>(&cap, &Dictionary::dct(), &opts).unwrap();
        let (f64r, _) = decode::<5, 5, 8125, _>(&cap, &F64Dct::<5, 5, 8125>::default(), &opts).unwrap();
        let (a, b) = (peak_psnr(&truth, &f32r), peak_psnr(&truth, &f64r));
        assert!((a - b).abs() <= 0.05, "{name}, 5 views: f32 {a:.3} dB vs f64 {b:.3} dB");
    }
}
