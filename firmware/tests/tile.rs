//! The tile decoder: frames in RAM to patches, bad samples flagged and left out, bad
//! patches and failing tiles losing only themselves.

mod common;

use common::*;
use slf_firmware::raw::ReadError;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
/// 10 x 15 lenslets of 5 x 5 views: 2 x 3 blocks of the paper's patch, 50 x 75 pixels.
const SENSOR: SensorGeometry = SensorGeometry { lenslets: (10, 15), lenslet: L5 };
type Decoder<'a> = TileDecoder<'a, PaperShape>;

/// A smooth 5D light field over the whole sensor, `[s][t][u][v][b]`.
fn light_field() -> Vec<f32> {
    let (s, t) = (10, 15);
    let mut l = vec![0.0; s * t * 25 * 13];
    for (i, x) in l.iter_mut().enumerate() {
        let b = i % 13;
        let v = (i / 13) % 5;
        let u = (i / 65) % 5;
        let tt = (i / 325) % t;
        let ss = i / (325 * t);
        *x = 0.45
            + 0.2 * ((ss as f32) * 0.4 + (tt as f32) * 0.25).sin()
            + 0.15 * ((b as f32) * 0.5 + ss as f32 * 0.1).cos()
            + 0.01 * (u as f32 - 2.0) * (v as f32 - 2.0);
    }
    l
}

fn lf_at(l: &[f32], s: usize, t: usize, u: usize, v: usize, b: usize) -> f32 {
    l[((((s * 15) + t) * 5 + u) * 5 + v) * 13 + b]
}

/// The raw frames a camera with `mask` records of `l`, normalised units.
fn capture(l: &[f32], mask: &Mask) -> Vec<Vec<f32>> {
    let (rows, cols) = SENSOR.frame_size();
    (0..mask.snapshots())
        .map(|j| {
            (0..rows * cols)
                .map(|p| {
                    let (row, col) = (p / cols, p % cols);
                    let band = mask.band(j, row, col).unwrap() as usize;
                    lf_at(l, row / 5, col / 5, row % 5, col % 5, band)
                })
                .collect()
        })
        .collect()
}

/// The truth of the patch at `origin`, in the patch layout.
fn truth_patch(l: &[f32], o: PatchOrigin) -> Vec<f32> {
    (0..5200)
        .map(|i| {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            lf_at(
                l,
                o.lenslet_row as usize + s,
                o.lenslet_col as usize + t,
                o.view_row as usize + u,
                o.view_col as usize + v,
                b,
            )
        })
        .collect()
}

#[derive(Default)]
struct Collect {
    accepted: Vec<(PatchOrigin, Vec<f32>, PatchReport)>,
    rejected: Vec<(PatchOrigin, SolveError)>,
}

impl PatchSink<PaperShape> for Collect {
    type Error = ();
    fn accept(&mut self, origin: PatchOrigin, patch: &[f32; 5200], report: &PatchReport) -> Result<(), ()> {
        self.accepted.push((origin, patch.to_vec(), *report));
        Ok(())
    }
    fn reject(&mut self, origin: PatchOrigin, error: SolveError) -> Result<(), ()> {
        self.rejected.push((origin, error));
        Ok(())
    }
}

