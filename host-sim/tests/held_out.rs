//! The error estimate of the decode actually made ([`slf_host::decode::held_out`]): the frame
//! decoded again without one sample in eight, and that decode's values at those samples
//! against them. Checked against the slow obvious route (the held-out samples made defective
//! pixels of a second capture, decoded by the public API, the tallies summed in f64), and for
//! what it must not change (the decode) and must see (the model that decoded).

use slf_host::decode::cs::{Balance, Basis, DecodeOptions, EstimateBy, decode_with};
use slf_host::decode::held_out::{Held, LEVEL};
use slf_host::firmware::HoldOut;
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;

fn estimating() -> DecodeOptions {
    DecodeOptions { balance: Balance::Off, error_estimate: true, ..DecodeOptions::default() }
}

/// The error map by hand: `cap`'s held-out samples as defective pixels of a copy (one
/// snapshot: a sample is a pixel), the copy decoded, each held-out sample's light-field
/// value against its normalised raw value, the noise variance off, per 5 x 5 lenslets (the
/// measured values at the lower of that and the noise's variance; a saturated held-out
/// sample at the gap from the decode's value up to the top of the range). Also returns how
/// many held-out samples saturated. A capture whose frames were divided by a flat
/// ([`Capture::flat`]) has each sample's noise variance over its pixel's flat squared: the
/// raw value's noise at `seen * flat`.
fn slow_map(cap: &Capture, opts: &DecodeOptions) -> (Vec<f64>, usize) {
    let d = &cap.description;
    assert_eq!(cap.frames.len(), 1, "the reference holds pixels out: one snapshot");
    let (rows, cols) = cap.frame_size();
    let (lu, lv) = (d.views[0], d.views[1]);
    let (lr, lc) = (d.lenslets[0], d.lenslets[1]);
    let held: Vec<(usize, usize)> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| (r, c)))
        .filter(|&at| Held::Sample.holds(&HoldOut::DEFAULT, 0, at, (rows, cols)))
        .collect();
    let mut hidden = cap.clone();
    hidden.description.defective_pixels = held.iter().map(|&(r, c)| [r as u32, c as u32]).collect();
    let hidden = Capture::with_frames(hidden.description, hidden.frames).unwrap();
    let plain = DecodeOptions { error_estimate: false, ..*opts };
    let lf: LightField = decode_with(&hidden, &Basis::Dct, &plain).unwrap().0;
    let mask = cap.mask().unwrap();
    let (noise, shot) = cap.noise_model().map_or((0.0, 0.0), |(n, s)| (f64::from(n), f64::from(s)));
    let (black, white) = (f64::from(d.black_level), f64::from(d.white_level));
    let top = (f64::from(d.saturation_level) - 0.5 - black) / (white - black);
    let mut flat = vec![1.0f32; rows * cols];
    if let Some(map) = cap.flat() {
        map.read_rows(0, &mut flat).unwrap();
    }
    // Per lenslet: squared error, variance, held-out samples, valid samples.
    let mut t = vec![[0.0f64; 4]; lr * lc];
    let mut saturated = 0;
    for r in 0..rows {
        for c in 0..cols {
            let raw = f64::from(cap.held_frames().unwrap()[0][r * cols + c]);
            let over = raw > f64::from(d.saturation_level) - 0.5;
            let seen = (raw - black) / (white - black);
            let (y, x, u, v) = (r / lu, c / lv, r % lu, c % lv);
            let slot = &mut t[y * lc + x];
            slot[3] += if over { 0.0 } else { 1.0 };
            if held.binary_search(&(r, c)).is_err() {
                continue;
            }
            let band = usize::from(mask.bands_at(r, c)[0]);
            let value = f64::from(lf.data[lf.index(u, v, y, x, band)]);
            if over {
                saturated += 1;
                slot[0] += (top - value).max(0.0).powi(2);
            } else {
                slot[0] += (value - seen).powi(2);
                let f = f64::from(flat[r * cols + c].max(0.1));
                slot[1] += (noise * noise + shot * (seen * f).max(0.0)) / (f * f);
            }
            slot[2] += 1.0;
        }
    }
    let mut out = vec![f64::NAN; lr * lc];
    for y in 0..lr {
        for x in 0..lc {
            let mut s = [0.0f64; 4];
            let mut n = 0.0;
            for yy in y.saturating_sub(2)..(y + 3).min(lr) {
                for xx in x.saturating_sub(2)..(x + 3).min(lc) {
                    for (a, b) in s.iter_mut().zip(&t[yy * lc + xx]) {
                        *a += b;
                    }
                    n += 1.0;
                }
            }
            if s[2] > 0.0 {
                let measured = (s[3] / n / (lu * lv * 13) as f64).min(1.0);
                let (r2, var) = (s[0] / s[2], s[1] / s[2]);
                let unmeasured = (r2 - var).max(0.0);
                out[y * lc + x] = (unmeasured * (1.0 - measured) + unmeasured.min(var) * measured).sqrt();
            }
        }
    }
    (out, saturated)
}

