//! The plausibility check: its bounds against a slow, obvious reference, and the tile
//! decoder catching a decode that lit up a dark patch.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::plausible::{clip, implausible};
use slf_firmware::shape::ValueCount;
use slf_firmware::*;

type Ws = Workspace<PaperShape>;

/// Random measurements: about one entry a pixel (some negative, some pixels empty).
fn random_measurements(seed: u64) -> Box<Ws> {
    let mut r = rng(seed);
    let mut ws = Box::new(Ws::new());
    for p in 0..400 {
        if r.random_range(0.0..1.0) < 0.15 {
            continue;
        }
        let b = r.random_range(0..13);
        let y = if r.random_range(0.0..1.0) < 0.1 { -0.01 } else { r.random_range(0.0..0.3f32).powi(2) };
        ws.measurements_mut().set(p * 13 + b, y).unwrap();
    }
    ws
}

/// The bound of value `(s, t, u, v, b)` by the definition: the brightest measurement of the
/// pixels within 1 in every coordinate if one of them measured band `b`, else the patch's.
fn reference_bound(m: &Measurements<ValueCount<5200>>, p: &Plausibility, at: [usize; 5]) -> f32 {
    let [s, t, u, v, b] = at;
    let (mut near, mut seen, mut wide) = (f32::NEG_INFINITY, false, f32::NEG_INFINITY);
    for i in 0..5200 {
        let Some(y) = m.get(i) else { continue };
        let [s2, t2, u2, v2, b2] = PaperShape::coordinates(i);
        wide = wide.max(y);
        if s.abs_diff(s2) <= 1 && t.abs_diff(t2) <= 1 && u.abs_diff(u2) <= 1 && v.abs_diff(v2) <= 1 {
            near = near.max(y);
            seen |= b2 == b;
        }
    }
    let most = if seen { near } else { wide };
    if most == f32::NEG_INFINITY { f32::INFINITY } else { p.factor * most.max(0.0) + p.margin }
}

#[test]
fn bounds_are_the_neighbourhoods_brightest_measurement() {
    let p = Plausibility::DEFAULT;
    for seed in 0..3 {
        let ws = random_measurements(seed);
        let bounds = p.bounds::<PaperShape>(ws.measurements());
        let mut r = rng(100 + seed);
        let patch: Vec<f32> = (0..5200).map(|_| r.random_range(0.0..1.0f32)).collect();
        let patch: [f32; 5200] = patch.try_into().unwrap();
        let (mut above, mut clipped) = (0u32, patch);
        for (i, x) in clipped.iter_mut().enumerate() {
            let bound = reference_bound(ws.measurements(), &p, PaperShape::coordinates(i));
            if patch[i] > bound {
                above += 1;
                *x = bound;
            }
        }
        assert!(above > 100 && above < 5000, "a test that can fail either way: {above}");
        assert_eq!(implausible::<PaperShape>(&bounds, &patch), above, "seed {seed}");
        let mut out = patch;
        clip::<PaperShape>(&bounds, &mut out);
        assert_eq!(out, clipped, "seed {seed}");
    }
    // Off: no bound at all.
    let ws = random_measurements(7);
    let off = Plausibility::OFF.bounds::<PaperShape>(ws.measurements());
    assert_eq!(implausible::<PaperShape>(&off, &[1e30; 5200]), 0);
    // A NaN is above any bound.
    let on = Plausibility::DEFAULT.bounds::<PaperShape>(ws.measurements());
    let mut nan = [0.0f32; 5200];
    nan[17] = f32::NAN;
    assert_eq!(implausible::<PaperShape>(&on, &nan), 1);
}

/// The DCT's decode with every unmeasured value raised by 1: a diverged solve that still
/// meets its measurements.
struct Diverging(Dictionary<PaperShape>);

impl PatchModel<PaperShape> for Diverging {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Ws) -> Result<ModelOutcome, SolveError> {
        let outcome = solve(&self.0, cfg, ws)?;
        let measured: Vec<bool> = (0..5200).map(|i| ws.measurements().get(i).is_some()).collect();
        for (x, m) in ws.patch_mut().iter_mut().zip(measured) {
            if !m {
                *x += 1.0;
            }
        }
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }
}

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

/// A dark frame (every value 0.01 to 0.02, varying in space: no patch is flat) of 10 x 10
/// lenslets through a pixel mask.
fn dark_frame(mask: &Mask) -> Vec<f32> {
    (0..50 * 50)
        .map(|p| {
            let (row, col) = (p / 50, p % 50);
            0.01 + 0.008 * (mask.band(0, row, col).unwrap() as f32 / 12.0)
                + 0.002 * ((row * 7 + col * 3) % 5) as f32 / 4.0
        })
        .collect()
}

fn decode_dark(bound: Plausibility) -> (Patches, TileReport) {
    let mask = Mask::pixel(5, 1, 13, L5).unwrap();
    let frame = dark_frame(&mask);
    let config = decoder_config((10, 10), mask);
    let dec = TileDecoder::<PaperShape>::new(config).unwrap().with_plausibility(bound).unwrap();
    let raw = [RawFrame::new(&frame, 50, 50).unwrap()];
    let mut sink = Patches::default();
    let mut ws = Box::new(Ws::new());
    let r = dec.decode_frame(&Diverging(Dictionary::dct()), (2, 2), &mut FrameSource::new(&raw), &mut sink, &mut ws);
    assert_eq!(r.failed_tiles, 0, "{:?}", r.first_failure);
    (sink, r.patches)
}

#[test]
fn a_dark_patch_decoded_bright_is_decoded_again_and_never_passed_on_bright() {
    let (off, report) = decode_dark(Plausibility::OFF);
    assert_eq!((report.decoded, report.implausible), (16, 0));
    // Unchecked, the diverged values reach the output (clamped to white).
    assert!(off.0.iter().all(|(_, p, r)| r.checked == Checked::Plausible && p.iter().any(|&x| x > 0.9)));
    let (on, report) = decode_dark(Plausibility::DEFAULT);
    assert_eq!((report.decoded, report.implausible), (16, 16), "every patch caught");
    for (o, patch, r) in &on.0 {
        assert_ne!(r.checked, Checked::Plausible, "{o:?}");
        assert_eq!(r.solves, 2, "the model's solve and the safe one");
        // The brightest measurement is 0.02: nothing above 3 x 0.02 + 0.05.
        let top = patch.iter().fold(0.0f32, |a, &x| a.max(x));
        assert!(top <= 3.0 * 0.02 + 0.05 + 1e-6, "{o:?}: {top}");
    }
    assert_eq!(report.clipped, on.0.iter().filter(|(_, _, r)| r.checked == Checked::Clipped).count() as u32);
}

#[test]
fn a_bound_out_of_range_is_refused() {
    let config = decoder_config((10, 10), Mask::pixel(5, 1, 13, L5).unwrap());
    let dec = TileDecoder::<PaperShape>::new(config).unwrap();
    assert_eq!(dec.plausibility(), Plausibility::DEFAULT);
    for bad in [
        Plausibility { factor: 0.5, margin: 0.05 },
        Plausibility { factor: 2.0, margin: -0.1 },
        Plausibility { factor: f32::NAN, margin: 0.0 },
        Plausibility { factor: 2.0, margin: f32::NAN },
    ] {
        assert_eq!(dec.with_plausibility(bad).unwrap_err(), ConfigError::Plausibility, "{bad:?}");
    }
    assert!(dec.with_plausibility(Plausibility::OFF).is_ok());
}
