//! Sheared patches (issue 19): the sheared read against a dense gather written out from
//! the definition, the operator against gather x dense 5D basis in f64, adjointness, the
//! consistency score against every pair counted by hand, the disparity chosen on frames of
//! known integer disparity, and a range that picks 0 everywhere bit-identical to the
//! unsheared decode (tile and overlap decoders).

mod common;

use common::*;
use rand::Rng;
use slf_firmware::disparity::{Consistency, Disparity, MAX_DISPARITY};
use slf_firmware::*;

/// The sensor lenslet of patch lenslet `(s, t)`, view `(u, v)` of the window at `window`,
/// sheared to `d`, from the definition: view `w` of a lenslet of 3 views is shifted by
/// `-d (w - 1)` lenslets.
fn sheared(
    origin: (isize, isize),
    (s, t): (usize, usize),
    window: (usize, usize),
    (u, v): (usize, usize),
    d: i8,
) -> (isize, isize) {
    let d = d as isize;
    (
        origin.0 + s as isize - d * ((window.0 + u) as isize - 1),
        origin.1 + t as isize - d * ((window.1 + v) as isize - 1),
    )
}

#[test]
fn sheared_operator_matches_dense_gather_times_basis() {
    let (rows, cols) = SMALL.frame_size();
    for (seed, k, d, origin, window) in
        [(1, 1, 1i8, (3, 4), (0, 0)), (2, 2, -1, (4, 3), (1, 1)), (3, 1, 2, (3, 3), (1, 0)), (4, 3, -2, (0, 0), (0, 1))]
    {
        let mask = Mask::pixel(seed, k, 4, L3).unwrap();
        let dec = small_decoder(mask);
        let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(seed + 10);
        let (kd, n) = dense_kronecker(dict.synthesis());
        let mut r = rng(seed);
        let c: Vec<f32> = (0..n).map(|_| r.random_range(-1.0f32..1.0)).collect();
        // The sheared patch's values, dense in f64: K c.
        let x = dense_apply(&kd, n, &c);
        // Frames: noise everywhere, the patch's values where its sheared pixels are.
        let mut frames: Vec<Vec<f32>> =
            (0..k).map(|_| (0..rows * cols).map(|_| 10.0 + r.random_range(-1.0f32..1.0)).collect()).collect();
        // The dense gather: (patch value index, frame j, pixel) of every measurement.
        let mut gather = Vec::new();
        for s in 0..3 {
            for t in 0..3 {
                for u in 0..2 {
                    for v in 0..2 {
                        let (lr, lc) = sheared(origin, (s, t), window, (u, v), d);
                        if lr < 0 || lc < 0 || lr >= 10 || lc >= 11 {
                            continue;
                        }
                        let (row, col) = (lr as usize * 3 + window.0 + u, lc as usize * 3 + window.1 + v);
                        for (j, f) in frames.iter_mut().enumerate() {
                            let b = mask.band(j, row, col).unwrap() as usize;
                            let i = SmallShape::index(s, t, u, v, b);
                            f[row * cols + col] = 10.0 + x[i] as f32;
                            gather.push(i);
                        }
                    }
                }
            }
        }
        assert!(gather.len() >= 8, "case {seed}: the patch reads too little of the sensor");
        let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
        let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, 144>>::new());
        let o = PatchOrigin {
            lenslet_row: origin.0 as u16,
            lenslet_col: origin.1 as u16,
            view_row: window.0 as u8,
            view_col: window.1 as u8,
            disparity: Disparity::pixels(d),
        };
        let (flags, excluded) = dec.read_patch(o, &mut FrameSource::new(&raw), &mut ws).unwrap();
        assert!(flags.is_empty() && excluded == 0);
        // The fast operator: the separable synthesis of c, at the entries the read measured.
        let mut coeffs: [f32; 144] = c.clone().try_into().unwrap();
        let mut signal = [0.0f32; 144];
        slf_firmware::transform::synthesize(&dict, &mut coeffs, &mut signal);
        let m = ws.measurements();
        assert_eq!(m.count(), gather.len(), "case {seed}: measured entries");
        for &i in &gather {
            let y = m.get(i).unwrap_or_else(|| panic!("case {seed}: entry {i} not measured"));
            // What the sensor holds (the dense gather of K c) is what the read took...
            assert!((f64::from(y) - x[i]).abs() < 2e-6, "case {seed}: read {y} vs {}", x[i]);
            // ... and what the decoder's model predicts from c.
            assert!((f64::from(signal[i]) - x[i]).abs() < 1e-5, "case {seed}: model {} vs {}", signal[i], x[i]);
        }
    }
}

