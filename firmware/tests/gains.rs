//! White balance: gains from band sums worked by hand, the frame estimate against a slow
//! f64 reference, and the balanced tile decode against the plain decode of a frame divided
//! by the gains by hand.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::gains::{MAX_RATIO, gains_from_sums};
use slf_firmware::shape::ValueCount;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
const SENSOR: SensorGeometry = SensorGeometry { lenslets: (10, 15), lenslet: L5 };
const ROWS: usize = 50;
const COLS: usize = 75;
type Decoder<'a> = TileDecoder<'a, PaperShape>;

#[test]
fn gains_from_sums_by_hand() {
    // Means 1, 2, 4 over three bands: mean of the means 7/3.
    let g = gains_from_sums(&[2.0, 8.0, 4.0], &[2, 4, 1]);
    for (a, b) in g.iter().zip([3.0 / 7.0, 6.0 / 7.0, 12.0 / 7.0]) {
        assert!((a - b).abs() < 1e-6, "{g:?}");
    }
    // A band darker than the brightest over MAX_RATIO keeps that floor: means 128, 1, 0.
    let g = gains_from_sums(&[128.0, 1.0, 0.0], &[1, 1, 1]);
    let floor = 128.0 / MAX_RATIO;
    let mean = (128.0 + 2.0 * floor) / 3.0;
    for (a, b) in g.iter().zip([128.0 / mean, floor / mean, floor / mean]) {
        assert!((a - b).abs() < 1e-6, "{g:?}");
    }
    // A band with no measurement takes the measured bands' mean gain: means 1, 3, none.
    let g = gains_from_sums(&[1.0, 3.0, 0.0], &[1, 1, 0]);
    for (a, b) in g.iter().zip([0.5, 1.5, 1.0]) {
        assert!((a - b).abs() < 1e-6, "{g:?}");
    }
    // A black frame, no measurement at all, and a non-finite sum: gains of 1.
    assert_eq!(gains_from_sums(&[0.0; 4], &[9; 4]), [1.0; 4]);
    assert_eq!(gains_from_sums(&[0.0; 4], &[0; 4]), [1.0; 4]);
    assert_eq!(gains_from_sums(&[f32::INFINITY, 1.0], &[1, 1]), [1.0; 2]);
}

/// Random frames with a steep tilt across the bands (band `b` scaled by `0.05 + b / 13`),
/// some samples invalid.
fn tilted_frames(mask: &Mask, seed: u64) -> Vec<Vec<f32>> {
    let mut r = rng(seed);
    (0..mask.snapshots())
        .map(|j| {
            (0..ROWS * COLS)
                .map(|p| {
                    let band = mask.band(j, p / COLS, p % COLS).unwrap() as f32;
                    match r.random_range(0..200) {
                        0 => f32::NAN,
                        1 => 1.5, // over range
                        _ => (0.05 + band / 13.0) * r.random_range(0.2f32..0.9),
                    }
                })
                .collect()
        })
        .collect()
}

fn config(mask: Mask<'static>, defects: DefectList<'static>) -> DecoderConfig<'static> {
    DecoderConfig {
        sensor: SENSOR,
        mask,
        raw: RawFormat::NORMALISED,
        defects,
        sl0: Sl0Config { min_bands: 0, ..Sl0Config::DEFAULT },
    }
}

#[test]
fn frame_estimate_matches_slow_reference() {
    static DEFECTS: [Pixel; 3] = [Pixel { row: 0, col: 0 }, Pixel { row: 7, col: 30 }, Pixel { row: 49, col: 74 }];
    for (seed, mask) in [(1, Mask::pixel(3, 1, 13, L5).unwrap()), (2, Mask::pixel(4, 3, 13, L5).unwrap())] {
        let frames = tilted_frames(&mask, seed);
        let dec = Decoder::new(config(mask, DefectList::new(&DEFECTS).unwrap())).unwrap();
        let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, ROWS, COLS).unwrap()).collect();
        let g = dec.estimate_gains(&mut FrameSource::new(&raw)).unwrap();
        // The reference: every valid, non-defective sample in f64, per band.
        let mut sums = [0.0f64; 13];
        let mut counts = [0u64; 13];
        for (j, f) in frames.iter().enumerate() {
            for (p, &x) in f.iter().enumerate() {
                let (row, col) = (p / COLS, p % COLS);
                if DEFECTS.iter().any(|d| (d.row as usize, d.col as usize) == (row, col)) || !(0.0..=1.0).contains(&x) {
                    continue;
                }
                let b = mask.band(j, row, col).unwrap() as usize;
                sums[b] += f64::from(x);
                counts[b] += 1;
            }
        }
        let means: Vec<f64> = (0..13).map(|b| sums[b] / counts[b] as f64).collect();
        let mean = means.iter().sum::<f64>() / 13.0;
        for b in 0..13 {
            let want = means[b] / mean;
            assert!((f64::from(g[b]) - want).abs() < 1e-5 * want, "seed {seed} band {b}: {} vs {want}", g[b]);
        }
        // The tilt is recovered: band 12's gain over band 0's is (0.05 + 12/13) / 0.05.
        let ratio = f64::from(g[12] / g[0]);
        assert!((ratio / 19.46 - 1.0).abs() < 0.1, "ratio {ratio}");
    }
}

