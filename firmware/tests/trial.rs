//! The model trial: its errors are the held-out estimate's, it picks the model nearer the
//! truth, and the picked model decodes as it does alone.

mod common;

use common::*;
use slf_firmware::*;

type Ws = Workspace<PaperShape>;
type Decoder = TileDecoder<'static, PaperShape>;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

fn frames(l: &[f32], mask: &Mask) -> Vec<RawFrame<'static, f32>> {
    capture_10x15(l, mask)
        .into_iter()
        .map(|f| RawFrame::new(Box::leak(f.into_boxed_slice()), 50, 75).unwrap())
        .collect()
}

fn decode<M: PatchModel<PaperShape>>(dec: &Decoder, raw: &[RawFrame<f32>], model: &M) -> Patches {
    let mut sink = Patches::default();
    let mut ws = Box::new(Ws::new());
    let r = dec.decode_frame(model, (2, 3), &mut FrameSource::new(raw), &mut sink, &mut ws);
    assert_eq!((r.failed_tiles, r.patches.decoded), (0, 24));
    sink
}

/// The six blocks of the 10 x 15-lenslet frame.
fn blocks() -> impl Iterator<Item = (u16, u16)> {
    (0..2u16).flat_map(|r| (0..3u16).map(move |c| (5 * r, 5 * c)))
}

#[test]
fn a_pilots_errors_are_the_held_out_estimates_of_each_model() {
    let l = rough_light_field(3);
    let mask = Mask::pixel(4, 3, 13, L5).unwrap();
    let raw = frames(&l, &mask);
    let dec = Decoder::new(decoder_config((10, 15), mask)).unwrap();
    let dct = Dictionary::<PaperShape>::dct();
    let other = random_dictionary::<PaperShape>(7);
    let estimated = |model: &Dictionary<PaperShape>| {
        let dec = dec.with_error_estimate(Some(HoldOut::DEFAULT)).unwrap();
        decode(&dec, &raw, model).0
    };
    let (by_dct, by_other) = (estimated(&dct), estimated(&other));
    let mut ws = Box::new(Ws::new());
    for at in blocks() {
        let t = dec.trial(&dct, &other, at, &mut FrameSource::new(&raw), &mut ws).unwrap().errors;
        // The block's first window's patch, as the decode with the estimate reports it.
        let reported = |patches: &[(PatchOrigin, Vec<f32>, PatchReport)]| {
            let (_, _, r) = patches
                .iter()
                .find(|(o, _, _)| (o.lenslet_row, o.lenslet_col, o.view_row, o.view_col) == (at.0, at.1, 0, 0))
                .unwrap();
            r.error.unwrap()
        };
        let (a, z) = (reported(&by_dct), reported(&by_other));
        assert_eq!(t.pilots, 1);
        assert!((t.first.sqrt() - a).abs() <= 1e-6 * a, "{at:?}: {} against {a}", t.first.sqrt());
        assert!((t.second.sqrt() - z).abs() <= 1e-6 * z, "{at:?}: {} against {z}", t.second.sqrt());
    }
}

/// The true RMS error of a frame's patches against the light field.
fn true_rms(patches: &Patches, l: &[f32]) -> f64 {
    let (mut e2, mut n) = (0.0f64, 0.0f64);
    for (o, p, _) in &patches.0 {
        for (i, &x) in p.iter().enumerate() {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            let (s, t) = (o.lenslet_row as usize + s, o.lenslet_col as usize + t);
            let (u, v) = (o.view_row as usize + u, o.view_col as usize + v);
            e2 += (f64::from(x) - f64::from(l[((((s * 15) + t) * 5 + u) * 5 + v) * 13 + b])).powi(2);
            n += 1.0;
        }
    }
    (e2 / n).sqrt()
}

#[test]
fn the_trial_picks_the_model_nearer_the_truth_in_either_order() {
    for (seed, mask) in [(3, Mask::pixel(4, 3, 13, L5).unwrap()), (4, Mask::pixel(4, 1, 13, L5).unwrap())] {
        let l = rough_light_field(seed);
        let raw = frames(&l, &mask);
        let dec = Decoder::new(decoder_config((10, 15), mask)).unwrap();
        let dct = Dictionary::<PaperShape>::dct();
        // A member the scene is not sparse in: the DCT's neighbour in a random rotation.
        let other = random_dictionary::<PaperShape>(seed + 10);
        let truth = [true_rms(&decode(&dec, &raw, &dct), &l), true_rms(&decode(&dec, &raw, &other), &l)];
        let nearer = if truth[0] < truth[1] { Pick::First } else { Pick::Second };
        let mut ws = Box::new(Ws::new());
        let (mut forward, mut backward) = (PairedErrors::default(), PairedErrors::default());
        for at in blocks() {
            forward += dec.trial(&dct, &other, at, &mut FrameSource::new(&raw), &mut ws).unwrap().errors;
            backward += dec.trial(&other, &dct, at, &mut FrameSource::new(&raw), &mut ws).unwrap().errors;
        }
        assert_eq!(forward.pilots, 6);
        // Both orders: a trial that always said "first" (or "second") fails one of them.
        assert_eq!(forward.pick(), nearer, "seed {seed}: true RMS {truth:?}, trial {forward:?}");
        let flipped = if nearer == Pick::First { Pick::Second } else { Pick::First };
        assert_eq!(backward.pick(), flipped, "seed {seed}: true RMS {truth:?}, trial {backward:?}");
    }
}