fn config(mask: Mask<'static>) -> DecoderConfig<'static> {
    DecoderConfig {
        sensor: SENSOR,
        mask,
        raw: RawFormat::NORMALISED,
        defects: DefectList::EMPTY,
        // Every patch solved, so that each is the solver's (kronecker patches measure
        // fewer than `min_bands` bands; interpolation is tested in `interpolate.rs` and
        // the host's `baselines.rs`).
        sl0: Sl0Config { min_bands: 0, ..Sl0Config::DEFAULT },
    }
}

fn decode_all(dec: &Decoder, frames: &[Vec<f32>], dict: &Dictionary<PaperShape>) -> (Collect, TileReport) {
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let mut src = FrameSource::new(&raw);
    let mut sink = Collect::default();
    let mut ws = Box::new(PaperWorkspace::new());
    let r = dec.decode_frame(dict, (1, 2), &mut src, &mut sink, &mut ws);
    assert_eq!(r.failed_tiles, 0);
    assert_eq!(r.tiles, 4); // 2 x 3 blocks in tiles of 1 x 2 patches: 2 x 2 tiles
    (sink, r.patches)
}

#[test]
fn tile_decode_is_the_solver_on_the_cameras_measurements() {
    let l = light_field();
    let dict = Dictionary::dct();
    for mask in [
        Mask::pixel(3, 3, 13, L5).unwrap(),
        Mask::lenslet(3, 1, 13, L5).unwrap(),
        Mask::kronecker(3, 2, 13, L5, (5, 5)).unwrap(),
    ] {
        let dec = Decoder::new(config(mask)).unwrap();
        assert_eq!(dec.windows().collect::<Vec<_>>(), [(0, 0), (0, 1), (1, 0), (1, 1)]);
        let (sink, report) = decode_all(&dec, &capture(&l, &mask), &dict);
        assert_eq!(report, TileReport { decoded: 24, ..TileReport::default() });
        assert_eq!(sink.accepted.len(), 24);
        for (origin, patch, rep) in &sink.accepted {
            let truth = truth_patch(&l, *origin);
            let mut ws = Box::new(PaperWorkspace::new());
            let (l0, v0) = ((origin.lenslet_row, origin.lenslet_col), (origin.view_row, origin.view_col));
            measure_window(&mask, (l0.0.into(), l0.1.into()), (v0.0.into(), v0.1.into()), &truth, &mut ws);
            let out = solve(&dict, &dec.config().sl0, &mut ws).unwrap();
            // The tile decoder clamps to the physical range: normalised samples, [0, 1].
            let clamped: Vec<f32> = ws.patch().iter().map(|x| x.clamp(0.0, 1.0)).collect();
            assert_eq!(&clamped[..], &patch[..], "{:?} {origin:?}", mask.family());
            assert_eq!(out, rep.outcome);
            assert_eq!(rep.measured as usize, 400 * mask.snapshots());
            assert!(patch.iter().all(|x| x.is_finite()));
            if mask.family() == MaskFamily::Pixel {
                let e = rel_err32(patch, &truth);
                assert!(e < 0.05, "{origin:?}: rel err {e}");
            }
        }
    }
}

#[test]
fn sixteen_bit_frames_with_black_level() {
    let l = light_field();
    let mask = Mask::pixel(8, 3, 13, L5).unwrap();
    let raw = RawFormat::bits(12, 64.0);
    let frames: Vec<Vec<u16>> = capture(&l, &mask)
        .iter()
        .map(|f| f.iter().map(|&x| (64.0 + x * (4095.0 - 64.0)).round() as u16).collect())
        .collect();
    let dec = Decoder::new(DecoderConfig { raw, ..config(mask) }).unwrap();
    let rf: Vec<RawFrame<u16>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let mut sink = Collect::default();
    let mut ws = Box::new(PaperWorkspace::new());
    let r = dec.decode_frame(&Dictionary::dct(), (2, 3), &mut FrameSource::new(&rf), &mut sink, &mut ws);
    assert_eq!((r.tiles, r.patches.decoded, r.patches.flagged), (1, 24, 0));
    for (origin, patch, _) in &sink.accepted {
        let e = rel_err32(patch, &truth_patch(&l, *origin));
        assert!(e < 0.05, "{origin:?}: rel err {e}");
    }
}

#[test]
fn bad_samples_are_flagged_left_out_and_lose_nothing_else() {
    let l = light_field();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let dict = Dictionary::dct();
    let clean = capture(&l, &mask);
    let dec = Decoder::new(config(mask)).unwrap();
    let (clean_sink, _) = decode_all(&dec, &clean, &dict);

    // Block (0, 0) gets NaN, +inf, a negative and an over-range sample, all in window (0, 0)
    // (lenslet row 1, view rows 0..4) and also a defective pixel.
    let mut bad = clean.clone();
    bad[0][5 * 75 + 6] = f32::NAN;
    bad[1][6 * 75 + 7] = f32::INFINITY;
    bad[2][7 * 75 + 8] = -0.5;
    bad[0][8 * 75 + 8] = 1.5;
    let defects = [Pixel { row: 5, col: 10 }];
    let dec = Decoder::new(DecoderConfig { defects: DefectList::new(&defects).unwrap(), ..config(mask) }).unwrap();
    let (sink, report) = decode_all(&dec, &bad, &dict);
    assert_eq!(report.decoded, 24);
    assert!(report.flagged >= 1);
    for ((origin, patch, rep), (o2, clean_patch, _)) in sink.accepted.iter().zip(&clean_sink.accepted) {
        assert_eq!(origin, o2);
        assert!(patch.iter().all(|x| x.is_finite()));
        let touched = origin.lenslet_row == 0 && origin.lenslet_col == 0;
        if !touched {
            assert!(rep.flags.is_empty());
            assert_eq!(patch, clean_patch, "{origin:?} changed by bad samples elsewhere");
            continue;
        }
        if (origin.view_row, origin.view_col) == (0, 0) {
            for f in [PatchFlags::NON_FINITE, PatchFlags::NEGATIVE, PatchFlags::OVER_RANGE, PatchFlags::DEFECTIVE] {
                assert!(rep.flags.contains(f), "{origin:?} missing {f:?} in {:?}", rep.flags);
            }
            assert!(rep.outcome.iterations <= Sl0Config::DEFAULT.max_iterations);
            assert_eq!(rep.excluded, 4 + 3); // four bad samples + one defective pixel x 3 snapshots
            assert_eq!(rep.measured, 1200 - 7);
            // Still a good decode: the bad samples were left out, not fed in.
            let e = rel_err32(patch, &truth_patch(&l, *origin));
            assert!(e < 0.05, "{origin:?}: rel err {e}");
        }
    }
}

#[test]
fn a_patch_without_measurements_is_rejected_and_the_tile_goes_on() {
    let l = light_field();
    let mask = Mask::lenslet(3, 2, 13, L5).unwrap();
    let mut frames = capture(&l, &mask);
    // Every sample of block (1, 2) (lenslet rows 5..10, cols 10..15) is NaN in both snapshots.
    for f in &mut frames {
        for row in 25..50 {
            for col in 50..75 {
                f[row * 75 + col] = f32::NAN;
            }
        }
    }
    // Every pixel of block (0, 1) is on the defect list.
    let defects: Vec<Pixel> = (0..25).flat_map(|r| (25..50).map(move |c| Pixel { row: r, col: c })).collect();
    let defects: &'static [Pixel] = Box::leak(defects.into_boxed_slice());
    let dec = Decoder::new(DecoderConfig { defects: DefectList::new(defects).unwrap(), ..config(mask) }).unwrap();
    let (sink, report) = decode_all(&dec, &frames, &Dictionary::dct());
    assert_eq!(report, TileReport { decoded: 16, failed: 8, ..TileReport::default() });
    assert_eq!(sink.rejected.len(), 8);
    for (o, e) in &sink.rejected {
        assert_eq!(*e, SolveError::NoMeasurements);
        assert!(matches!((o.lenslet_row, o.lenslet_col), (5, 10) | (0, 5)), "{o:?}");
    }
    for (_, patch, _) in &sink.accepted {
        assert!(patch.iter().all(|x| x.is_finite()));
    }
}

/// A source that fails on one row, as a bus error would.
struct Flaky<'a> {
    inner: FrameSource<'a, RawFrame<'a, f32>>,
    bad_row: usize,
}

