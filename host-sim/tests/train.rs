//! Ensemble training: monotone at fixed assignments, orthonormal members, better than the
//! DCT on held-out patches, reproducible to the byte; and the shipped ensemble.

use slf_host::firmware::{ChoiceRule, DEFAULT_ENSEMBLE, Dictionary, Ensemble, EnsembleModel, MemberChoice, blob};
use slf_host::train::{self, TrainConfig};

fn patches(seed: u64, scenes: usize, count: usize) -> Vec<f32> {
    train::sample_patches(&train::training_fields(scenes, 24, seed, train::Generator::Toy), count, seed)
}

fn small() -> TrainConfig {
    TrainConfig { members: 4, tau: 100, iterations: 3, group: 16, seed: 5, dct_member: true, progress: false }
}

#[test]
fn one_update_never_increases_the_coding_error_at_fixed_assignments() {
    let data = patches(2000, 4, 240);
    let cfg = small();
    let members = train::init_members(&data, &cfg);
    let dicts: Vec<Dictionary<5, 5, 4, 4, 13>> = members.iter().map(|m| m.dictionary()).collect();
    let assignment = train::assign(&data, &dicts, cfg.tau);
    let mut updated = 0;
    for (k, m) in members.iter().enumerate().skip(1) {
        let group: Vec<usize> = (0..assignment.len()).filter(|&p| assignment[p].0 == k).collect();
        if group.is_empty() {
            continue;
        }
        let before = train::member_error(&data, m, &group, cfg.tau);
        let next = train::update_member(&data, m, &group, cfg.tau);
        let after = train::member_error(&data, &next, &group, cfg.tau);
        assert!(after <= before * (1.0 + 1e-9) + 1e-12, "member {k}: {before} -> {after}");
        // Learned matrices stay orthonormal to 1e-5 (in f32, as shipped).
        let errs = next.dictionary().synthesis().orthonormality_errors();
        assert!(errs.iter().all(|&e| e <= 1e-5), "member {k}: {errs:?}");
        updated += 1;
    }
    assert!(updated >= 2, "too few members were assigned patches to test");
}

#[test]
fn the_ensemble_codes_held_out_patches_better_than_the_dct() {
    let cfg = small();
    let (dicts, reports) = train::train(&patches(3000, 6, 400), &cfg);
    assert!(reports.last().unwrap().ensemble_error < reports[0].ensemble_error, "{reports:?}");
    let held_out = patches(4000, 4, 200);
    let ensemble = train::ensemble_error(&held_out, &dicts, cfg.tau);
    let dct = train::coding_error(&held_out, &Dictionary::dct(), cfg.tau);
    assert!(ensemble < 0.9 * dct, "held out: ensemble {ensemble} vs DCT {dct}");
}

#[test]
fn training_is_reproducible_to_the_byte() {
    let data = patches(5000, 3, 160);
    let run = |seed| {
        let (dicts, _) = train::train(&data, &TrainConfig { seed, iterations: 2, ..small() });
        let mut out = vec![0u8; blob::blob_len([5, 5, 4, 4, 13], dicts.len())];
        blob::write_blob(&dicts, &mut out).unwrap();
        out
    };
    let a = run(9);
    assert_eq!(a, run(9));
    assert_ne!(a, run(10));
}

#[test]
fn the_shipped_ensemble_loads_and_validates() {
    let e = Ensemble::<5, 5, 4, 4, 13>::new(DEFAULT_ENSEMBLE).unwrap();
    assert_eq!(e.len(), 8);
    let model = EnsembleModel::new(e, MemberChoice::Screened(ChoiceRule::DEFAULT));
    assert_eq!(model.dct_member(), Some(0), "member 0 is the fixed DCT");
    for k in 1..8 {
        let errs = e.member(k).unwrap().synthesis().orthonormality_errors();
        assert!(errs.iter().all(|&x| x <= 1e-5), "member {k}: {errs:?}");
    }
}
