//! nD SL0: the fast path against the paper's pseudo-inverse path, exact and sparse
//! recovery, the noise-aware mode, how a solve reports its end, and hard cases.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::Fixed;
use slf_firmware::PaperShape;
use slf_firmware::Shape as _;
use slf_firmware::pinv::{PinvOperator, solve_pinv};
use slf_firmware::{
    Dictionary, Ended, FullViewWorkspace, LensletSize, Mask, MaskFamily, PaperWorkspace, PatchShape, Sl0Config,
    SolveError, Workspace, solve,
};

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

fn ws() -> Box<PaperWorkspace> {
    Box::new(Workspace::new())
}

#[test]
fn workspace_fits_the_ram_budget() {
    let size = core::mem::size_of::<PaperWorkspace>();
    assert!(size <= 96 * 1024, "workspace is {size} bytes");
    // Four patch buffers (coefficients, signal, values, weights), a flag per value, a gain
    // per band (MAX_BANDS), the response matrix with its inverse (2 x 13 x 13 f32), and
    // behind a lenslet grid each pixel's place in its view cell (2 x MAX_PLACES bytes) and
    // the shares' widths and shifts:
    // nothing else hides in it.
    let response = 2 * 4 * 13 * 13 + 8;
    let grid = 2 * slf_firmware::workspace::MAX_PLACES + 8 + 2 * slf_firmware::workspace::MAX_SHARE_VIEWS + 4;
    assert!(size <= 4 * 4 * 5200 + 5200 + 4 * 32 + 16 + response + grid, "workspace is {size} bytes");
    // The exact figure docs/decoder.md, the crate docs and the device's log give: a change to the
    // workspace shows here first.
    assert_eq!(size, 91_176, "docs/decoder.md and firmware/src/lib.rs say 91,176 B");
    // The full-view patch's, the device's (`scripts/budgets.sh` checks its log against it):
    // the same parts for 8,125 values, in the part's 512 KiB of RAM.
    let full = core::mem::size_of::<FullViewWorkspace>();
    assert!(full <= 4 * 4 * 8125 + 8125 + 4 * 32 + 16 + response + grid, "full-view workspace is {full} bytes");
    assert_eq!(full, 140_900, "docs/decoder.md, firmware/src/lib.rs and scripts/budgets.sh say 140,900 B");
}

fn masks(k: u8) -> [Mask<'static>; 3] {
    [
        Mask::kronecker(11, k, 13, L5, (5, 5)).unwrap(),
        Mask::lenslet(12, k, 13, L5).unwrap(),
        Mask::pixel(13, k, 13, L5).unwrap(),
    ]
}

/// The orthonormal fast path and the paper's pseudo-inverse path decode the same patch
/// on kronecker masks (1e-4 relative), with the DCT and with a random orthonormal member.
fn fast_equals_pinv<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const N: usize>() {
    for (dseed, dict) in [(0, Dictionary::<PatchShape<PS, PT, PU, PV, 13, N>>::dct()), (5, random_dictionary(5))] {
        for k in [1u8, 3, 7] {
            let mask = Mask::kronecker(21 + u64::from(k), k, 13, L5, (PS as u8, PT as u8)).unwrap();
            let truth = smooth_patch::<PatchShape<PS, PT, PU, PV, 13, N>>(k.into());
            let mut ws = Box::new(Workspace::<PatchShape<PS, PT, PU, PV, 13, N>>::new());
            measure(&mask, (0, 0), &truth, &mut ws);
            let cfg = Sl0Config::DEFAULT;
            let fast_out = solve(&dict, &cfg, &mut ws).unwrap();
            let fast = ws.patch().to_vec();
            let op = PinvOperator::new(
                &dict,
                &mask.kronecker_phi::<Fixed<PS>, Fixed<PT>, Fixed<PU>, Fixed<PV>>(0, 0).unwrap(),
            )
            .unwrap();
            let pinv_out = solve_pinv(&op, &cfg, &mut ws).unwrap();
            let e = rel_err32(ws.patch(), &fast);
            assert!(e <= 1e-4, "dict {dseed} k {k}: fast vs pinv rel diff {e}");
            assert!((fast_out.sigma0 - pinv_out.sigma0).abs() <= 1e-5 * fast_out.sigma0);
            assert_eq!(fast_out.iterations, pinv_out.iterations);
        }
    }
}