#[test]
fn the_picked_model_decodes_as_it_does_alone() {
    let l = rough_light_field(5);
    let mask = Mask::pixel(4, 3, 13, L5).unwrap();
    let raw = frames(&l, &mask);
    let dec = Decoder::new(decoder_config((10, 15), mask)).unwrap();
    let dct = Dictionary::<PaperShape>::dct();
    let other = random_dictionary::<PaperShape>(9);
    let (by_dct, by_other) = (decode(&dec, &raw, &dct), decode(&dec, &raw, &other));
    let first = decode(&dec, &raw, &Picked { first: &dct, second: &other, pick: Pick::First });
    let second = decode(&dec, &raw, &Picked { first: &dct, second: &other, pick: Pick::Second });
    let values = |p: &Patches| p.0.iter().map(|(o, v, _)| (*o, v.clone())).collect::<Vec<_>>();
    assert_eq!(values(&first), values(&by_dct));
    assert_eq!(values(&second), values(&by_other));
    assert_ne!(values(&by_dct), values(&by_other));
}

#[test]
fn the_pick_is_the_smaller_sum_and_the_second_without_pilots_or_on_a_tie() {
    assert_eq!(PairedErrors::default().pick(), Pick::Second);
    let mut t = PairedErrors::one(1.0, 2.0);
    assert_eq!(t.pick(), Pick::First);
    t += PairedErrors::one(3.0, 1.0);
    assert_eq!(t, PairedErrors { first: 4.0, second: 3.0, spread: 5.0, pilots: 2 });
    assert_eq!(t.pick(), Pick::Second);
    assert_eq!(PairedErrors { first: 2.0, second: 2.0, spread: 0.0, pilots: 3 }.pick(), Pick::Second);
    // No pilot: the sums say nothing.
    assert_eq!(PairedErrors { first: 0.0, second: 5.0, spread: 0.0, pilots: 0 }.pick(), Pick::Second);
}

#[test]
fn a_leaning_pick_leaves_its_model_only_below_the_margin() {
    // Written from the definition: the other model where its summed squares are below
    // margin^2 times the kept one's, the kept one on a tie, above it or without pilots.
    let reference = |t: &PairedErrors, towards: Pick, margin: f32| {
        let (kept, other) = if towards == Pick::First { (t.first, t.second) } else { (t.second, t.first) };
        let flip = |p: Pick| if p == Pick::First { Pick::Second } else { Pick::First };
        if t.pilots > 0 && f64::from(other) < f64::from(margin).powi(2) * f64::from(kept) {
            flip(towards)
        } else {
            towards
        }
    };
    let mut next = uniform(0x2545_f491_4f6c_dd1d);
    for i in 0..2000 {
        let t = PairedErrors { first: next(), second: next(), spread: 0.0, pilots: (i % 3) as u32 };
        for (towards, margin) in [(Pick::First, 0.8), (Pick::Second, 0.8), (Pick::Second, 1.0), (Pick::First, 1.0)] {
            assert_eq!(t.pick_leaning(towards, margin), reference(&t, towards, margin), "{t:?} {towards:?} {margin}");
        }
        assert_eq!(t.pick_leaning(Pick::Second, 1.0), t.pick(), "{t:?}");
    }
    // At the margin's edges: 0.64 x is not below 0.8^2 x, just under it is.
    let t = |second: f32| PairedErrors { first: 1.0, second, spread: 0.0, pilots: 4 };
    assert_eq!(t(0.7).pick_leaning(Pick::First, 0.8), Pick::First);
    assert_eq!(t(0.6).pick_leaning(Pick::First, 0.8), Pick::Second);
    assert_eq!(
        PairedErrors { first: 1.0, second: 0.0, spread: 0.0, pilots: 0 }.pick_leaning(Pick::First, 0.8),
        Pick::First
    );
}

