//! Member choice: the rules against slow references, the cost of each mode in solves,
//! and the choice finding the member a patch was made from.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::sl0::solve_warm;
use slf_firmware::transform::analyze_preserving;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

/// Energy outside the tau largest magnitudes by sorting (the obvious way).
fn residual_by_sorting(s: &[f32], tau: usize) -> f32 {
    let mut sq: Vec<f32> = s.iter().map(|x| x * x).collect();
    sq.sort_by(|a, b| b.total_cmp(a));
    let total: f32 = sq.iter().sum();
    sq[tau..].iter().sum::<f32>() / total
}

#[test]
fn rules_match_slow_references() {
    let mut r = rng(1);
    for _ in 0..20 {
        // Heavy-tailed coefficients, like a sparse code.
        let s: Vec<f32> = (0..5200).map(|_| r.random_range(-1.0f32..1.0).powi(5)).collect();
        for tau in [1usize, 100, 260, 5199] {
            let fast = ChoiceRule::Residual { tau: tau as u16 }.score(&s);
            let slow = residual_by_sorting(&s, tau);
            assert!((fast - slow).abs() <= 1e-5 * slow.max(1e-3), "tau {tau}: {fast} vs {slow}");
        }
        let l1: f64 = s.iter().map(|&x| f64::from(x.abs())).sum();
        assert!((f64::from(ChoiceRule::L1.score(&s)) - l1).abs() <= 1e-6 * l1, "l1 {l1}");
        let count = s.iter().filter(|x| x.abs() > 0.3).count() as f32;
        assert_eq!(ChoiceRule::Count { threshold: 0.3 }.score(&s), count);
    }
    assert_eq!(ChoiceRule::Residual { tau: 10 }.score(&[0.0; 100]), 0.0);
}

/// The residual's bisection must drop the same set as sorting: every magnitude at or below
/// the `tau + 1`-th largest, ties with it included (where no threshold leaves exactly `tau`
/// above it). Checked in f64 on coarse values (many ties), sparse ones (mostly zeros) and
/// short inputs (the counts' 32 lanes and their tail).
#[test]
fn the_residual_drops_what_sorting_drops_ties_included() {
    let dropped = |s: &[f32], tau: usize| {
        let mut mags: Vec<f32> = s.iter().map(|x| x.abs()).collect();
        mags.sort_by(|a, b| b.total_cmp(a));
        let t = mags[tau];
        let sq = |x: &f32| f64::from(*x) * f64::from(*x);
        let total: f64 = s.iter().map(sq).sum();
        s.iter().filter(|x| x.abs() <= t).map(sq).sum::<f64>() / total
    };
    let mut r = rng(2);
    for case in 0..60 {
        let len = [5200usize, 5200, 63, 64, 65, 200][case % 6];
        let s: Vec<f32> = (0..len)
            .map(|_| match case % 3 {
                0 => (r.random_range(-1.0f32..1.0).powi(3) * 8.0).round() / 8.0,
                1 if r.random_range(0.0f32..1.0) < 0.9 => 0.0,
                _ => r.random_range(-1.0f32..1.0).powi(5),
            })
            .collect();
        if s.iter().all(|&x| x == 0.0) {
            continue;
        }
        for tau in [1usize, 20, 62, 100, len - 1].into_iter().filter(|&t| t < len) {
            let fast = f64::from(ChoiceRule::Residual { tau: tau as u16 }.score(&s));
            let slow = dropped(&s, tau);
            assert!((fast - slow).abs() <= 1e-5 * slow.max(1e-3), "case {case}, tau {tau}: {fast} vs {slow}");
        }
    }
}