#[test]
fn fast_path_equals_pinv_path_paper_patch() {
    fast_equals_pinv::<5, 5, 4, 4, 5200>();
}

#[test]
fn fast_path_equals_pinv_path_full_view_patch() {
    fast_equals_pinv::<5, 5, 5, 5, 8125>();
}

#[test]
fn pinv_path_needs_the_kronecker_measurements() {
    let dict = Dictionary::<PaperShape>::dct();
    let mask = Mask::kronecker(1, 2, 13, L5, (5, 5)).unwrap();
    let op =
        PinvOperator::new(&dict, &mask.kronecker_phi::<Fixed<5>, Fixed<5>, Fixed<4>, Fixed<4>>(0, 0).unwrap()).unwrap();
    let truth = smooth_patch::<PaperShape>(1);
    let mut w = ws();
    // Measured with a pixel mask: not what this Phi selects.
    measure(&Mask::pixel(1, 2, 13, L5).unwrap(), (0, 0), &truth, &mut w);
    assert_eq!(solve_pinv(&op, &Sl0Config::DEFAULT, &mut w).unwrap_err(), SolveError::IncompleteKronecker);
    // One measurement missing.
    measure(&mask, (0, 0), &truth, &mut w);
    assert!(solve_pinv(&op, &Sl0Config::DEFAULT, &mut w).is_ok());
    let first = (0..5200).find(|&i| w.measurements().get(i).is_some()).unwrap();
    let mut w2 = ws();
    for i in (0..5200).filter(|&i| i != first) {
        if let Some(y) = w.measurements().get(i) {
            w2.measurements_mut().set(i, y).unwrap();
        }
    }
    assert_eq!(solve_pinv(&op, &Sl0Config::DEFAULT, &mut w2).unwrap_err(), SolveError::IncompleteKronecker);
}

/// k = 13 measures every band of every pixel: the decode is the patch itself.
fn all_bands_reproduce<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const N: usize>() {
    let dict = Dictionary::<PatchShape<PS, PT, PU, PV, 13, N>>::dct();
    let truth = smooth_patch::<PatchShape<PS, PT, PU, PV, 13, N>>(9);
    let all = [
        Mask::kronecker(1, 13, 13, L5, (PS as u8, PT as u8)).unwrap(),
        Mask::lenslet(2, 13, 13, L5).unwrap(),
        Mask::pixel(3, 13, 13, L5).unwrap(),
    ];
    for mask in all {
        let mut w = Box::new(Workspace::<PatchShape<PS, PT, PU, PV, 13, N>>::new());
        measure(&mask, (5, 10), &truth, &mut w);
        assert_eq!(w.measurements().count(), N);
        let out = solve(&dict, &Sl0Config::DEFAULT, &mut w).unwrap();
        let e = max_abs_diff(w.patch(), &truth);
        assert!(e <= 1e-5, "{:?}: max abs diff {e}", mask.family());
        assert!(!out.hit_bound());
    }
}

#[test]
fn all_thirteen_bands_reproduce_the_patch() {
    all_bands_reproduce::<5, 5, 4, 4, 5200>();
    all_bands_reproduce::<5, 5, 5, 5, 8125>();
}

