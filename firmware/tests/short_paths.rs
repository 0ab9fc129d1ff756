//! Modelling only what a patch needs: the early stop, the warm start and the flat short
//! path, each against the full solve it shortens.

mod common;

use common::*;
use slf_firmware::sl0::solve_warm;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
type Ws = PaperWorkspace;

fn measured(truth: &[f32], k: u8) -> Box<Ws> {
    let mut ws = Box::new(Ws::new());
    measure(&Mask::pixel(5, k, 13, L5).unwrap(), (0, 0), truth, &mut ws);
    ws
}

/// Largest difference between the patch and the measurements it must meet.
fn misfit(ws: &Ws) -> f32 {
    (0..5200).filter_map(|i| ws.measurements().get(i).map(|y| (ws.patch()[i] - y).abs())).fold(0.0, f32::max)
}

fn dct() -> Dictionary<PaperShape> {
    Dictionary::dct()
}

/// Tolerance 0 is the plain schedule; a loose tolerance ends the solve early with
/// `Converged`, still on the measurements and finite, at a bounded cost in error.
#[test]
fn early_stop_ends_when_the_patch_stops_moving() {
    let truth = smooth_patch::<PaperShape>(3);
    let mut ws = measured(&truth, 3);
    let full = solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!(full.ended, Ended::SigmaMin);
    let full_err = rel_err32(ws.patch(), &truth);
    let mut last = full.iterations;
    for tolerance in [1e-5f32, 1e-4, 1e-3, 1e-2] {
        let cfg = Sl0Config { tolerance, ..Sl0Config::DEFAULT };
        let out = solve(&dct(), &cfg, &mut ws).unwrap();
        assert!(out.iterations <= last, "a looser tolerance never takes longer");
        last = out.iterations;
        if out.ended == Ended::Converged {
            assert!(out.iterations < full.iterations);
            assert_eq!(out.iterations % 3, 0, "stops at the end of a level");
        } else {
            assert_eq!(out, full);
        }
        assert!(ws.patch().iter().all(|x| x.is_finite()));
        assert!(misfit(&ws) <= 1e-5, "{tolerance}: misfit {}", misfit(&ws));
        let err = rel_err32(ws.patch(), &truth);
        assert!(err <= full_err + 20.0 * f64::from(tolerance) + 1e-6, "{tolerance}: {err} vs {full_err}");
    }
    assert!(last < full.iterations / 2, "at 1e-2 RMS the smooth patch stops early: {last} steps");
}

/// The solver's movement measure, |d|^2 - residual^2, against the patch's actual movement
/// over each level, measured directly by solving level by level (`max_iterations` = L,
/// 2L, ...) and differencing the patches: the two agree where it matters, at the stop.
#[test]
fn early_stop_measures_movement_like_the_obvious_difference() {
    let truth = smooth_patch::<PaperShape>(7);
    let mut ws = measured(&truth, 1);
    let base = Sl0Config::DEFAULT;
    // Patch after every level, by bounded solves (the schedule is deterministic).
    let mut patches = Vec::new();
    for levels in 1..=30u32 {
        let cfg = Sl0Config { max_iterations: 3 * levels, ..base };
        let out = solve(&dct(), &cfg, &mut ws).unwrap();
        patches.push(ws.patch().to_vec());
        if out.ended != Ended::IterationBound {
            break;
        }
    }
    let rms =
        |a: &[f32], b: &[f32]| (a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum::<f64>() / 5200.0).sqrt();
    let moves: Vec<f64> = patches.windows(2).map(|w| rms(&w[0], &w[1])).collect();
    let mut checked = 0;
    for tolerance in [3e-3f32, 1e-3, 3e-4] {
        let out = solve(&dct(), &Sl0Config { tolerance, ..base }, &mut ws).unwrap();
        if out.ended != Ended::Converged {
            continue;
        }
        checked += 1;
        // Level l (1-based) ended the solve: it moved less than the tolerance (the
        // solver sums its steps, an upper bound of the level's movement).
        let l = out.levels as usize;
        assert!(moves[l - 2] < f64::from(tolerance) * 1.01, "{tolerance}: level {l} moved {}", moves[l - 2]);
    }
    assert!(checked >= 2, "the loose tolerances stop this patch early");
}