#[test]
fn the_map_is_the_held_out_decodes_error_at_the_samples_it_was_not_given() {
    let lf = common::small_smooth(5);
    // The scene as it is, and three times as bright: samples saturate.
    let bright = LightField { data: lf.data.iter().map(|x| x * 3.0).collect(), ..lf.clone() };
    for (name, scene, saturates) in [("smooth", &lf, false), ("bright", &bright, true)] {
        let cap = simulate(scene, &CameraConfig::pixel(3, 1)).unwrap();
        let opts = estimating();
        let (_, report) = decode_with(&cap, &Basis::Dct, &opts).unwrap();
        let (slow, saturated) = slow_map(&cap, &opts);
        assert_eq!(saturated > 0, saturates, "{name}: {saturated} held-out samples saturated");
        assert_eq!(report.error_lenslets.len(), slow.len());
        assert!(report.error_map.is_empty(), "{name}: the patches' estimates ran as well");
        for (i, (&fast, &slow)) in report.error_lenslets.iter().zip(&slow).enumerate() {
            let slow = slow * LEVEL;
            // f32 tallies against f64 ones: well within 1e-4 relative.
            assert!(
                (f64::from(fast) - slow).abs() <= 1e-4 * slow.abs() + 1e-7,
                "{name}, lenslet {i}: map {fast} against the slow route's {slow}"
            );
        }
        assert!(slow.iter().all(|e| e.is_finite() && *e > 0.0), "{name}: a lenslet without an estimate");
    }
}

/// A corrected capture's values were divided by their pixels' flats, and so was their
/// noise (issue 65, item 12): the estimate's noise term is the raw noise over each pixel's
/// flat, as the slow route computes it, not the raw noise (which a flat of 0.3 under-counts
/// elevenfold). The flat here is made up, from 0.3 to 1, to see the term alone; a real
/// calibrated decode gives it `decode::correction`'s map.
#[test]
fn the_noise_term_sees_the_flat_the_frames_were_divided_by() {
    use slf_host::io::map::Map;
    let lf = common::small_smooth(5);
    let plain = simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap();
    let (rows, cols) = plain.frame_size();
    let flat: Vec<f32> = (0..rows * cols).map(|i| 0.3 + 0.7 * ((i * 7 + i / cols * 3) % 10) as f32 / 9.0).collect();
    let mut cap = plain.clone();
    cap.divided_by(Map::Held(flat.into(), cols));
    let opts = estimating();
    let (_, report) = decode_with(&cap, &Basis::Dct, &opts).unwrap();
    let (_, before) = decode_with(&plain, &Basis::Dct, &opts).unwrap();
    let (slow, _) = slow_map(&cap, &opts);
    let mut apart = 0;
    for (i, ((&fast, &slow), &raw)) in report.error_lenslets.iter().zip(&slow).zip(&before.error_lenslets).enumerate() {
        let slow = slow * LEVEL;
        assert!(
            (f64::from(fast) - slow).abs() <= 1e-4 * slow.abs() + 1e-7,
            "lenslet {i}: map {fast} against the slow route's {slow}"
        );
        apart += usize::from((fast - raw).abs() > 1e-3 * raw.abs());
    }
    assert!(apart * 2 > slow.len(), "the flat moved {apart} of {} lenslets' estimates", slow.len());
}