#[test]
fn bad_config_is_a_typed_error() {
    let dict = Dictionary::<PaperShape>::dct();
    let mut w = ws();
    w.measurements_mut().set(0, 0.5).unwrap();
    let d = Sl0Config::DEFAULT;
    for (cfg, field) in [
        (Sl0Config { sigma_f: 1.0, ..d }, "sigma_f"),
        (Sl0Config { sigma_f: f32::NAN, ..d }, "sigma_f"),
        (Sl0Config { steps: 0, ..d }, "steps"),
        (Sl0Config { mu: -1.0, ..d }, "mu"),
        (Sl0Config { sigma_min: 0.0, ..d }, "sigma_min"),
        (Sl0Config { max_iterations: 0, ..d }, "max_iterations"),
        (Sl0Config { noise: f32::INFINITY, ..d }, "noise"),
        (Sl0Config { tolerance: -1e-3, ..d }, "tolerance"),
        (Sl0Config { tolerance: f32::NAN, ..d }, "tolerance"),
        (Sl0Config { warm_start: 0.0, ..d }, "warm_start"),
        (Sl0Config { warm_start: 1.5, ..d }, "warm_start"),
        (Sl0Config { warm_start: f32::NAN, ..d }, "warm_start"),
        (Sl0Config { warm_sigma_f: 0.0, ..d }, "warm_sigma_f"),
        (Sl0Config { warm_sigma_f: 1.0, ..d }, "warm_sigma_f"),
        (Sl0Config { warm_sigma_f: f32::NAN, ..d }, "warm_sigma_f"),
        (Sl0Config { warm_steps: 0, ..d }, "warm_steps"),
        (Sl0Config { flat: -1.0, ..d }, "flat"),
        (Sl0Config { flat: f32::INFINITY, ..d }, "flat"),
    ] {
        assert_eq!(solve(&dict, &cfg, &mut w).unwrap_err(), SolveError::InvalidConfig { field });
    }
    assert_eq!(w.measurements_mut().set(5200, 1.0), Err(SolveError::IndexOutOfRange));
    assert_eq!(w.measurements_mut().set(3, f32::NAN), Err(SolveError::NonFiniteMeasurement));
    assert_eq!(w.measurements().count(), 1);
}