#[test]
fn sheared_operator_and_its_adjoint_agree() {
    let (rows, cols) = SMALL.frame_size();
    let mask = Mask::pixel(7, 2, 4, L3).unwrap();
    let dec = small_decoder(mask);
    let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(8);
    let mut r = rng(9);
    let frames: Vec<Vec<f32>> =
        (0..2).map(|_| (0..rows * cols).map(|_| 10.0 + r.random_range(0.0f32..1.0)).collect()).collect();
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
    for d in [-2i8, -1, 1, 2] {
        let o =
            PatchOrigin { lenslet_row: 4, lenslet_col: 4, view_row: 1, view_col: 0, disparity: Disparity::pixels(d) };
        let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, 144>>::new());
        dec.read_patch(o, &mut FrameSource::new(&raw), &mut ws).unwrap();
        let m = ws.measurements();
        let omega: Vec<usize> = (0..144).filter(|&i| m.get(i).is_some()).collect();
        assert!(omega.len() > 20);
        for trial in 0..3 {
            let mut c = [0.0f32; 144];
            c.iter_mut().for_each(|x| *x = r.random_range(-1.0..1.0));
            let mut y = [0.0f32; 144];
            omega.iter().for_each(|&i| y[i] = r.random_range(-1.0..1.0));
            // A c = (D c) on omega; A^T y = D^T (y zero-filled off omega).
            let (mut cc, mut ac) = (c, [0.0f32; 144]);
            slf_firmware::transform::synthesize(&dict, &mut cc, &mut ac);
            let (mut yy, mut aty) = (y, [0.0f32; 144]);
            slf_firmware::transform::analyze(&dict, &mut yy, &mut aty);
            let lhs: f64 = omega.iter().map(|&i| f64::from(ac[i]) * f64::from(y[i])).sum();
            let rhs: f64 = c.iter().zip(&aty).map(|(&a, &b)| f64::from(a) * f64::from(b)).sum();
            let scale: f64 = omega.iter().map(|&i| f64::from(ac[i]).abs() * f64::from(y[i]).abs()).sum();
            assert!((lhs - rhs).abs() <= 1e-5 * scale, "d {d} trial {trial}: {lhs} vs {rhs}");
        }
    }
}

#[test]
fn consistency_is_the_mean_squared_difference_of_same_band_pairs() {
    let mut r = rng(11);
    let mut score = Consistency::new();
    let (mut total, mut pairs) = (0.0f64, 0u32);
    for _point in 0..6 {
        let samples: Vec<(usize, f32)> =
            (0..r.random_range(0..30)).map(|_| (r.random_range(0..13), r.random_range(0.0..1.0))).collect();
        for &(b, y) in &samples {
            score.add(b, y);
        }
        score.end_point();
        for (i, a) in samples.iter().enumerate() {
            for b in &samples[i + 1..] {
                if a.0 == b.0 {
                    total += (f64::from(a.1) - f64::from(b.1)).powi(2);
                    pairs += 1;
                }
            }
        }
    }
    assert_eq!(score.pairs(), pairs);
    let want = total / f64::from(pairs);
    let got = f64::from(score.score().unwrap());
    assert!((got - want).abs() < 1e-5 * want, "{got} vs {want}");
    // A band out of range is ignored; no pair is no score.
    let mut lone = Consistency::new();
    lone.add(40, 1.0);
    lone.add(3, 1.0);
    lone.end_point();
    assert_eq!(lone.score(), None);
}