/// With a cold second solve (`warm_start` 1) both choices find the member an exactly
/// sparse patch is made of. The default warm start (1e-2, +1.2 dB on real scenes at k = 1)
/// does not: from a DCT solution that is wrong everywhere (relative error ~1, as only
/// such a synthetic patch makes it) the member's solve starts too low to leave it, and the
/// DCT keeps the patch. That limit is asserted too, so a change to it is seen.
#[test]
fn choice_finds_the_member_a_patch_is_made_of_at_the_stated_cost() {
    let cold = Sl0Config { warm_start: 1.0, ..Sl0Config::DEFAULT };
    let members = vec![Dictionary::dct(), random_dictionary(11), random_dictionary(12), random_dictionary(13)];
    let e = Ensemble::<PaperShape>::new(blob(&members)).unwrap();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    for (choice, solves) in [
        (MemberChoice::Exhaustive(ChoiceRule::DEFAULT), &[5u16][..]),
        (MemberChoice::Screened(ChoiceRule::DEFAULT), &[2][..]),
        (MemberChoice::ScreenedResolve(ChoiceRule::DEFAULT), &[2, 3][..]),
    ] {
        let model = EnsembleModel::new(e, choice);
        assert_eq!(model.dct_member(), Some(0));
        for (m, dict) in members.iter().enumerate() {
            let truth = sparse_in(dict, 40 + m as u64);
            let mut ws = Box::new(PaperWorkspace::new());
            measure(&mask, (0, 0), &truth, &mut ws);
            let out = model.decode(&cold, &mut ws).unwrap();
            assert!(solves.contains(&out.solves), "{choice:?}: {} solves", out.solves);
            assert_eq!(out.member, Some(m as u16), "{choice:?}: patch made of member {m}");
            let e = rel_err32(ws.patch(), &truth);
            assert!(e < 0.05, "{choice:?} member {m}: rel err {e}");
            if let (MemberChoice::Screened(_) | MemberChoice::ScreenedResolve(_), true) = (choice, m > 0) {
                let out = model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
                assert_eq!(out.member, Some(0), "warm start: the DCT keeps member {m}'s patch");
                assert!(ws.patch().iter().all(|x| x.is_finite()));
            }
        }
    }
}

#[test]
fn the_shipped_ensemble_decodes_a_patch() {
    let model = EnsembleModel::new(
        Ensemble::<PaperShape>::new(DEFAULT_ENSEMBLE).unwrap(),
        MemberChoice::Screened(ChoiceRule::DEFAULT),
    );
    let truth = smooth_patch::<PaperShape>(4);
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let mut ws = Box::new(PaperWorkspace::new());
    measure(&mask, (0, 0), &truth, &mut ws);
    let out = model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert!(out.member.is_some_and(|m| m < 8));
    assert!(ws.patch().iter().all(|x| x.is_finite()));
    // A single dictionary is a model too: one solve, no member.
    let out = Dictionary::<PaperShape>::dct().decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!((out.solves, out.member), (1, None));
    // No measurement: the typed error comes through the model.
    ws.measurements_mut().clear();
    assert_eq!(model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap_err(), SolveError::NoMeasurements);
}

/// A patch of a few DCT atoms plus small white noise: the DCT's solution scores sparser
/// than a random member's, but not exactly sparse (its score is not 0).
fn dct_win_patch() -> Vec<f32> {
    let mut r = rng(77);
    let mut x = sparse_in(&Dictionary::dct(), 76);
    for v in &mut x {
        *v += r.random_range(-0.05f32..0.05);
    }
    x
}

fn score(dict: &Dictionary<PaperShape>, patch: &[f32]) -> f64 {
    let mut c = Box::new([0.0f32; 5200]);
    analyze_preserving(dict, patch.try_into().unwrap(), &mut c);
    f64::from(ChoiceRule::DEFAULT.score(&c[..]))
}