/// Tests that every patch configuration must pass, instantiated for the paper's patch and
/// for every view of a 5 x 5-pixel lenslet.
macro_rules! shape_suite {
    ($name:ident, $pu:literal, $pv:literal, $n:literal) => {
        mod $name {
            use super::*;

            const PU: usize = $pu;
            const PV: usize = $pv;
            const N: usize = $n;
            type Shape = PatchShape<5, 5, PU, PV, 13, N>;
            type Dict = Dictionary<PatchShape<5, 5, PU, PV, 13, N>>;

            fn wsn() -> Box<Workspace<PatchShape<5, 5, PU, PV, 13, N>>> {
                Box::new(Workspace::new())
            }

            /// A patch made of a few random DCT atoms.
            fn sparse_patch(seed: u64, atoms: usize) -> Vec<f32> {
                let dict = Dict::dct();
                let mut r = rng(seed);
                let mut s = Box::new([0.0f32; N]);
                s[0] = 20.0; // a DC level: a positive patch of mean ~0.28
                for _ in 0..atoms {
                    s[r.random_range(1..5200)] =
                        r.random_range(0.5f32..2.0) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
                }
                let mut x = Box::new([0.0f32; N]);
                slf_firmware::transform::synthesize(&dict, &mut s, &mut x);
                x.to_vec()
            }

            #[test]
            fn sparse_patch_is_recovered_from_pixel_mask_k3() {
                let dict = Dict::dct();
                let mask = Mask::pixel(77, 3, 13, L5).unwrap();
                for seed in 0..3 {
                    let truth = sparse_patch(seed, 12);
                    let mut w = wsn();
                    measure(&mask, (0, 0), &truth, &mut w);
                    let cfg = Sl0Config { sigma_min: 1e-4, ..Sl0Config::DEFAULT };
                    let out = solve(&dict, &cfg, &mut w).unwrap();
                    let e = rel_err32(w.patch(), &truth);
                    assert!(e <= 1e-3, "seed {seed}: rel err {e} after {out:?}");
                }
            }

            #[test]
            fn pixel_mask_beats_kronecker_mask_on_a_smooth_patch() {
                // docs/design.md, section 3: one band per patch per snapshot leaves PD fully coherent.
                let dict = Dict::dct();
                let mut errs = [0.0; 3];
                for seed in 0..3 {
                    let truth = smooth_patch::<PatchShape<5, 5, PU, PV, 13, N>>(40 + seed);
                    for (e, mask) in errs.iter_mut().zip(masks(3)) {
                        let mut w = wsn();
                        measure(&mask, (0, 0), &truth, &mut w);
                        solve(&dict, &Sl0Config::DEFAULT, &mut w).unwrap();
                        *e += rel_err32(w.patch(), &truth);
                    }
                }
                let [kron, _lenslet, pixel] = errs;
                assert!(pixel * 3.0 < kron, "pixel {pixel} vs kronecker {kron}");
            }

            #[test]
            fn noise_aware_mode_stays_on_the_noise_ball_and_fits_less_noise() {
                let dict = Dict::dct();
                let mask = Mask::pixel(5, 3, 13, L5).unwrap();
                let noise = 0.02f32;
                let mut err = [0.0f64; 2];
                for seed in 0..3u64 {
                    let truth = smooth_patch::<PatchShape<5, 5, PU, PV, 13, N>>(60 + seed);
                    let mut w = wsn();
                    measure(&mask, (0, 0), &truth, &mut w);
                    let mut r = rng(seed);
                    for i in 0..N {
                        if let Some(y) = w.measurements().get(i) {
                            // Uniform noise of standard deviation `noise`.
                            let n = r.random_range(-1.0f32..1.0) * noise * 3f32.sqrt();
                            w.measurements_mut().set(i, y + n).unwrap();
                        }
                    }
                    let noisy: Vec<(usize, f32)> =
                        (0..N).filter_map(|i| w.measurements().get(i).map(|y| (i, y))).collect();
                    for (mode, e) in err.iter_mut().enumerate() {
                        let cfg = Sl0Config { noise: if mode == 1 { noise } else { 0.0 }, ..Sl0Config::DEFAULT };
                        solve(&dict, &cfg, &mut w).unwrap();
                        let p = w.patch();
                        let r2: f32 = noisy.iter().map(|&(i, y)| (p[i] - y).powi(2)).sum();
                        let eps = cfg.noise * (noisy.len() as f32).sqrt();
                        assert!(
                            r2.sqrt() <= eps * 1.0001 + 1e-5,
                            "mode {mode}: residual {} above eps {eps}",
                            r2.sqrt()
                        );
                        *e += rel_err32(p, &truth);
                    }
                }
                assert!(err[1] < err[0], "noise-aware {} not below exact {}", err[1], err[0]);
            }

            #[test]
            fn the_iteration_bound_is_honoured_and_reported() {
                let dict = Dict::dct();
                let truth = smooth_patch::<PatchShape<5, 5, PU, PV, 13, N>>(3);
                let mut w = wsn();
                measure(&masks(1)[2], (0, 0), &truth, &mut w);
                let cfg = Sl0Config { max_iterations: 7, ..Sl0Config::DEFAULT };
                let out = solve(&dict, &cfg, &mut w).unwrap();
                assert_eq!(out.iterations, 7);
                assert!(out.hit_bound());
                assert_eq!(out.ended, Ended::IterationBound);
                let out = solve(&dict, &Sl0Config::DEFAULT, &mut w).unwrap();
                assert_eq!(out.ended, Ended::SigmaMin);
                // Levels: sigma0 * sigma_f^levels <= sigma_min < sigma0 * sigma_f^(levels-1).
                let c = Sl0Config::DEFAULT;
                let expect = ((c.sigma_min / out.sigma0).ln() / c.sigma_f.ln()).ceil() as u32;
                assert!(out.levels.abs_diff(expect) <= 1, "levels {} vs {expect}", out.levels);
                assert_eq!(out.iterations, out.levels * u32::from(c.steps));
            }

            // ---- Hard cases: finite output, the bound honoured, and an error bound or a typed error.

            /// Decodes `truth` through `mask` and checks the invariants every hard case shares:
            /// finite output, the iteration bound, consistency with every measurement, and no
            /// amplification (|output| <= 1.5 max |measurement|; measured at most 1.22 over these
            /// cases and all three families). Returns the relative error against the truth.
            fn decode_checked(truth: &[f32], mask: &Mask, cfg: &Sl0Config) -> (f64, Vec<f32>) {
                let dict = Dict::dct();
                let mut w = wsn();
                measure(mask, (0, 0), truth, &mut w);
                let out = solve(&dict, cfg, &mut w).unwrap();
                let p = w.patch();
                assert!(p.iter().all(|x| x.is_finite()), "non-finite output");
                assert!(out.iterations <= cfg.max_iterations);
                let max_y = (0..N).filter_map(|i| w.measurements().get(i)).fold(0.0f32, |m, y| m.max(y.abs()));
                for (i, &x) in p.iter().enumerate() {
                    if let Some(y) = w.measurements().get(i) {
                        assert!((x - y).abs() <= 1e-5 * max_y.max(f32::MIN_POSITIVE), "entry {i}: {x} vs measured {y}");
                    }
                }
                let max_out = p.iter().fold(0.0f32, |m, x| m.max(x.abs()));
                assert!(max_out <= 1.5 * max_y, "{:?}: output {max_out} vs measurements {max_y}", mask.family());
                (rel_err32(p, truth), p.to_vec())
            }

            /// The error bound of a hard case. Pixel and lenslet masks see several bands per patch and
            /// stay within the signal's own norm (measured at most 0.80). The kronecker mask gives
            /// every pixel of a patch the same bands, so any spectral atom explains the data equally
            /// (docs/design.md, section 3): its bound only says the guess is no wilder than the signal
            /// (measured at most 1.22).
            fn error_bound(mask: &Mask) -> f64 {
                match mask.family() {
                    MaskFamily::Kronecker => 1.5,
                    MaskFamily::Lenslet | MaskFamily::Pixel => 1.0,
                }
            }

            fn check_hard_case(name: &str, truth: &[f32]) {
                for k in [1, 3] {
                    for mask in masks(k) {
                        let (e, _) = decode_checked(truth, &mask, &Sl0Config::DEFAULT);
                        assert!(e <= error_bound(&mask), "{name} {:?} k {k}: rel err {e}", mask.family());
                    }
                }
            }

            #[test]
            fn hard_all_zero_patch_decodes_to_zero() {
                for mask in masks(1) {
                    let (_, p) = decode_checked(&[0.0; N], &mask, &Sl0Config::DEFAULT);
                    assert!(p.iter().all(|&x| x == 0.0));
                }
            }

            #[test]
            fn hard_constant_patch_is_recovered() {
                check_hard_case("constant", &[0.37; N]);
                // Where the mask sees more than one band per patch, a constant (one DCT atom) is exact.
                for k in [1, 3] {
                    for mask in &masks(k)[1..] {
                        let (e, _) = decode_checked(&[0.37; N], mask, &Sl0Config::DEFAULT);
                        assert!(e <= 1e-3, "{:?} k {k}: rel err {e}", mask.family());
                    }
                }
            }

            #[test]
            fn hard_one_bright_pixel_stays_bounded() {
                let mut truth = vec![0.01f32; N];
                truth[Shape::index(2, 3, 1, 2, 6)] = 1.0;
                check_hard_case("bright pixel", &truth);
            }

            #[test]
            fn hard_full_scale_checkerboards_stay_bounded() {
                let spatial: Vec<f32> = (0..N).map(Shape::coordinates).map(|[s, t, ..]| ((s + t) % 2) as f32).collect();
                let spectral: Vec<f32> = (0..N).map(|i| (Shape::coordinates(i)[4] % 2) as f32).collect();
                check_hard_case("spatial checkerboard", &spatial);
                check_hard_case("spectral checkerboard", &spectral);
                // A pixel mask resolves a spatial checkerboard even from one snapshot.
                let (e, _) = decode_checked(&spatial, &masks(1)[2], &Sl0Config::DEFAULT);
                assert!(e <= 1e-3, "pixel k 1 spatial checkerboard: rel err {e}");
            }

            #[test]
            fn hard_values_spanning_1e6_to_1() {
                // Log-spaced over six decades along the bands, times a smooth spatial factor.
                let truth: Vec<f32> = (0..N)
                    .map(|i| {
                        let [s, t, _, _, b] = Shape::coordinates(i);
                        10f32.powf(-6.0 + 6.0 * b as f32 / 12.0) * (0.5 + 0.1 * (s + t) as f32)
                    })
                    .collect();
                check_hard_case("1e-6..1", &truth);
                // Every band measured: reproduced to f32 precision across all six decades.
                let (e, _) = decode_checked(&truth, &Mask::pixel(1, 13, 13, L5).unwrap(), &Sl0Config::DEFAULT);
                assert!(e <= 1e-6, "k = 13 rel err {e}");
            }

            #[test]
            fn hard_sigma_min_below_f32_resolution() {
                let truth = smooth_patch::<PatchShape<5, 5, PU, PV, 13, N>>(8);
                for sigma_min in [1e-30f32, f32::MIN_POSITIVE, 1e-45] {
                    for max_iterations in [100_000, 50] {
                        let cfg = Sl0Config { sigma_min, max_iterations, ..Sl0Config::DEFAULT };
                        let (e, _) = decode_checked(&truth, &masks(3)[2], &cfg);
                        assert!(e <= 0.1, "sigma_min {sigma_min}: rel err {e}");
                    }
                }
                let dict = Dict::dct();
                let mut w = wsn();
                measure(&masks(3)[2], (0, 0), &truth, &mut w);
                let cfg = Sl0Config { sigma_min: 1e-45, max_iterations: 100_000, ..Sl0Config::DEFAULT };
                let out = solve(&dict, &cfg, &mut w).unwrap();
                assert_eq!(out.ended, Ended::SigmaUnderflow);
                assert!(out.iterations < 1000);
            }

            #[test]
            fn hard_no_measurement_is_a_typed_error() {
                let dict = Dict::dct();
                let mut w = wsn();
                assert_eq!(solve(&dict, &Sl0Config::DEFAULT, &mut w).unwrap_err(), SolveError::NoMeasurements);
            }

            #[test]
            fn hard_single_measurement_is_bounded() {
                let dict = Dict::dct();
                let mut w = wsn();
                w.measurements_mut().set(Shape::index(4, 4, 3, 3, 12), 0.8).unwrap();
                solve(&dict, &Sl0Config::DEFAULT, &mut w).unwrap();
                let p = w.patch();
                assert!(p.iter().all(|x| x.is_finite() && x.abs() <= 0.8 + 1e-6));
                assert_eq!(p[Shape::index(4, 4, 3, 3, 12)], 0.8);
            }
        }
    };
}

