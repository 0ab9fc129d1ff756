//! Held-out measurements: which are held out, the estimate against an f64 reference, a
//! decode that is the same with the estimate, and an estimate that follows the true error.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::holdout::{Unit, estimate, hold_out};
use slf_firmware::*;

type Ws = Workspace<PaperShape>;

#[test]
fn the_held_out_measurements_are_left_out_and_nothing_else() {
    let hold = HoldOut::DEFAULT;
    let mut r = rng(1);
    let mut ws = Box::new(Ws::new());
    let values: Vec<Option<f32>> =
        (0..5200).map(|_| (r.random_range(0.0..1.0) < 0.2).then(|| r.random_range(0.1..1.0f32))).collect();
    for (i, v) in values.iter().enumerate() {
        if let Some(y) = v {
            ws.measurements_mut().set(i, *y).unwrap();
        }
    }
    let before = ws.measurements().count();
    let expect = (0..5200).filter(|&i| values[i].is_some() && hold.held::<PaperShape>(Unit::Measurement, i)).count();
    // About one in eight, spread (a test that fails for a hash that holds none or all).
    assert!(expect * 8 > before / 2 && expect * 8 < before * 2, "{expect} of {before}");
    assert_eq!(hold_out::<PaperShape>(&hold, ws.measurements_mut()) as usize, expect);
    assert_eq!(ws.measurements().count(), before - expect);
    for (i, v) in values.iter().enumerate() {
        let kept = if hold.held::<PaperShape>(Unit::Measurement, i) { None } else { *v };
        assert_eq!(ws.measurements().get(i), kept, "entry {i}");
    }
    // A patch whose every measurement would be held out keeps them all.
    let mut one = Box::new(Ws::new());
    let i = (0..5200).find(|&i| hold.held::<PaperShape>(Unit::Measurement, i)).unwrap();
    one.measurements_mut().set(i, 0.5).unwrap();
    assert_eq!(hold_out::<PaperShape>(&hold, one.measurements_mut()), 0);
    assert_eq!(one.measurements().get(i), Some(0.5));
}

#[test]
fn the_estimate_is_the_held_out_error_less_the_noise() {
    let hold = HoldOut { fold: 4 };
    let mut r = rng(2);
    let mut ws = Box::new(Ws::new());
    let gains: Vec<f32> = (0..13).map(|_| r.random_range(0.5..2.0f32)).collect();
    ws.measurements_mut().set_gains(&gains).unwrap();
    let mut predicted = [0.0f32; 5200];
    for (i, x) in predicted.iter_mut().enumerate() {
        *x = r.random_range(0.0..1.0);
        if r.random_range(0.0..1.0) < 0.25 {
            ws.measurements_mut().set(i, *x + r.random_range(-0.2..0.2f32)).unwrap();
        }
    }
    let (noise, shot) = (0.01f32, 0.002f32);
    // A vignetted patch: each view's flat field, 0.3 to 1 (issue 65, item 12: the noise of
    // a measurement divided by its flat is the raw noise over the flat).
    let flats: Vec<f32> = (0..25).map(|_| r.random_range(0.3..1.0f32)).collect();
    let flat = |i: usize| {
        let [_, _, u, v, _] = <PaperShape as Shape>::coordinates(i);
        flats[u * 5 + v]
    };
    // By the definition, in f64: the squared error of the held-out ones in sensor units,
    // less their noise variance (the raw value's, divided by the flat as the value was),
    // for the unmeasured share, and the noise for the rest.
    let m = ws.measurements();
    let want = |flat: &dyn Fn(usize) -> f32| {
        let (mut r2, mut var, mut n) = (0.0f64, 0.0f64, 0.0f64);
        for (i, &x) in predicted.iter().enumerate() {
            let Some(y) = m.get(i).filter(|_| hold.held::<PaperShape>(Unit::Measurement, i)) else { continue };
            let (g, f) = (f64::from(gains[i % 13]), f64::from(flat(i)));
            r2 += ((f64::from(x) - f64::from(y)) * g).powi(2);
            var += (f64::from(noise).powi(2) + f64::from(shot) * (f64::from(y) * g * f).max(0.0)) / (f * f);
            n += 1.0;
        }
        let share = m.count() as f64 / 5200.0;
        ((r2 / n - var / n).max(0.0) * (1.0 - share) + var / n * share).sqrt()
    };
    let (flat_want, plain_want) = (want(&flat), want(&|_| 1.0));
    let got = f64::from(estimate::<PaperShape>(&hold, m, &predicted, (noise, shot), flat).unwrap());
    assert!((got - flat_want).abs() <= 1e-5 * flat_want, "{got} against {flat_want}");
    let plain = f64::from(estimate::<PaperShape>(&hold, m, &predicted, (noise, shot), |_| 1.0).unwrap());
    assert!((plain - plain_want).abs() <= 1e-5 * plain_want, "{plain} against {plain_want}");
    // The flats matter here: the two differ by more than the tolerance.
    assert!((flat_want - plain_want).abs() > 1e-3 * plain_want, "{flat_want} {plain_want}");
    // Nothing held out, no estimate.
    assert_eq!(estimate::<PaperShape>(&hold, &Measurements::new(), &predicted, (noise, shot), |_| 1.0), None);
}

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