#[test]
fn ranges_are_checked_and_searched_nearest_zero_first() {
    assert_eq!(DisparityRange::new(1, 2), None, "0 must be a candidate");
    assert_eq!(DisparityRange::new(-MAX_DISPARITY - 1, 0), None);
    assert_eq!(DisparityRange::new(0, MAX_DISPARITY + 1), None);
    let r = DisparityRange::new(-2, 1).unwrap();
    let halves = |r: DisparityRange| r.candidates().map(|d| d.in_halves()).collect::<Vec<_>>();
    assert_eq!(halves(r), [0, -2, 2, -4]);
    assert_eq!(halves(DisparityRange::OFF), [0]);
    // With halves: every half pixel between the ends, nearest zero first.
    assert_eq!(halves(r.with_halves(true)), [0, -1, 1, -2, 2, -3, -4]);
    assert_eq!(halves(DisparityRange::OFF.with_halves(true)), [0]);
    // Lenslets of 5 views: view 0 or 4 is 2 from the centre, so d = 2 reaches 4 lenslets.
    assert_eq!((r.halo(5), r.halo(4), r.halo(3), DisparityRange::OFF.halo(5)), (4, 4, 2, 0));
}

// The paper's patch on lenslets of 5 x 5 views.
const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
const SENSOR: SensorGeometry = SensorGeometry { lenslets: (17, 19), lenslet: L5 };
type Decoder<'a> = TileDecoder<'a, PaperShape>;

/// A Lambertian scene at disparity `d` everywhere: the value of band `b` at sensor pixel
/// `(row, col)`. View `(u, v)` of lenslet `(y, x)` sees the scene point
/// `(y + d (u - 2), x + d (v - 2))` (the HCI convention), whose spectrum is a smooth random
/// texture.
fn scene(d: i32, seed: u64) -> impl Fn(usize, usize, usize) -> f32 {
    let mut r = rng(seed);
    // A texture over points -10..30 (beyond the sensor, where the shear reaches).
    let tex: Vec<[f32; 3]> =
        (0..40 * 40).map(|_| [r.random_range(0.1..0.9), r.random_range(-0.3..0.3), r.random()]).collect();
    move |row, col, b| {
        let (y, u, x, v) = ((row / 5) as i32, (row % 5) as i32, (col / 5) as i32, (col % 5) as i32);
        let (py, px) = (y + d * (u - 2), x + d * (v - 2));
        let t = tex[((py + 10).clamp(0, 39) * 40 + (px + 10).clamp(0, 39)) as usize];
        (t[0] + t[1] * (b as f32 / 12.0 - 0.5) + 0.05 * (t[2] * 6.0 + b as f32 * 0.3).sin()).clamp(0.02, 0.98)
    }
}

/// The raw frames of [`scene`] through `mask`.
fn plane(mask: &Mask, d: i32, seed: u64) -> Vec<Vec<f32>> {
    let (rows, cols) = SENSOR.frame_size();
    let value = scene(d, seed);
    (0..mask.snapshots())
        .map(|j| {
            (0..rows * cols)
                .map(|p| value(p / cols, p % cols, mask.band(j, p / cols, p % cols).unwrap() as usize))
                .collect()
        })
        .collect()
}

#[derive(Default)]
struct Collect(Vec<(PatchOrigin, Vec<f32>, bool)>);

impl PatchSink<PaperShape> for Collect {
    type Error = ();
    fn accept(&mut self, origin: PatchOrigin, patch: &[f32; 5200], r: &PatchReport) -> Result<(), ()> {
        self.0.push((origin, patch.to_vec(), r.fallback));
        Ok(())
    }
}