#[derive(Default)]
struct Collect(Vec<(PatchOrigin, Vec<f32>)>);

impl PatchSink<PaperShape> for Collect {
    type Error = ();
    fn accept(&mut self, origin: PatchOrigin, patch: &[f32; 5200], _: &PatchReport) -> Result<(), ()> {
        self.0.push((origin, patch.to_vec()));
        Ok(())
    }
}

fn decode(dec: &Decoder, frames: &[Vec<f32>]) -> Collect {
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, ROWS, COLS).unwrap()).collect();
    let mut sink = Collect::default();
    let mut ws = Box::new(PaperWorkspace::new());
    let r = dec.decode_frame(&Dictionary::dct(), (2, 3), &mut FrameSource::new(&raw), &mut sink, &mut ws);
    assert_eq!((r.failed_tiles, r.patches.failed), (0, 0));
    sink
}

#[test]
fn balanced_decode_is_the_plain_decode_of_the_divided_frame() {
    let mask = Mask::pixel(5, 3, 13, L5).unwrap();
    let frames: Vec<Vec<f32>> = tilted_frames(&mask, 7)
        .into_iter()
        .map(|f| f.into_iter().map(|x| if x.is_finite() { x.min(1.0) } else { 0.5 }).collect())
        .collect();
    let plain = Decoder::new(config(mask, DefectList::EMPTY)).unwrap();
    let gains: [f32; 13] = core::array::from_fn(|b| 0.05 + b as f32 / 13.0);
    let balanced = plain.with_gains(&gains).unwrap();
    assert_eq!(balanced.gains(), &gains);
    let got = decode(&balanced, &frames);

    // By hand: each sample divided by its band's gain, decoded plainly with room above
    // white (the divided samples exceed 1), then each band multiplied back and clamped.
    let divided: Vec<Vec<f32>> = frames
        .iter()
        .enumerate()
        .map(|(j, f)| {
            f.iter().enumerate().map(|(p, &x)| x / gains[mask.band(j, p / COLS, p % COLS).unwrap() as usize]).collect()
        })
        .collect();
    let wide = RawFormat { black: 0.0, white: 1.0, max_valid: 1e6 };
    let plain_out = decode(&plain, &frames);
    let reference =
        decode(&Decoder::new(DecoderConfig { raw: wide, ..config(mask, DefectList::EMPTY) }).unwrap(), &divided);
    assert_eq!(got.0.len(), 24);
    let mut differs = 0;
    for (((o, a), (o2, b)), (_, p)) in got.0.iter().zip(&reference.0).zip(&plain_out.0) {
        assert_eq!(o, o2);
        for (i, (&x, &y)) in a.iter().zip(b).enumerate() {
            let want = (y * gains[i % 13]).clamp(0.0, 1.0);
            assert!((x - want).abs() <= 1e-6, "{o:?} value {i}: {x} vs {want}");
        }
        differs += usize::from(a != p);
    }
    assert!(differs > 0, "the gains changed nothing");

    // Gains of 1 are the plain decode, bit for bit.
    let ones = plain.with_gains(&[1.0; 13]).unwrap();
    assert_eq!(decode(&ones, &frames).0, plain_out.0);
}

#[test]
fn bad_gains_are_refused() {
    let dec = Decoder::new(config(Mask::pixel(5, 1, 13, L5).unwrap(), DefectList::EMPTY)).unwrap();
    for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let mut g = [1.0f32; 13];
        g[4] = bad;
        assert_eq!(dec.with_gains(&g).err(), Some(ConfigError::Gains), "gain {bad}");
        let mut m = Measurements::<ValueCount<5200>>::new();
        assert_eq!(m.set_gains(&g), Err(SolveError::BadGains));
        assert_eq!(m.gains(), &[1.0; 32], "a refused set leaves the gains");
    }
    let mut m = Measurements::<ValueCount<5200>>::new();
    assert_eq!(m.set_gains(&[1.0; 33]), Err(SolveError::BadGains));
}