fn decode(frames: &[Vec<f32>], mask: Mask<'static>, hold: Option<HoldOut>) -> Patches {
    let config = decoder_config((10, 15), mask);
    let dec = TileDecoder::<PaperShape>::new(config).unwrap().with_error_estimate(hold).unwrap();
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let mut sink = Patches::default();
    let mut ws = Box::new(Ws::new());
    let r = dec.decode_frame(&Dictionary::dct(), (2, 3), &mut FrameSource::new(&raw), &mut sink, &mut ws);
    assert_eq!((r.failed_tiles, r.patches.decoded), (0, 24));
    sink
}

#[test]
fn the_estimate_leaves_the_decode_as_it_was_and_follows_the_true_error() {
    let l = rough_light_field(3);
    let mask = Mask::pixel(4, 3, 13, L5).unwrap();
    let frames = capture_10x15(&l, &mask);
    let plain = decode(&frames, mask, None);
    let estimated = decode(&frames, mask, Some(HoldOut::DEFAULT));
    let (mut est, mut truth) = (Vec::new(), Vec::new());
    for ((o, p, r), (o2, p2, r2)) in plain.0.iter().zip(&estimated.0) {
        assert_eq!((o, p), (o2, p2), "the same decode, bit for bit");
        assert_eq!((r.error, r2.solves), (None, r.solves + 1));
        let e = r2.error.expect("every patch is estimated");
        let mut err2 = 0.0f64;
        for (i, &x) in p.iter().enumerate() {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            let (s, t) = (o.lenslet_row as usize + s, o.lenslet_col as usize + t);
            let (u, v) = (o.view_row as usize + u, o.view_col as usize + v);
            let y = l[((((s * 15) + t) * 5 + u) * 5 + v) * 13 + b];
            err2 += (f64::from(x) - f64::from(y)).powi(2);
        }
        est.push(f64::from(e));
        truth.push((err2 / 5200.0).sqrt());
    }
    // Spearman's rank correlation, by hand (no ties in continuous errors).
    let rank = |x: &[f64]| {
        let mut o: Vec<usize> = (0..x.len()).collect();
        o.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
        let mut r = vec![0.0; x.len()];
        for (k, &i) in o.iter().enumerate() {
            r[i] = k as f64;
        }
        r
    };
    let (ra, rb) = (rank(&est), rank(&truth));
    let n = ra.len() as f64;
    let d2: f64 = ra.iter().zip(&rb).map(|(a, b)| (a - b).powi(2)).sum();
    let rho = 1.0 - 6.0 * d2 / (n * (n * n - 1.0));
    assert!(rho > 0.7, "rank correlation {rho}: {est:?} against {truth:?}");
    let within = est.iter().zip(&truth).filter(|(e, t)| **e < 3.0 * **t && **t < 3.0 * **e).count();
    assert!(within * 4 >= est.len() * 3, "within 3 x: {within} of {}: {est:?} against {truth:?}", est.len());
}

#[test]
fn a_fold_below_two_is_refused() {
    let config = decoder_config((10, 15), Mask::pixel(4, 3, 13, L5).unwrap());
    let dec = TileDecoder::<PaperShape>::new(config).unwrap();
    assert_eq!(dec.error_estimate(), None);
    for fold in [0, 1] {
        assert_eq!(dec.with_error_estimate(Some(HoldOut { fold })).unwrap_err(), ConfigError::HoldOut);
    }
    assert_eq!(dec.with_error_estimate(Some(HoldOut { fold: 2 })).unwrap().error_estimate(), Some(HoldOut { fold: 2 }));
}

/// A lenslet mask's patch (each lenslet's bands in all its views) holds out whole (lenslet,
/// band) groups; a pixel mask's holds out single measurements.
#[test]
fn the_unit_held_out_follows_the_mask() {
    let l = rough_light_field(5);
    for (mask, unit) in [
        (Mask::pixel(4, 1, 13, L5).unwrap(), Unit::Measurement),
        (Mask::pixel(4, 3, 13, L5).unwrap(), Unit::Measurement),
        (Mask::lenslet(4, 3, 13, L5).unwrap(), Unit::LensletBand),
    ] {
        let frames = capture_10x15(&l, &mask);
        let mut ws = Box::new(Ws::new());
        for p in 0..400 {
            let [s, t, u, v, _] = PaperShape::coordinates(p * 13);
            let (row, col) = (s * 5 + u, t * 5 + v);
            for (j, frame) in frames.iter().enumerate() {
                let b = mask.band(j, row, col).unwrap() as usize;
                ws.measurements_mut().set(p * 13 + b, frame[row * 75 + col]).unwrap();
            }
        }
        assert_eq!(Unit::of::<PaperShape>(ws.measurements()), unit, "{:?}", mask.family());
        let before = ws.measurements().count();
        let held = hold_out::<PaperShape>(&HoldOut::DEFAULT, ws.measurements_mut()) as usize;
        assert!(held * 16 > before && held * 4 < before, "{held} of {before}");
        if unit == Unit::LensletBand {
            // Every view of a held-out group is out: no lenslet keeps part of a band.
            for lenslet in 0..25 {
                for b in 0..13 {
                    let seen: Vec<bool> =
                        (0..16).map(|v| ws.measurements().get(lenslet * 16 * 13 + v * 13 + b).is_some()).collect();
                    assert!(seen.iter().all(|&x| x) || seen.iter().all(|&x| !x), "lenslet {lenslet} band {b}");
                }
            }
        }
    }
}