impl TileSource for Flaky<'_> {
    type Error = ReadError;
    fn read(&mut self, snapshot: usize, row: usize, col: usize, out: &mut [f32]) -> Result<(), ReadError> {
        if row == self.bad_row && col >= 25 {
            return Err(ReadError::OutOfBounds { row: row as u32, col: col as u32 });
        }
        self.inner.read(snapshot, row, col, out)
    }
}

#[test]
fn a_failing_tile_is_abandoned_and_the_frame_goes_on() {
    let l = light_field();
    let mask = Mask::pixel(1, 1, 13, L5).unwrap();
    let frames = capture(&l, &mask);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let dec = Decoder::new(config(mask)).unwrap();
    let mut src = Flaky { inner: FrameSource::new(&raw), bad_row: 31 };
    let mut sink = Collect::default();
    let mut ws = Box::new(PaperWorkspace::new());
    // Tiles of one patch: the six blocks; row 31, col >= 25 is in blocks (1, 1) and (1, 2).
    let r = dec.decode_frame(&Dictionary::dct(), (1, 1), &mut src, &mut sink, &mut ws);
    assert_eq!(r.tiles, 6);
    assert_eq!(r.failed_tiles, 2);
    assert_eq!(r.patches.decoded, 16);
    let (tile, err) = r.first_failure.unwrap();
    assert_eq!((tile.lenslet_row, tile.lenslet_col), (5, 5));
    assert!(matches!(err, TileError::Source(ReadError::OutOfBounds { row: 31, .. })));
    assert!(sink.accepted.iter().all(|(o, ..)| o.lenslet_row == 0 || o.lenslet_col == 0));
}