/// A warm start from another dictionary's patch meets the measurements, stays finite,
/// takes fewer steps than a cold solve, and from the same dictionary's own solution
/// changes it little.
#[test]
fn warm_start_resumes_from_the_patch_in_the_workspace() {
    let truth = smooth_patch::<PaperShape>(9);
    let mut ws = measured(&truth, 3);
    let cfg = Sl0Config::DEFAULT;
    let cold = solve(&random_dictionary::<PaperShape>(3), &cfg, &mut ws).unwrap();
    let warm = solve_warm(&dct(), &cfg, &mut ws).unwrap();
    assert!(warm.iterations < cold.iterations, "{} vs {}", warm.iterations, cold.iterations);
    assert!(misfit(&ws) <= 1e-5);
    assert!(ws.patch().iter().all(|x| x.is_finite()));
    // Warm from the DCT's own solution: a small correction only.
    solve(&dct(), &cfg, &mut ws).unwrap();
    let own = ws.patch().to_vec();
    solve_warm(&dct(), &cfg, &mut ws).unwrap();
    assert!(rel_err32(ws.patch(), &own) < 0.02, "{}", rel_err32(ws.patch(), &own));
    // warm_start 1 starts where a cold start would from this patch: bounded like any solve.
    let out = solve_warm(&dct(), &Sl0Config { warm_start: 1.0, max_iterations: 9, ..cfg }, &mut ws).unwrap();
    assert_eq!((out.iterations, out.ended), (9, Ended::IterationBound));
    // The warm schedule: from its sigma0, `warm_steps` steps a level, sigma falling by
    // `warm_sigma_f` until `sigma_min`; the level count from an f64 recount of the same
    // schedule (f32 sigma may land one level either side of an exact boundary: none here).
    for (sigma_f, steps) in [(0.85f32, 1u16), (0.6, 2), (0.7, 3)] {
        let c = Sl0Config { warm_sigma_f: sigma_f, warm_steps: steps, ..cfg };
        let out = solve_warm(&dct(), &c, &mut ws).unwrap();
        let mut levels = 0u32;
        let mut sigma = f64::from(out.sigma0);
        while sigma > f64::from(c.sigma_min) {
            sigma *= f64::from(sigma_f);
            levels += 1;
        }
        assert_eq!(out.ended, Ended::SigmaMin);
        assert_eq!((out.levels, out.iterations), (levels, levels * u32::from(steps)), "{sigma_f} L {steps}");
        // The cold schedule is the main one, whatever the warm one is.
        let cold = solve(&dct(), &c, &mut ws).unwrap();
        assert_eq!(cold.iterations, cold.levels * u32::from(c.steps));
    }
    // No measurement: the typed error, as for a cold solve.
    ws.measurements_mut().clear();
    assert_eq!(solve_warm(&dct(), &cfg, &mut ws).unwrap_err(), SolveError::NoMeasurements);
}

/// A patch flat in space and view (any spectrum) takes the short path: no step, every
/// value exactly its band's level, measurements met.
#[test]
fn flat_patches_take_the_short_path() {
    let spectrum = |b: usize| 0.1 + 0.05 * b as f32;
    let truth: Vec<f32> = (0..5200).map(|i| spectrum(i % 13)).collect();
    for k in [1u8, 3] {
        let mut ws = measured(&truth, k);
        let out = solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap();
        assert_eq!((out.ended, out.iterations), (Ended::Flat, 0));
        for (i, (x, t)) in ws.patch().iter().zip(&truth).enumerate() {
            assert!((x - t).abs() <= 1e-6, "k {k} value {i}: {x} vs {t}");
        }
    }
    // The ensemble stops after its first solve.
    let model = EnsembleModel::new(
        Ensemble::<PaperShape>::new(DEFAULT_ENSEMBLE).unwrap(),
        MemberChoice::Screened(ChoiceRule::DEFAULT),
    );
    let mut ws = measured(&truth, 3);
    let out = model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!((out.solves, out.outcome.ended), (1, Ended::Flat));
}

/// Spread above `flat` in any band, or a band never measured, means a full solve; a dark
/// patch within `flat` is decoded to within `flat` of the truth.
#[test]
fn the_short_path_only_takes_flat_patches() {
    let mut truth: Vec<f32> = (0..5200).map(|i| 0.3 + 0.01 * (i % 13) as f32).collect();
    truth[13 * 77 + 4] += 1e-4;
    let mut ws = measured(&truth, 13);
    assert_eq!(solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap().ended, Ended::SigmaMin);
    let loose = Sl0Config { flat: 2e-4, ..Sl0Config::DEFAULT };
    assert_eq!(solve(&dct(), &loose, &mut ws).unwrap().ended, Ended::Flat);
    // Band 5 never measured: a flat short path cannot know its level.
    let mut ws = Box::new(Ws::new());
    for i in (0..5200).filter(|i| i % 13 != 5) {
        ws.measurements_mut().set(i, 0.25).unwrap();
    }
    assert_ne!(solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap().ended, Ended::Flat);
    // Dark: values 0..1e-3 with any structure; within flat 1e-3 the short path's error is
    // below flat everywhere.
    let dark: Vec<f32> = (0..5200).map(|i| 1e-3 * ((i * 37 % 101) as f32 / 100.0)).collect();
    let mut ws = measured(&dark, 3);
    let cfg = Sl0Config { flat: 1e-3, ..Sl0Config::DEFAULT };
    assert_eq!(solve(&dct(), &cfg, &mut ws).unwrap().ended, Ended::Flat);
    assert!(ws.patch().iter().zip(&dark).all(|(x, t)| (x - t).abs() <= 1e-3));
    // Values whose band sums leave f32's range go to the full solve, which reports them.
    let mut ws = measured(&vec![3e38f32; 5200], 3);
    assert_eq!(solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap_err(), SolveError::NonFiniteResult);
}

