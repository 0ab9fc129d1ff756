//! Member choice: the rules against slow references, the cost of each mode in solves,
//! and the choice finding the member a patch was made from.

mod common;

use common::*;
use rand::Rng;
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

fn blob(members: &[Dictionary<5, 5, 4, 4, 13>]) -> &'static [u8] {
    let mut out = vec![0u8; blob::blob_len([5, 5, 4, 4, 13], members.len())];
    write_blob(members, &mut out).unwrap();
    Box::leak(out.into_boxed_slice())
}

/// A patch of a few atoms of `dict` plus a DC level.
fn sparse_in(dict: &Dictionary<5, 5, 4, 4, 13>, seed: u64) -> Vec<f32> {
    let mut r = rng(seed);
    let mut s = Box::new([0.0f32; 5200]);
    for _ in 0..15 {
        s[r.random_range(0..5200)] = r.random_range(1.0f32..3.0) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
    }
    let mut x = Box::new([0.0f32; 5200]);
    synthesize(dict, &mut s, &mut x);
    x.to_vec()
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
    let e = Ensemble::<5, 5, 4, 4, 13>::new(blob(&members)).unwrap();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    for (choice, solves) in [
        (MemberChoice::Exhaustive(ChoiceRule::DEFAULT), &[5u16][..]),
        (MemberChoice::Screened(ChoiceRule::DEFAULT), &[2, 3][..]),
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
            if let (MemberChoice::Screened(_), true) = (choice, m > 0) {
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
        Ensemble::<5, 5, 4, 4, 13>::new(DEFAULT_ENSEMBLE).unwrap(),
        MemberChoice::Screened(ChoiceRule::DEFAULT),
    );
    let truth = smooth_patch::<5, 5, 4, 4, 13, 5200>(4);
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let mut ws = Box::new(PaperWorkspace::new());
    measure(&mask, (0, 0), &truth, &mut ws);
    let out = model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert!(out.member.is_some_and(|m| m < 8));
    assert!(ws.patch().iter().all(|x| x.is_finite()));
    // A single dictionary is a model too: one solve, no member.
    let out = Dictionary::<5, 5, 4, 4, 13>::dct().decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!((out.solves, out.member), (1, None));
    // No measurement: the typed error comes through the model.
    ws.measurements_mut().clear();
    assert_eq!(model.decode(&Sl0Config::DEFAULT, &mut ws).unwrap_err(), SolveError::NoMeasurements);
}