#[test]
fn tile_geometry_is_checked() {
    let mask = Mask::pixel(1, 1, 13, L5).unwrap();
    let dec = Decoder::new(config(mask)).unwrap();
    let frames = [vec![0.5f32; 50 * 75]];
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let mut ws = Box::new(PaperWorkspace::new());
    let dict = Dictionary::dct();
    for tile in [
        Tile { lenslet_row: 6, lenslet_col: 0, lenslet_rows: 5, lenslet_cols: 5 },
        Tile { lenslet_row: 0, lenslet_col: 0, lenslet_rows: 4, lenslet_cols: 5 },
        Tile { lenslet_row: 5, lenslet_col: 0, lenslet_rows: 10, lenslet_cols: 5 },
        Tile { lenslet_row: 0, lenslet_col: 15, lenslet_rows: 5, lenslet_cols: 5 },
        Tile { lenslet_row: 0, lenslet_col: 0, lenslet_rows: 0, lenslet_cols: 5 },
    ] {
        let mut sink = Collect::default();
        let r = dec.decode_tile(&dict, tile, &mut FrameSource::new(&raw), &mut sink, &mut ws);
        assert_eq!(r.unwrap_err(), TileError::Geometry, "{tile:?}");
        assert!(sink.accepted.is_empty());
    }
    assert_eq!(
        RawFrame::new(&frames[0][..10], 50, 75).unwrap_err(),
        SensingError::FrameSize { expected: 3750, found: 10 }
    );
    // A frame with fewer snapshots than the mask: the source says so, per tile.
    let mask3 = Mask::pixel(1, 3, 13, L5).unwrap();
    let dec3 = Decoder::new(config(mask3)).unwrap();
    let mut sink = Collect::default();
    let r = dec3.decode_frame(&dict, (1, 1), &mut FrameSource::new(&raw), &mut sink, &mut ws);
    assert_eq!(r.failed_tiles, 6);
    assert!(matches!(r.first_failure, Some((_, TileError::Source(ReadError::NoSuchSnapshot { snapshot: 1 })))));
}