#[test]
fn a_tie_is_a_difference_within_two_standard_errors_of_the_pilots_and_takes_the_prior() {
    // The reference, in f64 from the pilots' pairs: the paired differences' sample
    // variance s^2, the sum's standard error sqrt(n s^2); tied when the sum of the
    // differences is within two of them, or with fewer than two pilots.
    let reference = |pairs: &[(f32, f32)]| {
        let n = pairs.len() as f64;
        if pairs.len() < 2 {
            return true;
        }
        let d: Vec<f64> = pairs.iter().map(|&(a, b)| f64::from(a) - f64::from(b)).collect();
        let mean = d.iter().sum::<f64>() / n;
        let s2 = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean * n).abs() <= 2.0 * (n * s2).sqrt()
    };
    let mut next = uniform(0x9e37_79b9_7f4a_7c15);
    let (mut tied, mut apart) = (0, 0);
    for case in 0..3000 {
        let n = case % 40;
        // A shift between the models, from none to about the pilots' own spread.
        let shift = (case % 7) as f32 * 0.05;
        let pairs: Vec<(f32, f32)> = (0..n).map(|_| (next(), next() * 0.8 + shift)).collect();
        let mut t = PairedErrors::default();
        for &(a, b) in &pairs {
            t += PairedErrors::one(a, b);
        }
        let want = reference(&pairs);
        // Away from the edge (f32 sums against f64), the two must agree.
        let d: f64 = pairs.iter().map(|&(a, b)| f64::from(a) - f64::from(b)).sum();
        let ratio = if n >= 2 {
            let mean = d / n as f64;
            let s2 = pairs.iter().map(|&(a, b)| (f64::from(a) - f64::from(b) - mean).powi(2)).sum::<f64>()
                / (n as f64 - 1.0);
            d.abs() / (2.0 * (n as f64 * s2).sqrt())
        } else {
            0.0
        };
        if (ratio - 1.0).abs() > 1e-3 {
            assert_eq!(t.tied(), want, "{pairs:?}");
        }
        let lower = if t.first < t.second { Pick::First } else { Pick::Second };
        for prior in [Pick::First, Pick::Second] {
            // Without a pilot, the second whatever the prior.
            let want = match (n, t.tied()) {
                (0, _) => Pick::Second,
                (_, true) => prior,
                (_, false) => lower,
            };
            assert_eq!(t.pick_unless_tied(Some(prior)), want, "{t:?}");
        }
        // The prior is taken where a pilot was measured and the sums tie, never without one.
        assert_eq!(t.takes_prior(Some(Pick::First)), n > 0 && t.tied(), "{t:?}");
        assert!(!t.takes_prior(None), "{t:?}");
        // Without a prior, the lower sum however close.
        assert_eq!(t.pick_unless_tied(None), if n == 0 { Pick::Second } else { lower }, "{t:?}");
        if t.tied() { tied += 1 } else { apart += 1 }
    }
    // Both sides of the test were reached.
    assert!(tied > 300 && apart > 300, "{tied} tied, {apart} apart");
    // Pilots that all differ by the same amount are apart however small it is; two
    // pilots of opposite differences are tied.
    let mut same = PairedErrors::default();
    for _ in 0..4 {
        same += PairedErrors::one(1.0, 1.01);
    }
    assert!(!same.tied());
    assert_eq!(same.pick_unless_tied(Some(Pick::Second)), Pick::First);
    let mut opposite = PairedErrors::one(1.0, 2.0);
    opposite += PairedErrors::one(2.0, 0.9);
    assert!(opposite.tied());
    assert_eq!(opposite.pick_unless_tied(Some(Pick::First)), Pick::First);
    assert_eq!(opposite.pick_unless_tied(None), Pick::Second);
}

/// A scene at half a pixel of disparity (each view of lenslet `(s, t)` sees the point
/// `(s + d (u - 2), t + d (v - 2))` of a smooth texture), in the layout of
/// [`rough_light_field`].
fn sheared_light_field(d: f32) -> Vec<f32> {
    let f = |y: f32, x: f32, b: usize| {
        let b = b as f32;
        0.45 + 0.2 * (0.9 * y + 0.3 * b).sin() * (0.7 * x - 0.2 * b).cos() + 0.1 * (0.4 * x + 0.5 * y).sin()
    };
    let mut l = vec![0.0; 10 * 15 * 25 * 13];
    for (i, x) in l.iter_mut().enumerate() {
        let (b, v, u, t, s) = (i % 13, (i / 13) % 5, (i / 65) % 5, (i / 325) % 15, i / (325 * 15));
        *x = f(s as f32 + d * (u as f32 - 2.0), t as f32 + d * (v as f32 - 2.0), b);
    }
    l
}