fn paper_decoder(mask: Mask<'static>) -> Decoder<'static> {
    Decoder::new(DecoderConfig {
        sensor: SENSOR,
        mask,
        raw: RawFormat::NORMALISED,
        defects: DefectList::EMPTY,
        sl0: Sl0Config::DEFAULT,
    })
    .unwrap()
}

#[test]
fn the_known_disparity_of_a_plane_is_chosen_off_the_edges() {
    let (rows, cols) = SENSOR.frame_size();
    for (seed, k, d) in [(1u64, 1u8, 1i32), (2, 1, -1), (3, 3, 2), (4, 1, 0)] {
        let mask = Mask::pixel(seed, k, 13, L5).unwrap();
        let frames = plane(&mask, d, seed);
        let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
        let dec = paper_decoder(mask).with_disparities(DisparityRange::new(-2, 2).unwrap());
        for r0 in 0..=12 {
            for c0 in 0..=14 {
                let got = dec.choose_disparity(r0, c0, &mut FrameSource::new(&raw)).unwrap();
                // Off the edges: the shear's halo (2 |d|) inside the sensor.
                let h = 2 * d.unsigned_abs() as usize;
                if r0 >= h && c0 >= h && r0 + 5 + h <= 17 && c0 + 5 + h <= 19 {
                    assert_eq!(i32::from(got.in_halves()), 2 * d, "seed {seed}, k {k}: block ({r0}, {c0})");
                }
            }
        }
    }
}

#[test]
fn the_sheared_fallback_adds_each_sheared_blocks_unsheared_patches_and_nothing_else() {
    let (rows, cols) = SENSOR.frame_size();
    let mask = Mask::pixel(6, 1, 13, L5).unwrap();
    let frames = plane(&mask, 1, 6);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
    let plain = paper_decoder(mask);
    let sheared = plain.with_disparities(DisparityRange::new(-1, 1).unwrap());
    let dct = Dictionary::dct();
    let mut ws = Box::new(PaperWorkspace::new());
    let run = |dec: &Decoder<'static>, ws: &mut PaperWorkspace| {
        let mut sink = Collect::default();
        dec.decode_frame(&dct, (2, 2), &mut FrameSource::new(&raw), &mut sink, ws);
        sink.0
    };
    let (edges, all, unsheared) =
        (run(&sheared, &mut ws), run(&sheared.with_sheared_fallback(true), &mut ws), run(&plain, &mut ws));
    let key = |o: &PatchOrigin| (o.lenslet_row, o.lenslet_col, o.view_row, o.view_col);
    // The sheared patches are the same with or without it.
    let main = |v: &[(PatchOrigin, Vec<f32>, bool)]| v.iter().filter(|p| !p.2).cloned().collect::<Vec<_>>();
    assert_eq!(main(&all), main(&edges));
    // One fallback for each window of each sheared block, equal to the unsheared decode's
    // patch there; the edge fallback alone covers fewer.
    let sheared_windows: Vec<_> =
        main(&all).iter().filter(|p| p.0.disparity != Disparity::ZERO).map(|p| key(&p.0)).collect();
    assert!(sheared_windows.len() >= 8, "{} sheared windows", sheared_windows.len());
    let fallbacks: Vec<_> = all.iter().filter(|p| p.2).collect();
    assert_eq!(fallbacks.iter().map(|p| key(&p.0)).collect::<Vec<_>>(), sheared_windows);
    for (o, values, _) in fallbacks {
        assert_eq!(o.disparity, Disparity::ZERO);
        let (_, twin, _) = unsheared.iter().find(|p| key(&p.0) == key(o)).unwrap();
        assert_eq!(values, twin, "{o:?}");
    }
    assert!(edges.iter().filter(|p| p.2).count() < all.iter().filter(|p| p.2).count());
}