#[test]
fn decoder_config_is_checked() {
    let m = Mask::pixel(1, 1, 13, L5).unwrap();
    let err = |c| Decoder::new(c).unwrap_err();
    let l4 = LensletSize { rows: 4, cols: 5 };
    assert_eq!(err(config(Mask::pixel(1, 1, 13, l4).unwrap())), ConfigError::LensletMismatch);
    let small = SensorGeometry { lenslets: (10, 10), lenslet: LensletSize { rows: 3, cols: 3 } };
    let m3 = Mask::pixel(1, 1, 13, small.lenslet).unwrap();
    assert_eq!(err(DecoderConfig { sensor: small, ..config(m3) }), ConfigError::PatchViews);
    assert_eq!(err(config(Mask::pixel(1, 1, 12, L5).unwrap())), ConfigError::BandMismatch);
    assert_eq!(err(config(Mask::kronecker(1, 1, 13, L5, (4, 4)).unwrap())), ConfigError::BlockMismatch);
    let bad_raw = RawFormat { black: 1.0, white: 1.0, max_valid: 1.0 };
    assert_eq!(err(DecoderConfig { raw: bad_raw, ..config(m) }), ConfigError::RawFormat);
    // Finite levels whose difference is not (issue 41, item 11): every value would
    // normalise to 0.
    let huge = RawFormat { black: -3e38, white: 3e38, max_valid: 1.0 };
    assert!((huge.white - huge.black).is_infinite());
    assert_eq!(err(DecoderConfig { raw: huge, ..config(m) }), ConfigError::RawFormat);
    let bad_sl0 = Sl0Config { steps: 0, ..Sl0Config::DEFAULT };
    assert_eq!(
        err(DecoderConfig { sl0: bad_sl0, ..config(m) }),
        ConfigError::Solver(SolveError::InvalidConfig { field: "steps" })
    );
}

#[test]
fn full_view_patches_need_one_window() {
    let l = light_field();
    let mask = Mask::pixel(2, 3, 13, L5).unwrap();
    let frames = capture(&l, &mask);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let dec = TileDecoder::<FullViewShape>::new(config(mask)).unwrap();
    assert_eq!(dec.windows().count(), 1);
    struct Count(usize, f64);
    impl PatchSink<FullViewShape> for Count {
        type Error = ();
        fn accept(&mut self, _: PatchOrigin, p: &[f32; 8125], _: &PatchReport) -> Result<(), ()> {
            self.0 += 1;
            self.1 += p.iter().map(|&x| f64::from(x)).sum::<f64>();
            Ok(())
        }
    }
    let mut sink = Count(0, 0.0);
    let mut ws = Box::new(Workspace::<FullViewShape>::new());
    let r = dec.decode_frame(&Dictionary::dct(), (2, 3), &mut FrameSource::new(&raw), &mut sink, &mut ws);
    assert_eq!((r.patches.decoded, sink.0), (6, 6));
    let mean = sink.1 / (6.0 * 8125.0);
    let truth_mean = l.iter().map(|&x| f64::from(x)).sum::<f64>() / l.len() as f64;
    assert!((mean - truth_mean).abs() < 0.01, "mean {mean} vs {truth_mean}");
}

#[test]
fn tiles_cover_every_lenslet_of_any_sensor() {
    for (rows, cols) in [(10u16, 15u16), (12, 13), (5, 9), (4, 20), (7, 7)] {
        let sensor = SensorGeometry { lenslets: (rows, cols), lenslet: L5 };
        let mask = Mask::pixel(1, 1, 13, L5).unwrap();
        let dec = Decoder::new(DecoderConfig { sensor, ..config(mask) }).unwrap();
        for per in [(1u16, 1u16), (2, 3), (100, 100)] {
            let mut covered = vec![0u32; rows as usize * cols as usize];
            for t in dec.tiles(per) {
                assert!(t.lenslet_rows % 5 == 0 && t.lenslet_cols % 5 == 0, "{t:?}");
                assert!(t.lenslet_row + t.lenslet_rows <= rows && t.lenslet_col + t.lenslet_cols <= cols, "{t:?}");
                assert!(t.lenslet_rows <= 5 * per.0 && t.lenslet_cols <= 5 * per.1);
                for r in t.lenslet_row..t.lenslet_row + t.lenslet_rows {
                    for c in t.lenslet_col..t.lenslet_col + t.lenslet_cols {
                        covered[r as usize * cols as usize + c as usize] += 1;
                    }
                }
            }
            if rows < 5 || cols < 5 {
                assert!(covered.iter().all(|&c| c == 0), "sensor smaller than a patch");
            } else {
                assert!(covered.iter().all(|&c| c >= 1), "{rows}x{cols} per {per:?}: uncovered lenslet");
                // Grid, row strip, column strip and their corner at most.
                assert!(covered.iter().all(|&c| c <= 4));
            }
        }
    }
}

/// Seeds from the truth, as a frame's first pass would give them (sensor units).
struct TruthSeed<'a>(&'a [f32], bool);

