//! Seeded decodes (issue 30): a patch started from an estimate of it (its overlapping
//! neighbours' decode) with one solve. The ensemble's seeded choice against the same steps
//! run one by one through the public API, with the mean taken in f64; a seed that is the
//! truth decodes closer than a cold decode; a flat patch takes the short path; the
//! half-pixel seed's interpolation against its definition.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::choice::DCT_MARGIN;
use slf_firmware::disparity::{Disparity, HalfViews};
use slf_firmware::fractional::{from_sensor, to_sensor};
use slf_firmware::sl0::solve_seeded;
use slf_firmware::transform::analyze_preserving;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

fn score(dict: &Dictionary<PaperShape>, patch: &[f32]) -> f64 {
    let mut c = Box::new([0.0f32; 5200]);
    analyze_preserving(dict, patch.try_into().unwrap(), &mut c);
    f64::from(ChoiceRule::DEFAULT.score(&c[..]))
}

/// `truth` plus uniform noise of `amp`: an estimate as the neighbours give one.
fn estimate(truth: &[f32], amp: f32, seed: u64) -> Vec<f32> {
    let mut r = rng(seed);
    truth.iter().map(|x| x + r.random_range(-amp..amp)).collect()
}

/// The seeded screened choice step by step: the seed with its measured entries replaced,
/// each member scored on it, the best solved seeded from it, and the score-weighted mean
/// with the seed where the DCT scores `DCT_MARGIN` times sparser. Tolerance: 1e-6 of the
/// patch's largest value.
#[test]
fn a_seeded_decode_is_one_solve_from_the_seed_as_the_screened_choice_describes() {
    let members = vec![Dictionary::dct(), random_dictionary(21), random_dictionary(22)];
    let e = Ensemble::<PaperShape>::new(blob(&members)).unwrap();
    let model = EnsembleModel::new(e, MemberChoice::Screened(ChoiceRule::DEFAULT));
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let mut outcomes = [0usize; 2];
    for (case, truth) in
        [sparse_in(&members[2], 5), sparse_in(&members[0], 6), smooth_patch::<PaperShape>(7)].into_iter().enumerate()
    {
        for noise in [0.0f32, 0.01] {
            let cfg = Sl0Config { noise, ..Sl0Config::DEFAULT };
            let seed = estimate(&truth, 0.05, 30 + case as u64);
            let mut ws = Box::new(PaperWorkspace::new());
            measure(&mask, (0, 0), &truth, &mut ws);
            let mut reference = ws.clone();
            ws.patch_mut().copy_from_slice(&seed);
            let out = model.decode_seeded(&cfg, &mut ws).unwrap();
            assert_eq!(out.solves, 1, "case {case}: one solve");

            let m = reference.measurements().clone();
            let start: Vec<f32> = (0..5200).map(|i| m.get(i).unwrap_or(seed[i])).collect();
            let scores: Vec<f64> = members.iter().map(|d| score(d, &start)).collect();
            let chosen = (1..members.len()).min_by(|&a, &b| scores[a].total_cmp(&scores[b])).unwrap();
            reference.patch_mut().copy_from_slice(&start);
            let member = e.member(chosen).unwrap();
            let solved = solve_seeded(&member, &cfg, &mut reference).unwrap();
            assert_eq!(out.outcome, solved, "case {case}: the outcome is the member's solve");
            let b = reference.patch().to_vec();
            let (sd, sm) = (scores[0], score(&member, &b));
            let dct_wins = sd < f64::from(DCT_MARGIN) * sm;
            assert_eq!(out.member, Some(if dct_wins { 0 } else { chosen as u16 }), "case {case}");
            outcomes[usize::from(dct_wins)] += 1;
            let w = sm / (sm + sd);
            let expected: Vec<f64> = (0..5200)
                .map(|i| match (m.get(i), dct_wins) {
                    (None, true) => w * f64::from(start[i]) + (1.0 - w) * f64::from(b[i]),
                    _ => f64::from(b[i]),
                })
                .collect();
            let top = b.iter().fold(0.0f32, |t, x| t.max(x.abs()));
            for (i, (&x, &y)) in ws.patch().iter().zip(&expected).enumerate() {
                assert!((f64::from(x) - y).abs() <= 1e-6 * f64::from(top), "case {case}, entry {i}: {x} vs {y}");
            }
            // The measurements are as they were (the seed waited in their unmeasured slots).
            assert_eq!(ws.measurements().count(), m.count());
            assert!((0..5200).all(|i| ws.measurements().get(i) == m.get(i)), "case {case}: measurements changed");
        }
    }
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "both ends of the choice reached: {outcomes:?}");
}