#[test]
fn the_shear_trial_pilots_half_pixel_blocks_and_finds_a_true_half_disparity_better() {
    let mask = Mask::pixel(4, 1, 13, L5).unwrap();
    let dct = Dictionary::<PaperShape>::dct();
    let mut ws = Box::new(Ws::new());
    let halves = DisparityRange::DEFAULT.with_halves(true);
    // At a whole disparity (0: every view alike) no block is a pilot.
    let raw = frames(&rough_light_field(3), &mask);
    let dec = Decoder::new(decoder_config((10, 15), mask)).unwrap().with_disparities(halves);
    for at in blocks() {
        let t = dec.shear_trial(&dct, at, &mut FrameSource::new(&raw), &mut ws).unwrap();
        assert_eq!(t, ShearTrial::default(), "{at:?}");
    }
    // At half a pixel, the inner blocks are pilots, and the half disparity predicts their
    // held-out measurements better than the whole ones beside it.
    let raw = frames(&sheared_light_field(0.5), &mask);
    let mut sum = ShearTrial::default();
    for at in blocks() {
        let d = dec.choose_disparity(at.0 as usize, at.1 as usize, &mut FrameSource::new(&raw)).unwrap();
        let t = dec.shear_trial(&dct, at, &mut FrameSource::new(&raw), &mut ws).unwrap();
        assert_eq!(t.errors.pilots, u32::from(!d.is_whole()), "{at:?} at {d:?}");
        sum += t;
    }
    assert!(sum.errors.pilots >= 2, "{sum:?}");
    assert!(sum.half() < sum.whole(), "half {} against whole {}", sum.half().sqrt(), sum.whole().sqrt());
}

/// A xorshift stream of values in [0, 1) from `seed` (fixed seeds: the tests repeat).
fn uniform(mut state: u64) -> impl FnMut() -> f32 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A model that counts the solves it runs, as its decodes report them.
struct Counting<'m, M> {
    model: &'m M,
    solves: std::cell::Cell<u32>,
}

impl<M: PatchModel<PaperShape>> PatchModel<PaperShape> for Counting<'_, M> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Ws) -> Result<ModelOutcome, SolveError> {
        let out = self.model.decode(cfg, ws);
        // A failed solve ran too: one, as the trial counts it.
        self.solves.set(self.solves.get() + out.as_ref().map_or(0, |o| u32::from(o.solves)));
        out
    }

    fn estimating_solve(&self, cfg: &Sl0Config, ws: &mut Ws) -> Result<u16, SolveError> {
        let out = self.model.estimating_solve(cfg, ws);
        self.solves.set(self.solves.get() + out.as_ref().map_or(0, |&n| u32::from(n)));
        out
    }
}

#[test]
fn a_trial_counts_the_solves_its_pilots_ran() {
    let dct = Dictionary::<PaperShape>::dct();
    let blob = slf_firmware::DEFAULT_ENSEMBLE;
    let ensemble =
        EnsembleModel::new(Ensemble::<PaperShape>::new(blob).unwrap(), MemberChoice::Screened(ChoiceRule::DEFAULT));
    let mut ws = Box::new(Ws::new());
    // The model trial: the DCT's solve and the screened ensemble's two or three a pilot.
    let mask = Mask::pixel(4, 3, 13, L5).unwrap();
    let raw = frames(&rough_light_field(3), &mask);
    let dec = Decoder::new(decoder_config((10, 15), mask)).unwrap();
    let (a, z) = (Counting { model: &dct, solves: 0.into() }, Counting { model: &ensemble, solves: 0.into() });
    let mut sum = ModelTrial::default();
    for at in blocks() {
        sum += dec.trial(&a, &z, at, &mut FrameSource::new(&raw), &mut ws).unwrap();
    }
    assert_eq!(sum.errors.pilots, 6);
    assert_eq!(sum.solves, a.solves.get() + z.solves.get());
    assert!(z.solves.get() > a.solves.get(), "the ensemble solves more than the DCT: {sum:?}");
    // The shear trial: three estimating solves a half-pixel pilot, none at a whole one.
    let mask = Mask::pixel(4, 1, 13, L5).unwrap();
    let raw = frames(&sheared_light_field(0.5), &mask);
    let dec = Decoder::new(decoder_config((10, 15), mask))
        .unwrap()
        .with_disparities(DisparityRange::DEFAULT.with_halves(true));
    let counted = Counting { model: &dct, solves: 0.into() };
    let mut sum = ShearTrial::default();
    for at in blocks() {
        sum += dec.shear_trial(&counted, at, &mut FrameSource::new(&raw), &mut ws).unwrap();
    }
    assert!(sum.errors.pilots >= 2, "{sum:?}");
    assert_eq!(sum.solves, counted.solves.get());
    assert!(sum.solves >= 3 * sum.errors.pilots, "{sum:?}");
}