impl PatchSeed<PaperShape> for TruthSeed<'_> {
    fn seed(&mut self, origin: PatchOrigin, patch: &mut [f32; 5200]) -> bool {
        patch.copy_from_slice(&truth_patch(self.0, origin));
        if self.1 {
            patch[17] = f32::NAN;
        }
        true
    }
}

/// A seeded tile decode is the model's seeded decode of each patch from its seed divided
/// by the band gains (written out here), multiplied back and clamped; a seed with a NaN is
/// no seed (the decode from nothing, bit for bit), and so is [`NoSeed`].
#[test]
fn a_seeded_tile_decode_starts_each_patch_from_its_balanced_seed() {
    let l = light_field();
    let dict = Dictionary::dct();
    let mask = Mask::pixel(3, 1, 13, L5).unwrap();
    let gains: [f32; 13] = core::array::from_fn(|b| 0.6 + 0.07 * b as f32);
    let dec = Decoder::new(config(mask)).unwrap().with_gains(&gains).unwrap();
    let frames = capture(&l, &mask);
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let tile = Tile { lenslet_row: 0, lenslet_col: 5, lenslet_rows: 5, lenslet_cols: 5 };
    let mut ws = Box::new(PaperWorkspace::new());
    // One tile into a sink of its own, from nothing (`None`) or seeded by `seed`.
    let run = |seed: Option<&mut dyn PatchSeed<PaperShape>>| {
        let (mut sink, mut ws) = (Collect::default(), Box::new(PaperWorkspace::new()));
        let mut src = FrameSource::new(&raw);
        match seed {
            None => dec.decode_tile(&dict, tile, &mut src, &mut sink, &mut ws),
            Some(q) => dec.decode_tile_seeded(&dict, tile, &mut src, q, &mut sink, &mut ws),
        }
        .unwrap();
        sink
    };
    let cold = run(None);
    let none = run(Some(&mut NoSeed));
    let nan = run(Some(&mut TruthSeed(&l, true)));
    let seeded = run(Some(&mut TruthSeed(&l, false)));
    assert_eq!(cold.accepted.len(), 4);
    for (a, b) in cold.accepted.iter().zip(&none.accepted) {
        assert_eq!((a.0, &a.1, a.2), (b.0, &b.1, b.2), "NoSeed");
    }
    for (a, b) in cold.accepted.iter().zip(&nan.accepted) {
        assert_eq!((a.0, &a.1, a.2), (b.0, &b.1, b.2), "a NaN seed");
    }
    for ((origin, patch, report), (_, cold_patch, cold_report)) in seeded.accepted.iter().zip(&cold.accepted) {
        let truth = truth_patch(&l, *origin);
        // By hand: the measurements read as the decoder reads them, the seed balanced.
        dec.read_patch(*origin, &mut FrameSource::new(&raw), &mut ws).unwrap();
        for (i, x) in ws.patch_mut().iter_mut().enumerate() {
            *x = truth[i] / gains[i % 13];
        }
        let out = dict.decode_seeded(&dec.config().sl0, &mut ws).unwrap();
        let expected: Vec<f32> =
            ws.patch().iter().enumerate().map(|(i, x)| (x * gains[i % 13]).clamp(0.0, 1.0)).collect();
        assert_eq!(&expected[..], &patch[..], "{origin:?}");
        assert_eq!((out.outcome, out.solves), (report.outcome, 1));
        assert!(report.outcome.iterations < cold_report.outcome.iterations);
        let (es, ec) = (rel_err32(patch, &truth), rel_err32(cold_patch, &truth));
        assert!(es < ec, "{origin:?}: seeded from the truth {es}, cold {ec}");
    }
}