/// Screened choice where the DCT wins: the patch is the two solutions' mean, each weighted
/// by the other's score, on the unmeasured entries; the measured ones are the member's.
/// Reference: the two solves run one by one through the public API, the mean taken in
/// f64. Stated tolerance: 1e-6 of the patch's largest value (the f32 weight and mean).
#[test]
fn a_dct_win_is_the_score_weighted_mean_of_the_two_solutions() {
    let members = vec![Dictionary::dct(), random_dictionary(21)];
    let e = Ensemble::<PaperShape>::new(blob(&members)).unwrap();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let truth = dct_win_patch();
    for noise in [0.0f32, 0.02] {
        let cfg = Sl0Config { noise, ..Sl0Config::DEFAULT };
        let mut ws = Box::new(PaperWorkspace::new());
        measure(&mask, (0, 0), &truth, &mut ws);
        let mut reference = ws.clone();
        let out = EnsembleModel::new(e, MemberChoice::Screened(ChoiceRule::DEFAULT)).decode(&cfg, &mut ws).unwrap();
        assert_eq!((out.member, out.solves), (Some(0), 2), "noise {noise}: the DCT wins with two solves");

        solve(&members[0], &cfg, &mut reference).unwrap();
        let a = reference.patch().to_vec();
        let member = e.member(1).unwrap();
        let second = solve_warm(&member, &cfg, &mut reference).unwrap();
        assert_eq!(out.outcome, second, "the outcome is the member's solve");
        let b = reference.patch().to_vec();
        let (sd, sm) = (score(&members[0], &a), score(&member, &b));
        let w = sm / (sm + sd);
        // A real mean, not one side (with noise the DCT's solution is sparser still).
        let most = if noise == 0.0 { 0.99 } else { 0.999_9 };
        assert!(w > 0.5 && w < most, "noise {noise}: weight {w}");
        let m = ws.measurements();
        let expected: Vec<f64> = (0..5200)
            .map(|i| match m.get(i) {
                Some(_) => f64::from(b[i]),
                None => w * f64::from(a[i]) + (1.0 - w) * f64::from(b[i]),
            })
            .collect();
        let top = a.iter().fold(0.0f32, |t, x| t.max(x.abs()));
        for (i, (&x, &y)) in ws.patch().iter().zip(&expected).enumerate() {
            assert!((f64::from(x) - y).abs() <= 1e-6 * f64::from(top), "noise {noise}, entry {i}: {x} vs {y}");
        }
        // The mean meets the measurements as the member's solution does: exactly, or to
        // the noise ball.
        let (mut r2, mut count) = (0.0f64, 0usize);
        for i in 0..5200 {
            if let Some(y) = m.get(i) {
                r2 += (f64::from(ws.patch()[i]) - f64::from(y)).powi(2);
                count += 1;
            }
        }
        let eps = f64::from(noise) * (count as f64).sqrt();
        assert!(r2.sqrt() <= eps * (1.0 + 1e-3) + 1e-6, "noise {noise}: residual {} over {eps}", r2.sqrt());
    }
}

/// The DCT's solution waits in the measurement buffer's unmeasured slots during a screened
/// decode; afterwards the measurements are as they were, whichever solution won.
#[test]
fn a_screened_decode_leaves_the_measurements_as_they_were() {
    let members = vec![Dictionary::dct(), random_dictionary(21)];
    let e = Ensemble::<PaperShape>::new(blob(&members)).unwrap();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let mut won = [false; 2];
    for truth in [dct_win_patch(), sparse_in(&members[1], 5)] {
        for choice in [MemberChoice::Screened(ChoiceRule::DEFAULT), MemberChoice::ScreenedResolve(ChoiceRule::DEFAULT)]
        {
            let cold = Sl0Config { warm_start: 1.0, ..Sl0Config::DEFAULT };
            let mut ws = Box::new(PaperWorkspace::new());
            measure(&mask, (0, 0), &truth, &mut ws);
            let before = format!("{:?}", ws.measurements());
            let out = EnsembleModel::new(e, choice).decode(&cold, &mut ws).unwrap();
            won[usize::from(out.member.unwrap())] = true;
            assert_eq!(format!("{:?}", ws.measurements()), before, "{choice:?}, member {:?}", out.member);
        }
    }
    assert_eq!(won, [true, true], "both the DCT and the member won once");
}