/// A seed is a start: from the truth of an exactly sparse patch the seeded decode stays at
/// it (it is the sparsest patch that meets the measurements), with fewer steps than a cold
/// decode; from a seed of zeros (the measurements alone) it meets the measurements but
/// starts too low to find the patch.
#[test]
fn a_seed_is_where_the_solve_starts() {
    let dct = Dictionary::<PaperShape>::dct();
    let mask = Mask::pixel(3, 1, 13, L5).unwrap();
    for s in [11u64, 12, 13] {
        let truth: Vec<f32> = sparse_in(&dct, s).iter().map(|x| x + 0.5).collect();
        let mut ws = Box::new(PaperWorkspace::new());
        measure(&mask, (0, 0), &truth, &mut ws);
        let (mut seeded, mut zero) = (ws.clone(), ws.clone());
        let cold = dct.decode(&Sl0Config::DEFAULT, &mut ws).unwrap();
        seeded.patch_mut().copy_from_slice(&truth);
        let warm = dct.decode_seeded(&Sl0Config::DEFAULT, &mut seeded).unwrap();
        assert_eq!((warm.solves, warm.member), (1, None));
        assert!(warm.outcome.iterations < cold.outcome.iterations, "seed {s}: {warm:?} vs {cold:?}");
        let es = rel_err32(seeded.patch(), &truth);
        assert!(es < 1e-3, "seed {s}: seeded from the truth, rel err {es}");
        zero.patch_mut().fill(0.0);
        dct.decode_seeded(&Sl0Config::DEFAULT, &mut zero).unwrap();
        let m = zero.measurements();
        assert!((0..5200).all(|i| m.get(i).is_none_or(|y| zero.patch()[i] == y)), "seed {s}: off the measurements");
        let ez = rel_err32(zero.patch(), &truth);
        assert!(ez > 10.0 * es.max(1e-4), "seed {s}: from zeros {ez}, from the truth {es}");
    }
}

/// A flat patch takes the short path from a seed too (no solve), whatever the seed holds.
#[test]
fn a_flat_patch_ignores_its_seed() {
    let dct = Dictionary::<PaperShape>::dct();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let truth: Vec<f32> = (0..5200).map(|i| 0.1 + 0.05 * (i % 13) as f32).collect();
    let mut ws = Box::new(PaperWorkspace::new());
    measure(&mask, (0, 0), &truth, &mut ws);
    ws.patch_mut().fill(7.0);
    let out = dct.decode_seeded(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!((out.outcome.ended, out.solves), (Ended::Flat, 0));
    assert!(max_abs_diff(ws.patch(), &truth) <= 1e-6);
}

/// The half-pixel seed: `from_sensor` undoes `to_sensor` wherever the patch is linear along
/// its half axes (every position but the last, which names no pixel, and the first, which
/// has one neighbour: there half a step off). Whole views are left alone.
#[test]
fn from_sensor_interpolates_the_half_grid_back() {
    type S = PaperShape;
    for d in [Disparity::halves(1), Disparity::halves(-3)] {
        let half = HalfViews::of(d, (0, 0), (5, 5));
        assert!(!half.is_none());
        // Linear along s and t, different per view and band.
        let truth: Vec<f32> = (0..5200)
            .map(|i| {
                let [s, t, u, v, b] = S::coordinates(i);
                0.3 + 0.05 * s as f32 - 0.03 * t as f32 + 0.01 * (u + 2 * v) as f32 + 0.02 * b as f32
            })
            .collect();
        let mut p: Box<[f32; 5200]> = truth.clone().try_into().unwrap();
        to_sensor::<PaperShape>(half, &mut p);
        from_sensor::<PaperShape>(half, &mut p);
        for (i, (&x, &y)) in p.iter().zip(&truth).enumerate() {
            let [s, t, u, v, _] = S::coordinates(i);
            let ends = (half.row(u) && (s == 0 || s == 4)) || (half.col(v) && (t == 0 || t == 4));
            let tol = if ends { 0.5 * 0.05 + 0.5 * 0.03 + 1e-6 } else { 1e-6 };
            assert!((x - y).abs() <= tol, "{d:?} entry {i} ({s}, {t}, {u}, {v}): {x} vs {y}");
        }
    }
}