/// `with_view_gains`: each sample of view `(u, v)` of a lenslet in region `(i, j)` is divided
/// by that region's gain for the view, region `(i, j)` holding lenslet row `r` when
/// `r * rows / S == i` (columns likewise). Written out here from that definition: with gains
/// that are powers of two the division is exact, so the decode with the table equals, bit for
/// bit, the decode without it of the frames divided by hand. (Issue 51: before, only the
/// host's calibration test, with its fixture's region count written in, reached it.)
#[test]
fn view_gains_divide_each_view_of_each_region() {
    let l = light_field();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let frames = capture(&l, &mask);
    let (rows, cols) = (2usize, 3usize);
    // Gains of 1, 2 and 4 (values only fall: none reaches the saturation level).
    let gain = |i: usize, j: usize, u: usize, v: usize| [1.0f32, 2.0, 4.0][(i + 2 * j + u + 3 * v) % 3];
    let mut table = Vec::new();
    for i in 0..rows {
        for j in 0..cols {
            for u in 0..5 {
                for v in 0..5 {
                    table.push(gain(i, j, u, v));
                }
            }
        }
    }
    let divided: Vec<Vec<f32>> = frames
        .iter()
        .map(|f| {
            f.iter()
                .enumerate()
                .map(|(p, &x)| {
                    let (row, col) = (p / 75, p % 75);
                    let (i, j) = ((row / 5) * rows / 10, (col / 5) * cols / 15);
                    x / gain(i, j, row % 5, col % 5)
                })
                .collect()
        })
        .collect();
    let dict = Dictionary::dct();
    let regions = (rows as u16, cols as u16);
    let gained = Decoder::new(config(mask)).unwrap().with_view_gains(Some((&table, regions))).unwrap();
    assert_eq!(gained.view_gains(), Some((&table[..], regions)));
    let (a, ra) = decode_all(&gained, &frames, &dict);
    let (b, rb) = decode_all(&Decoder::new(config(mask)).unwrap(), &divided, &dict);
    assert_eq!(ra, rb);
    assert_eq!(a.accepted.len(), 24);
    for ((oa, pa, _), (ob, pb, _)) in a.accepted.iter().zip(&b.accepted) {
        assert_eq!(oa, ob);
        assert_eq!(pa, pb, "{oa:?}");
    }
    // A table that is not one gain per view and region, in [1/64, 64], is refused.
    let refuse = |g: &[f32], r: (u16, u16)| Decoder::new(config(mask)).unwrap().with_view_gains(Some((g, r))).err();
    assert_eq!(refuse(&table, (0, 3)), Some(ConfigError::ViewGains));
    assert_eq!(refuse(&table, (11, 3)), Some(ConfigError::ViewGains)); // more regions than lenslet rows
    assert_eq!(refuse(&table[1..], regions), Some(ConfigError::ViewGains));
    for bad in [0.0, 65.0, f32::NAN] {
        let mut t = table.clone();
        t[7] = bad;
        assert_eq!(refuse(&t, regions), Some(ConfigError::ViewGains), "{bad}");
    }
    assert!(Decoder::new(config(mask)).unwrap().with_view_gains(None).unwrap().view_gains().is_none());
}