shape_suite!(paper_patch, 4, 4, 5200);
shape_suite!(full_view_patch, 5, 5, 8125);

/// Shot noise: each measurement's variance is `noise^2 + shot * y`. With the noise
/// described, the solve ends inside the weighted ball `sum r^2 / var <= m - p + p / 16`
/// (checked in f64 against the noisy measurements), on both projection paths' shared
/// final projection, and lands nearer the truth than the exact projection at three
/// snapshots; at one snapshot the ball is `p / 16`.
#[test]
fn weighted_noise_ball_holds_the_solution_and_fits_less_noise() {
    let dict = Dictionary::<PaperShape>::dct();
    let (noise, shot) = (0.002f32, 1.0 / 500.0); // a dim sensor: 500 electrons at white
    for k in [1u8, 3] {
        let mask = Mask::pixel(31, k, 13, L5).unwrap();
        let mut err = [0.0f64; 2];
        for seed in 0..3u64 {
            let truth = smooth_patch::<PaperShape>(70 + seed);
            let mut w = ws();
            measure(&mask, (0, 0), &truth, &mut w);
            let mut r = rng(seed);
            let mut noisy = Vec::new();
            for i in 0..5200 {
                if let Some(y) = w.measurements().get(i) {
                    let sd = (noise * noise + shot * y).sqrt();
                    let n = r.random_range(-1.0f32..1.0) * sd * 3f32.sqrt();
                    w.measurements_mut().set(i, y + n).unwrap();
                    noisy.push((i, y + n));
                }
            }
            let pixels = noisy.iter().map(|&(i, _)| i / 13).collect::<std::collections::BTreeSet<_>>().len();
            let radius2 = (noisy.len() - pixels) as f64 + pixels as f64 / 16.0;
            for (mode, e) in err.iter_mut().enumerate() {
                let cfg = if mode == 1 { Sl0Config { noise, shot, ..Sl0Config::DEFAULT } } else { Sl0Config::DEFAULT };
                solve(&dict, &cfg, &mut w).unwrap();
                let p = w.patch();
                let white2: f64 = noisy
                    .iter()
                    .map(|&(i, y)| {
                        let var = f64::from(noise).powi(2) + f64::from(shot) * f64::from(y).max(0.0);
                        (f64::from(p[i]) - f64::from(y)).powi(2) / var
                    })
                    .sum();
                let bound = if mode == 1 { radius2 } else { 0.0 };
                assert!(white2 <= bound * 1.001 + 1e-6, "k {k} mode {mode}: whitened residual^2 {white2} over {bound}");
                *e += rel_err32(p, &truth);
            }
        }
        if k == 3 {
            assert!(err[1] < err[0], "k 3: noise-aware {} not below exact {}", err[1], err[0]);
        }
    }
}