#[test]
fn a_range_that_chooses_zero_everywhere_is_the_unsheared_decode_bit_for_bit() {
    let (rows, cols) = SENSOR.frame_size();
    let mask = Mask::pixel(5, 1, 13, L5).unwrap();
    // Disparity 0: every view of a lenslet sees the same spectrum.
    let frames = plane(&mask, 0, 5);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
    let plain = paper_decoder(mask);
    let searched = plain.with_disparities(DisparityRange::new(-1, 1).unwrap());
    let dct = Dictionary::dct();
    let mut ws = Box::new(PaperWorkspace::new());
    let (mut a, mut b) = (Collect::default(), Collect::default());
    plain.decode_frame(&dct, (2, 2), &mut FrameSource::new(&raw), &mut a, &mut ws);
    searched.decode_frame(&dct, (2, 2), &mut FrameSource::new(&raw), &mut b, &mut ws);
    assert!(!a.0.is_empty());
    assert!(b.0.iter().all(|(o, _, f)| o.disparity == Disparity::ZERO && !f), "a block was sheared or had a fallback");
    assert_eq!(a.0, b.0);

    // The overlap decoder keeps a halo of rows for sheared patches; with every block at
    // 0 its rows are the unsheared ones, bit for bit.
    let rows_of = |dec: Decoder<'static>| {
        let (rows, r) = overlap_rows(dec, &raw, 19);
        assert_eq!((r.uncovered, r.filled), (0, 0));
        rows
    };
    let (x, y) = (rows_of(plain), rows_of(searched));
    assert_eq!(x.len(), 17);
    assert_eq!(x, y);
}

/// The rows of an overlapped decode (stride 3, tapered) of `raw` with the DCT, through a
/// strip of `columns` lenslet columns, and its report.
fn overlap_rows(
    dec: Decoder<'static>,
    raw: &[RawFrame<f32>],
    columns: usize,
) -> (Vec<(u16, u16, Vec<f32>)>, OverlapReport) {
    let od = OverlapDecoder::new(dec, Overlap { stride: (3, 3), window: Window::Tapered, seeded: false }).unwrap();
    let mut strip = vec![0.0f32; od.strip_len(columns)];
    let mut out = Rows(Vec::new());
    let mut ws = Box::new(PaperWorkspace::new());
    let r = od.decode_frame(&Dictionary::dct(), &mut FrameSource::new(raw), &mut strip, &mut out, &mut ws).unwrap();
    (out.0, r)
}

struct Rows(Vec<(u16, u16, Vec<f32>)>);

impl RowSink for Rows {
    type Error = ();
    fn row(&mut self, row: u16, first_col: u16, values: &[f32]) -> Result<(), ()> {
        self.0.push((row, first_col, values.to_vec()));
        Ok(())
    }
}

#[test]
fn a_sheared_plane_decodes_better() {
    let (rows, cols) = SENSOR.frame_size();
    let mask = Mask::pixel(6, 1, 13, L5).unwrap();
    let frames = plane(&mask, 1, 6);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
    let truth = scene(1, 6);
    let decode = |dec: Decoder<'static>| {
        let (out, r) = overlap_rows(dec, &raw, 7);
        assert_eq!(r.uncovered, 0);
        // Mean squared error over the sensor.
        let mut err = 0.0f64;
        for (row, c0, values) in &out {
            // `(u, v, x, b)` over the band's columns.
            let width = values.len() / (25 * 13);
            for (i, x) in values.chunks(13).enumerate() {
                let (c, u, v) = (*c0 as usize + i % width, (i / width) / 5, (i / width) % 5);
                let p = (*row as usize * 5 + u) * cols + c * 5 + v;
                for (b, &xb) in x.iter().enumerate() {
                    err += f64::from(xb - truth(p / cols, p % cols, b)).powi(2);
                }
            }
        }
        err / (rows * cols * 13) as f64
    };
    let plain = paper_decoder(mask);
    let (flat, sheared) = (decode(plain), decode(plain.with_disparities(DisparityRange::new(-1, 1).unwrap())));
    let gain = 10.0 * (flat / sheared).log10();
    assert!(gain > 1.0, "shearing a plane at disparity 1 gained {gain:.2} dB");
}