/// `FrameSource::with_flat` (issue 65, item 12): frames a host had already divided by a
/// per-pixel flat, with that flat given to the source, carry the same error estimate as the
/// raw frames decoded with the flat as view gains, bit for bit (gains of powers of two: every
/// division exact). The noise term is what the flat changes: without it the divided frames'
/// estimates differ (the noise of a pixel at gain 4 counted 16 times too small). A flat that
/// does not cover the frames is refused; one larger (frames cropped to its top-left corner)
/// is read at the frames' pixels.
#[test]
fn a_sources_flat_counts_in_the_error_estimate_as_the_view_gains_do() {
    let l = light_field();
    let mask = Mask::pixel(3, 3, 13, L5).unwrap();
    let frames = capture(&l, &mask);
    let gain = |p: usize| [1.0f32, 2.0, 4.0][(p / 75 % 5 + 3 * (p % 75 % 5)) % 3];
    // One region: the table is one gain a view.
    let table: Vec<f32> = (0..25).map(|i| gain((i / 5) * 75 + i % 5)).collect();
    let flat: Vec<f32> = (0..50 * 75).map(gain).collect();
    let divided: Vec<Vec<f32>> =
        frames.iter().map(|f| f.iter().enumerate().map(|(p, &x)| x / gain(p)).collect()).collect();
    let noisy = |mask| {
        let mut c = config(mask);
        c.sl0.noise = 0.004;
        c.sl0.shot = 0.002;
        Decoder::new(c).unwrap().with_error_estimate(Some(HoldOut::DEFAULT)).unwrap()
    };
    let dict = Dictionary::dct();
    let run = |dec: &Decoder, frames: &[Vec<f32>], flat: Option<&[f32]>| {
        let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
        let flat = flat.map(|f| RawFrame::new(f, 50, 75).unwrap());
        let mut src = FrameSource::new(&raw);
        if let Some(f) = &flat {
            src = src.with_flat(f).unwrap();
        }
        let mut sink = Collect::default();
        let r = dec.decode_frame(&dict, (1, 2), &mut src, &mut sink, &mut Box::new(PaperWorkspace::new()));
        assert_eq!(r.failed_tiles, 0);
        sink.accepted.iter().map(|(o, _, rep)| (*o, rep.error)).collect::<Vec<_>>()
    };
    let gained = noisy(mask).with_view_gains(Some((&table, (1, 1)))).unwrap();
    let want = run(&gained, &frames, None);
    assert_eq!(want.len(), 24);
    assert!(want.iter().all(|(_, e)| e.is_some_and(|e| e > 0.0)), "every patch estimated");
    let got = run(&noisy(mask), &divided, Some(&flat));
    for ((oa, ea), (ob, eb)) in want.iter().zip(&got) {
        assert_eq!(oa, ob);
        assert_eq!(ea.map(f32::to_bits), eb.map(f32::to_bits), "{oa:?}: {ea:?} against {eb:?}");
    }
    let without = run(&noisy(mask), &divided, None);
    let moved = want.iter().zip(&without).filter(|((_, a), (_, b))| a != b).count();
    assert!(moved > 12, "the flat moves the estimate: {moved} of 24 patches");
    let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, 50, 75).unwrap()).collect();
    let small = RawFrame::new(&flat[..75 * 49], 49, 75).unwrap();
    let e = FrameSource::new(&raw).with_flat(&small).err();
    assert_eq!(e, Some(SensingError::FrameSize { expected: 3750, found: 3675 }));
    // Frames cropped to their top-left corner read the whole sensor's flat at their pixels.
    let crops: Vec<Vec<f32>> = divided.iter().map(|f| f[..75 * 40].to_vec()).collect();
    let crop: Vec<RawFrame<f32>> = crops.iter().map(|f| RawFrame::new(f, 40, 75).unwrap()).collect();
    let whole = RawFrame::new(&flat, 50, 75).unwrap();
    let src = FrameSource::new(&crop).with_flat(&whole).unwrap();
    assert!(src.divided());
    assert!((0..40 * 75).all(|p| src.flat(p / 75, p % 75) == flat[p]));
    assert!(!FrameSource::new(&crop).divided());
}

/// `with_response`: a response that mixes bands, placed in the projection, is refused on a
/// kronecker mask (its patches measure whole blocks in one band); unmixing is not.
#[test]
fn a_mixing_projection_is_refused_on_kronecker_masks() {
    let mut r = [[0.0f32; 13]; 13];
    for (f, row) in r.iter_mut().enumerate() {
        for (b, x) in row.iter_mut().enumerate() {
            *x = if f == b { 0.88 } else { 0.01 };
        }
    }
    let response = Response::new(&r).unwrap();
    let kron = Mask::kronecker(3, 2, 13, L5, (5, 5)).unwrap();
    let dec = |m| Decoder::new(config(m)).unwrap();
    assert_eq!(dec(kron).with_response(&response, ResponseModel::Projection).err(), Some(ConfigError::Response));
    assert!(dec(kron).with_response(&response, ResponseModel::Unmix).is_ok());
    assert!(dec(kron).with_response(&Response::IDENTITY, ResponseModel::Projection).is_ok());
    let pixel = Mask::pixel(3, 3, 13, L5).unwrap();
    assert!(dec(pixel).with_response(&response, ResponseModel::Projection).is_ok());
}