/// The band-gain fill is exact for a patch of one spectrum at one brightness, keeps every
/// measurement, and is its definition elsewhere: each unmeasured value is its pixel's gain
/// times its band's mean, checked against a direct f64 computation on a random patch.
#[test]
fn the_band_gain_fill_is_its_definition_and_exact_for_one_spectrum() {
    use slf_firmware::solver::fill::fill_bands;
    let spectrum: Vec<f32> = (0..13).map(|b| 0.2 + 0.05 * b as f32).collect();
    let truth: Vec<f32> = (0..5200).map(|i| 0.7 * spectrum[i % 13]).collect();
    let ws = measured(&truth, 1);
    let mut out = [0.0f32; 5200];
    fill_bands::<PaperShape>(ws.measurements(), &mut out);
    let worst = out.iter().zip(&truth).map(|(a, b)| (a - b).abs() / b).fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "one spectrum is filled to {worst} relative");

    // Any patch: against f64 sums of the definition.
    let noisy: Vec<f32> = (0..5200).map(|i| 0.1 + 0.8 * ((i * 7919 % 1009) as f32 / 1009.0)).collect();
    let ws = measured(&noisy, 1);
    let m = ws.measurements();
    fill_bands::<PaperShape>(m, &mut out);
    let (mut sum, mut count) = ([0.0f64; 13], [0u32; 13]);
    for i in 0..5200 {
        if let Some(y) = m.get(i) {
            sum[i % 13] += f64::from(y);
            count[i % 13] += 1;
        }
    }
    assert!(count.iter().all(|&c| c > 0), "a 5 x 5 x 4 x 4 patch at k = 1 sees every band");
    let mean: Vec<f64> = (0..13).map(|b| sum[b] / f64::from(count[b])).collect();
    for p in 0..400 {
        let own: Vec<usize> = (0..13).filter(|&b| m.get(p * 13 + b).is_some()).collect();
        // The ratio of the pixel's measurements to its bands' means, each plus FLOOR a band.
        let floor = f64::from(slf_firmware::solver::fill::FLOOR) * own.len() as f64;
        let gain = if own.is_empty() {
            1.0
        } else {
            (own.iter().map(|&b| f64::from(m.get(p * 13 + b).unwrap())).sum::<f64>() + floor)
                / (own.iter().map(|&b| mean[b]).sum::<f64>() + floor)
        };
        for b in 0..13 {
            let want = m.get(p * 13 + b).map_or(gain * mean[b], f64::from);
            let got = f64::from(out[p * 13 + b]);
            assert!((got - want).abs() <= 1e-5 * want.abs().max(1.0), "pixel {p} band {b}: {got} vs {want}");
        }
    }

    // A dark patch: noise about the black level (some of it below) in most bands, one
    // band bright. A pixel whose bands' means are near nothing is filled near the patch's
    // means, not at its noise over theirs (issue 49: 200 times, the start of a diverged
    // solve).
    let dark: Vec<f32> = (0..5200)
        .map(|i| if i % 13 == 12 { 0.3 } else { 0.004 * (((i / 13 * 7919) % 1009) as f32 / 1009.0 - 0.5) })
        .collect();
    let ws = measured(&dark, 1);
    fill_bands::<PaperShape>(ws.measurements(), &mut out);
    let top = out.iter().fold(0.0f32, |a, &x| a.max(x.abs()));
    assert!(top <= 0.6, "the dark patch is filled up to {top}");
}

/// A cold solve from the fill (`cold_start` 0.05 and below: the fill's DC is about 13 times
/// the zero-filled start's) meets the measurements, starts lower and so takes fewer steps
/// than from the minimum-norm start, and on a smooth patch (which the
/// fill nearly is) decodes within a small margin of the full schedule's error; `cold_start`
/// outside (0, 1] is refused by name.
#[test]
fn a_cold_solve_from_the_fill_takes_fewer_steps_and_meets_the_measurements() {
    let truth = smooth_patch::<PaperShape>(3);
    let mut ws = measured(&truth, 1);
    let full = solve(&dct(), &Sl0Config::DEFAULT, &mut ws).unwrap();
    let full_err = rel_err32(ws.patch(), &truth);
    for cold_start in [0.05f32, 0.03, 0.01] {
        let cfg = Sl0Config { cold_start, ..Sl0Config::DEFAULT };
        let out = solve(&dct(), &cfg, &mut ws).unwrap();
        assert_eq!(out.ended, Ended::SigmaMin);
        assert!(out.iterations < full.iterations, "{cold_start}: {} vs {} steps", out.iterations, full.iterations);
        assert!(misfit(&ws) <= 1e-5, "{cold_start}: misfit {}", misfit(&ws));
        let err = rel_err32(ws.patch(), &truth);
        assert!(err <= 1.5 * full_err + 1e-3, "{cold_start}: {err} vs {full_err}");
    }
    for bad in [0.0f32, -0.5, 1.5, f32::NAN] {
        let cfg = Sl0Config { cold_start: bad, ..Sl0Config::DEFAULT };
        assert_eq!(solve(&dct(), &cfg, &mut ws), Err(SolveError::InvalidConfig { field: "cold_start" }));
    }
}