/// The patches' own estimates (`EstimateBy::Patches`, the firmware's `estimate_error`) see
/// the flat too, through the source (`FrameSource::with_flat`, the host's `MapFrame`): a
/// flat of 1 everywhere leaves every estimate as it was, bit for bit; a flat from 0.3 to 1
/// raises each held-out sample's noise variance, which at one snapshot (1 value in 13
/// measured) only lowers a patch's estimate: none rises, and more than half move. (The firmware's
/// `tile.rs` checks the flat against view gains bit for bit.)
#[test]
fn the_patches_estimates_see_the_flat_the_frames_were_divided_by() {
    use slf_host::io::map::Map;
    let lf = common::small_smooth(5);
    let plain = simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap();
    let (rows, cols) = plain.frame_size();
    let opts = DecodeOptions { estimate_by: EstimateBy::Patches, ..estimating() };
    let map = |flat: Vec<f32>| {
        let mut cap = plain.clone();
        cap.divided_by(Map::Held(flat.into(), cols));
        decode_with(&cap, &Basis::Dct, &opts).unwrap().1.error_map.iter().map(|p| p.1).collect::<Vec<_>>()
    };
    let before: Vec<f32> = decode_with(&plain, &Basis::Dct, &opts).unwrap().1.error_map.iter().map(|p| p.1).collect();
    assert!(before.len() > 20 && before.iter().all(|&e| e > 0.0), "every patch estimated");
    let ones = map(vec![1.0; rows * cols]);
    assert!(ones.iter().zip(&before).all(|(a, b)| a.to_bits() == b.to_bits()), "a flat of 1 moved an estimate");
    let flat: Vec<f32> = (0..rows * cols).map(|i| 0.3 + 0.7 * ((i * 7 + i / cols * 3) % 10) as f32 / 9.0).collect();
    let vignetted = map(flat);
    assert_eq!(vignetted.len(), before.len());
    let mut lower = 0;
    for (i, (&fast, &raw)) in vignetted.iter().zip(&before).enumerate() {
        assert!(fast <= raw, "patch {i}: {fast} above the flat-less {raw}");
        lower += usize::from(fast < raw * (1.0 - 1e-4));
    }
    assert!(lower * 2 > before.len(), "the flat lowered {lower} of {} patches' estimates", before.len());
}

#[test]
fn the_estimate_leaves_the_decode_as_it_was() {
    let lf = common::small_smooth(5);
    for k in [1u8, 3] {
        let cap = simulate(&lf, &CameraConfig::pixel(4, k)).unwrap();
        let plain = DecodeOptions { error_estimate: false, ..estimating() };
        let (with, report) = decode_with(&cap, &Basis::Dct, &estimating()).unwrap();
        let (without, none) = decode_with(&cap, &Basis::Dct, &plain).unwrap();
        assert_eq!(with.data, without.data, "k {k}: the estimate changed the decode");
        assert!(!report.error_lenslets.is_empty() && none.error_lenslets.is_empty(), "k {k}");
        assert!(report.estimate_seconds > 0.0, "k {k}: the held-out decode's time");
    }
}

/// The patches' estimates were one DCT solve whatever the model: a DCT decode and an
/// ensemble decode got the same map. The held-out decode is each decode's own.
#[test]
fn each_model_gets_the_map_of_its_own_decode() {
    let lf = common::small_smooth(5);
    let cap = simulate(&lf, &CameraConfig::pixel(5, 1)).unwrap();
    let ensemble = Basis::default_ensemble();
    let map = |basis: &Basis, by: EstimateBy| {
        decode_with(&cap, basis, &DecodeOptions { estimate_by: by, ..estimating() })
            .unwrap()
            .1
            .error_per_lenslet(12, 12)
    };
    let (dct, ens) = (map(&Basis::Dct, EstimateBy::Decode).unwrap(), map(&ensemble, EstimateBy::Decode).unwrap());
    assert_ne!(dct, ens, "the DCT's and the ensemble's decodes estimated alike");
    let (p_dct, p_ens) = (map(&Basis::Dct, EstimateBy::Patches).unwrap(), map(&ensemble, EstimateBy::Patches).unwrap());
    assert_eq!(p_dct, p_ens, "the patches' estimates now follow the model: this test's premise is gone");
}

/// The model trial by held-out decodes: the model whose decode, made again from seven in
/// eight samples, errs less at the eighth decodes the frame, bit for bit as that model alone
/// does, and its held-out decode is the error map.
#[test]
fn the_trial_by_decode_picks_the_model_whose_held_out_decode_errs_less() {
    use slf_host::decode::cs::TrialBy;
    let lf = common::small_smooth(5);
    for k in [1u8, 3] {
        let cap = simulate(&lf, &CameraConfig::pixel(6, k)).unwrap();
        let trial = DecodeOptions { model_trial: true, trial_by: TrialBy::Decode, ..estimating() };
        let (out, report) = decode_with(&cap, &Basis::default_ensemble(), &trial).unwrap();
        let t = report.trial.expect("the trial ran");
        let (dct, ensemble) = t.by_decode.expect("the held-out decodes estimated");
        assert!(dct > 0.0 && ensemble > 0.0, "k {k}: {dct} {ensemble}");
        assert_eq!(t.dct, dct < ensemble, "k {k}: picked the DCT {} on {dct} against {ensemble}", t.dct);
        // The picked model alone, with its own estimate.
        let alone = DecodeOptions { model_trial: false, ..estimating() };
        let basis = if t.dct { Basis::Dct } else { Basis::default_ensemble() };
        let (same, own) = decode_with(&cap, &basis, &alone).unwrap();
        assert_eq!(out.data, same.data, "k {k}: not the picked model's decode");
        assert_eq!(report.error_lenslets, own.error_lenslets, "k {k}: not the picked model's map");
    }
}
