//! Ensemble training: monotone at fixed assignments, orthonormal members, better than the
//! DCT on held-out patches, reproducible to the byte; and the shipped ensemble.

use slf_firmware::FullViewShape;
use slf_firmware::PaperShape;
use slf_firmware::PatchShape;
use slf_host::firmware::{
    ChoiceRule, DEFAULT_ENSEMBLE, DEFAULT_FULL_VIEW_ENSEMBLE, Dictionary, Ensemble, EnsembleModel, MemberChoice, blob,
};
use slf_host::train::{self, TrainConfig};

/// Patches of the paper's shape (4 x 4 views).
fn patches(seed: u64, scenes: usize, count: usize) -> Vec<f32> {
    patches_of::<4, 4, 5200>(seed, scenes, count)
}

fn patches_of<const PU: usize, const PV: usize, const N: usize>(seed: u64, scenes: usize, count: usize) -> Vec<f32> {
    train::sample_patches::<PU, PV, N>(&train::training_fields(scenes, 24, seed, train::Generator::Toy), count, seed)
}

fn small() -> TrainConfig {
    TrainConfig { members: 4, tau: 100, iterations: 3, group: 16, seed: 5, dct_member: true, progress: false }
}

#[test]
fn one_update_never_increases_the_coding_error_at_fixed_assignments() {
    let data = patches(2000, 4, 240);
    let cfg = small();
    let members = train::init_members::<4, 4, 5200>(&data, &cfg);
    let dicts: Vec<Dictionary<PaperShape>> = members.iter().map(|m| m.dictionary()).collect();
    let assignment = train::assign::<4, 4, 5200>(&data, &dicts, cfg.tau);
    let mut updated = 0;
    for (k, m) in members.iter().enumerate().skip(1) {
        let group: Vec<usize> = (0..assignment.len()).filter(|&p| assignment[p].0 == k).collect();
        if group.is_empty() {
            continue;
        }
        let before = train::member_error::<4, 4, 5200>(&data, m, &group, cfg.tau);
        let next = train::update_member::<4, 4, 5200>(&data, m, &group, cfg.tau);
        let after = train::member_error::<4, 4, 5200>(&data, &next, &group, cfg.tau);
        assert!(after <= before * (1.0 + 1e-9) + 1e-12, "member {k}: {before} -> {after}");
        // Learned matrices stay orthonormal to 1e-5 (in f32, as shipped).
        let errs = next.dictionary::<4, 4, 5200>().synthesis().orthonormality_errors();
        assert!(errs.iter().all(|&e| e <= 1e-5), "member {k}: {errs:?}");
        updated += 1;
    }
    assert!(updated >= 2, "too few members were assigned patches to test");
}

#[test]
fn the_ensemble_codes_held_out_patches_better_than_the_dct() {
    fn check<const PU: usize, const PV: usize, const N: usize>() {
        let cfg = small();
        let (dicts, reports) = train::train::<PU, PV, N>(&patches_of::<PU, PV, N>(3000, 6, 400), &cfg);
        assert!(reports.last().unwrap().ensemble_error < reports[0].ensemble_error, "{PU} views: {reports:?}");
        let held_out = patches_of::<PU, PV, N>(4000, 4, 200);
        let ensemble = train::ensemble_error::<PU, PV, N>(&held_out, &dicts, cfg.tau);
        let dct = train::coding_error::<PU, PV, N>(&held_out, &Dictionary::dct(), cfg.tau);
        assert!(ensemble < 0.9 * dct, "{PU} views, held out: ensemble {ensemble} vs DCT {dct}");
    }
    check::<4, 4, 5200>();
    check::<5, 5, 8125>();
}

#[test]
fn full_view_patches_are_the_light_fields_values_at_every_view() {
    // The sampler against the obvious reading: every patch of 5 x 5 views is a 5 x 5-lenslet
    // window of the light field at all 25 views, in the layout (s, t, u, v, b).
    let fields = train::training_fields(2, 12, 77, train::Generator::Toy);
    let data = train::sample_patches::<5, 5, 8125>(&fields, 6, 3);
    for patch in data.chunks_exact(8125) {
        let found = fields.iter().any(|lf| {
            (0..=lf.rows - 5).any(|r| {
                (0..=lf.cols - 5).any(|c| {
                    (0..8125).all(|i| {
                        let (s, t, u, v, b) = (i / 1625, i / 325 % 5, i / 65 % 5, i / 13 % 5, i % 13);
                        patch[i] == lf.get(u, v, r + s, c + t, b)
                    })
                })
            })
        });
        assert!(found, "a sampled full-view patch is no window of the training fields");
    }
}

#[test]
fn training_is_reproducible_to_the_byte() {
    let data = patches(5000, 3, 160);
    let run = |seed| {
        let (dicts, _) = train::train::<4, 4, 5200>(&data, &TrainConfig { seed, iterations: 2, ..small() });
        let mut out = vec![0u8; blob::blob_len([5, 5, 4, 4, 13], dicts.len())];
        blob::write_blob(&dicts, &mut out).unwrap();
        out
    };
    let a = run(9);
    assert_eq!(a, run(9));
    assert_ne!(a, run(10));
}

#[test]
fn the_shipped_ensembles_load_and_validate() {
    fn check<const PU: usize, const PV: usize, const N: usize>(bytes: &[u8]) {
        let e = Ensemble::<PatchShape<5, 5, PU, PV, 13, N>>::new(bytes).unwrap();
        assert_eq!(e.len(), 8, "{PU} views");
        let model = EnsembleModel::new(e, MemberChoice::Screened(ChoiceRule::DEFAULT));
        assert_eq!(model.dct_member(), Some(0), "{PU} views: member 0 is the fixed DCT");
        for k in 1..8 {
            let errs = e.member(k).unwrap().synthesis().orthonormality_errors();
            assert!(errs.iter().all(|&x| x <= 1e-5), "{PU} views, member {k}: {errs:?}");
        }
    }
    check::<4, 4, 5200>(DEFAULT_ENSEMBLE);
    check::<5, 5, 8125>(DEFAULT_FULL_VIEW_ENSEMBLE);
    // Each is refused as the other patch's.
    assert!(Ensemble::<FullViewShape>::new(DEFAULT_ENSEMBLE).is_err());
    assert!(Ensemble::<PaperShape>::new(DEFAULT_FULL_VIEW_ENSEMBLE).is_err());
}
