//! The overlapped decoder (the device's driver of the engine) against the slow obvious
//! reference: every patch position decoded on its own by the tile decoder, then averaged
//! with the window's weights in f64 over a whole frame; seeded, the shifted patches decoded
//! from the reference's own disjoint average. The strip must give the same rows (to 1e-6,
//! seeded 1e-5) at every band width.

mod common;

use std::collections::HashMap;

use slf_firmware::raw::ReadError;
use slf_firmware::*;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
/// 8 x 11 lenslets: neither a multiple of the patch, so edge strips and shifted grids meet.
const SENSOR: SensorGeometry = SensorGeometry { lenslets: (8, 11), lenslet: L5 };
const ROWS: usize = 8;
const COLS: usize = 11;
type Decoder<'a> = TileDecoder<'a, PaperShape>;
type Overlapped<'a> = OverlapDecoder<'a, PaperShape>;

/// A light field with texture at every lenslet, `[s][t][u][v][b]`.
fn light_field() -> Vec<f32> {
    let mut l = vec![0.0; ROWS * COLS * 25 * 13];
    for (i, x) in l.iter_mut().enumerate() {
        let b = i % 13;
        let v = (i / 13) % 5;
        let u = (i / 65) % 5;
        let t = (i / 325) % COLS;
        let s = i / (325 * COLS);
        *x = 0.45
            + 0.2 * ((s as f32) * 0.9 + (t as f32) * 0.6).sin()
            + 0.15 * ((b as f32) * 0.5 + s as f32 * 0.3).cos()
            + 0.02 * (u as f32 - 2.0) * (v as f32 - 2.0);
    }
    l
}

fn frames(mask: &Mask) -> Vec<Vec<f32>> {
    let l = light_field();
    let (rows, cols) = SENSOR.frame_size();
    (0..mask.snapshots())
        .map(|j| {
            (0..rows * cols)
                .map(|p| {
                    let (row, col) = (p / cols, p % cols);
                    let band = mask.band(j, row, col).unwrap() as usize;
                    l[((((row / 5) * COLS + col / 5) * 5 + row % 5) * 5 + col % 5) * 13 + band]
                })
                .collect()
        })
        .collect()
}

fn decoder(mask: Mask<'static>) -> Decoder<'static> {
    Decoder::new(DecoderConfig {
        sensor: SENSOR,
        mask,
        raw: RawFormat::NORMALISED,
        defects: DefectList::EMPTY,
        sl0: Sl0Config::DEFAULT,
    })
    .unwrap()
}

/// Patch origins of the host's overlapped decode, written out: the tile grid with its edge
/// strips, then each shifted grid's whole patches.
fn origins(dec: &Decoder, stride: (usize, usize)) -> Vec<(usize, usize)> {
    let mut o = Vec::new();
    for tile in dec.tiles((1, 1)) {
        o.push((tile.lenslet_row as usize, tile.lenslet_col as usize));
    }
    for dy in (0..5).step_by(stride.0) {
        for dx in (0..5).step_by(stride.1) {
            if (dy, dx) == (0, 0) {
                continue;
            }
            let mut r = dy;
            while r + 5 <= ROWS {
                let mut c = dx;
                while c + 5 <= COLS {
                    o.push((r, c));
                    c += 5;
                }
                r += 5;
            }
        }
    }
    o
}

struct Collect(Vec<(PatchOrigin, Vec<f32>)>);

impl PatchSink<PaperShape> for Collect {
    type Error = ();
    fn accept(&mut self, o: PatchOrigin, p: &[f32; 5200], _: &PatchReport) -> Result<(), ()> {
        self.0.push((o, p.to_vec()));
        Ok(())
    }
}

/// The reference's seeds: a frame of values `(s, t, u, v, b)` read at each patch pixel's
/// lenslet, clamped to the sensor.
struct FrameSeeds(Vec<f32>);

impl PatchSeed<PaperShape> for FrameSeeds {
    fn seed(&mut self, o: PatchOrigin, patch: &mut [f32; 5200]) -> bool {
        for (i, x) in patch.iter_mut().enumerate() {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            let Some((r, c)) = o.lenslet::<PaperShape>(s, t, u, v, (5, 5)) else { continue };
            let (r, c) = (r.clamp(0, ROWS as isize - 1) as usize, c.clamp(0, COLS as isize - 1) as usize);
            let (vu, vv) = (o.view_row as usize + u, o.view_col as usize + v);
            *x = self.0[(((r * COLS + c) * 5 + vu) * 5 + vv) * 13 + b];
        }
        true
    }
}

/// The reference: each origin decoded alone, averaged in f64; `(s, t, u, v, b)` order.
/// Seeded, the shifted grids' patches start from the disjoint grid's average (in f32, as
/// the strip holds it).
fn reference(dec: &Decoder, raw: &[RawFrame<f32>], stride: (usize, usize), window: Window, seeded: bool) -> Vec<f64> {
    let mut sum = vec![0.0f64; ROWS * COLS * 25 * 13];
    let mut weight = vec![0.0f64; sum.len()];
    let mut ws = Box::new(PaperWorkspace::new());
    let disjoint = dec.tiles((1, 1)).count();
    let mut seeds = None;
    let mut cache: HashMap<(usize, usize), Collect> = HashMap::new();
    for (i, (r, c)) in origins(dec, stride).into_iter().enumerate() {
        if seeded && i == disjoint {
            let mean = sum.iter().zip(&weight).map(|(s, w)| if *w > 0.0 { (s / w) as f32 } else { 0.0 }).collect();
            seeds = Some(FrameSeeds(mean));
            cache.clear();
        }
        let got = cache.entry((r, c)).or_insert_with(|| {
            let mut sink = Collect(Vec::new());
            let tile = Tile { lenslet_row: r as u16, lenslet_col: c as u16, lenslet_rows: 5, lenslet_cols: 5 };
            match seeds.as_mut() {
                Some(q) => {
                    dec.decode_tile_seeded(&Dictionary::dct(), tile, &mut FrameSource::new(raw), q, &mut sink, &mut ws)
                }
                None => dec.decode_tile(&Dictionary::dct(), tile, &mut FrameSource::new(raw), &mut sink, &mut ws),
            }
            .unwrap();
            sink
        });
        for (o, p) in &got.0 {
            for (i, &x) in p.iter().enumerate() {
                let [s, t, u, v, b] = PaperShape::coordinates(i);
                let w = f64::from(window.weight::<PaperShape>(s, t));
                let (row, col) = (o.lenslet_row as usize + s, o.lenslet_col as usize + t);
                let (vu, vv) = (o.view_row as usize + u, o.view_col as usize + v);
                let j = (((row * COLS + col) * 5 + vu) * 5 + vv) * 13 + b;
                sum[j] += w * f64::from(x);
                weight[j] += w;
            }
        }
    }
    sum.iter().zip(&weight).map(|(s, w)| if *w > 0.0 { s / w } else { 0.0 }).collect()
}

/// Rows from the strip, stitched into a frame; each row seen once per band.
struct Rows {
    frame: Vec<f32>,
    seen: Vec<(u16, u16)>,
    fail_at: Option<u16>,
}

impl RowSink for Rows {
    type Error = u16;
    fn row(&mut self, row: u16, first_col: u16, values: &[f32]) -> Result<(), u16> {
        if self.fail_at == Some(row) {
            return Err(row);
        }
        // `(u, v, x, b)` over the band's columns, into the frame's `(s, t, u, v, b)`.
        assert_eq!(values.len() % (25 * 13), 0);
        let width = values.len() / 325;
        for (i, &x) in values.iter().enumerate() {
            let (b, c, view) = (i % 13, (i / 13) % width, i / (13 * width));
            self.frame[((row as usize * COLS + first_col as usize + c) * 25 + view) * 13 + b] = x;
        }
        self.seen.push((row, first_col));
        Ok(())
    }
}

fn rows() -> Rows {
    Rows { frame: vec![f32::NAN; ROWS * COLS * 325], seen: Vec::new(), fail_at: None }
}

fn strip_decode<S: TileSource>(
    dec: &Overlapped,
    source: &mut S,
    band: usize,
    sink: &mut Rows,
) -> Result<OverlapReport, OverlapError<u16>> {
    let mut strip = vec![0.0f32; dec.strip_len(band)];
    let mut ws = Box::new(PaperWorkspace::new());
    dec.decode_frame(&Dictionary::dct(), source, &mut strip, sink, &mut ws)
}

fn worst(a: &[f32], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (f64::from(*x) - y).abs()).fold(0.0, f64::max)
}

#[test]
fn the_strip_is_the_average_of_independent_patches_at_every_band_width() {
    let mask = Mask::pixel(5, 2, 13, L5).unwrap();
    let fr = frames(&mask);
    let raw: Vec<RawFrame<f32>> = fr.iter().map(|f| RawFrame::new(f, 40, 55).unwrap()).collect();
    let dec = decoder(mask);
    for (stride, window, seeded, bands) in [
        ((3, 3), Window::Tapered, false, &[COLS, 4, 1][..]),
        ((2, 4), Window::Uniform, false, &[COLS][..]),
        ((5, 5), Window::Uniform, false, &[COLS, 5][..]),
        ((2, 2), Window::Tapered, true, &[COLS, 4, 1][..]),
        ((3, 2), Window::Uniform, true, &[COLS, 3][..]),
    ] {
        let want = reference(&dec, &raw, stride, window, seeded);
        let overlap = Overlap { stride: (stride.0 as u8, stride.1 as u8), window, seeded };
        let od = Overlapped::new(dec, overlap).unwrap();
        let tolerance = if seeded { 1e-5 } else { 1e-6 };
        for &band in bands {
            let mut sink = rows();
            let r = strip_decode(&od, &mut FrameSource::new(&raw), band, &mut sink).unwrap();
            // The strip of `band` columns decodes bands at least that wide.
            let band = od.band_width(od.strip_len(band)).unwrap();
            let e = worst(&sink.frame, &want);
            assert!(e < tolerance, "stride {stride:?} {window:?} seeded {seeded} band {band}: max difference {e:e}");
            assert_eq!(r.uncovered, 0);
            assert_eq!(r.source_failures, 0);
            assert_eq!(r.bands as usize, COLS.div_ceil(band));
            assert_eq!((r.patches.decoded + r.patches.failed) as usize, od.patch_decodes(band));
            // Every row of every band, in row order within a band.
            assert_eq!(sink.seen.len(), ROWS * COLS.div_ceil(band));
            for w in sink.seen.windows(2) {
                assert!(w[1].1 > w[0].1 || (w[1].1 == w[0].1 && w[1].0 == w[0].0 + 1), "{w:?}");
            }
        }
        // Four angular windows per position, each position decoded once at full width.
        let positions = origins(&dec, stride).len();
        assert_eq!(od.patch_decodes(COLS), positions * 4, "stride {stride:?}");
    }
}

#[test]
fn stride_five_is_the_disjoint_tile_decode() {
    let mask = Mask::pixel(9, 3, 13, L5).unwrap();
    let fr = frames(&mask);
    let raw: Vec<RawFrame<f32>> = fr.iter().map(|f| RawFrame::new(f, 40, 55).unwrap()).collect();
    let dec = decoder(mask);
    let od = Overlapped::new(dec, Overlap { stride: (5, 5), window: Window::Uniform, seeded: true }).unwrap();
    assert_eq!(od.patch_decodes(COLS), dec.tiles((1, 1)).count() * 4);
    let mut sink = rows();
    strip_decode(&od, &mut FrameSource::new(&raw), COLS, &mut sink).unwrap();
    let want = reference(&dec, &raw, (5, 5), Window::Uniform, false);
    assert!(worst(&sink.frame, &want) < 1e-6);
}

/// A source that fails on one pixel row.
struct Flaky<'a> {
    inner: FrameSource<'a, RawFrame<'a, f32>>,
    bad_row: usize,
}

impl TileSource for Flaky<'_> {
    type Error = ReadError;
    fn read(&mut self, snapshot: usize, row: usize, col: usize, out: &mut [f32]) -> Result<(), ReadError> {
        if row == self.bad_row {
            return Err(ReadError::OutOfBounds { row: row as u32, col: col as u32 });
        }
        self.inner.read(snapshot, row, col, out)
    }
}

#[test]
fn a_failing_read_loses_only_its_patches() {
    let mask = Mask::pixel(5, 2, 13, L5).unwrap();
    let fr = frames(&mask);
    let raw: Vec<RawFrame<f32>> = fr.iter().map(|f| RawFrame::new(f, 40, 55).unwrap()).collect();
    let dec = decoder(mask);
    let od = Overlapped::new(dec, Overlap { stride: (3, 3), window: Window::Tapered, seeded: false }).unwrap();
    // Pixel row 36 is lenslet row 7, view row 1: every window of the patches starting at
    // lenslet row 3 reads it first thing. Those are 3 edge-strip patches and 3 shifted.
    let mut sink = rows();
    let mut src = Flaky { inner: FrameSource::new(&raw), bad_row: 36 };
    let r = strip_decode(&od, &mut src, COLS, &mut sink).unwrap();
    assert_eq!(r.source_failures, 6);
    assert_eq!(r.patches.decoded as usize, od.patch_decodes(COLS) - 6 * 4);
    // Rows 0..3 only see patches starting at row 0: as in the full decode.
    let want = reference(&dec, &raw, (3, 3), Window::Tapered, false);
    let top = 3 * COLS * 325;
    assert!(worst(&sink.frame[..top], &want[..top]) < 1e-6);
    // Rows 5..8 were only in failed patches: uncovered, sent as 0.
    assert_eq!(r.uncovered as usize, 3 * COLS * 325);
    assert!(sink.frame[5 * COLS * 325..].iter().all(|&x| x == 0.0));
    assert!(sink.frame.iter().all(|x| x.is_finite()));
}

#[test]
fn a_failing_sink_stops_the_decode_and_keeps_what_it_sent() {
    let mask = Mask::pixel(5, 2, 13, L5).unwrap();
    let fr = frames(&mask);
    let raw: Vec<RawFrame<f32>> = fr.iter().map(|f| RawFrame::new(f, 40, 55).unwrap()).collect();
    let od = Overlapped::new(decoder(mask), Overlap::DEFAULT).unwrap();
    let mut sink = Rows { fail_at: Some(2), ..rows() };
    let r = strip_decode(&od, &mut FrameSource::new(&raw), COLS, &mut sink);
    assert_eq!(r, Err(OverlapError::Sink(2)));
    assert_eq!(sink.seen, vec![(0, 0), (1, 0)]);
}

#[test]
fn bad_strides_and_strips_are_refused() {
    let mask = Mask::pixel(5, 2, 13, L5).unwrap();
    let fr = frames(&mask);
    let raw: Vec<RawFrame<f32>> = fr.iter().map(|f| RawFrame::new(f, 40, 55).unwrap()).collect();
    let dec = decoder(mask);
    for stride in [(0, 3), (3, 0), (6, 3), (3, 6)] {
        let e = Overlapped::new(dec, Overlap { stride, ..Overlap::DEFAULT }).unwrap_err();
        assert_eq!(e, ConfigError::Stride);
    }
    for overlap in [Overlap::DEFAULT, Overlap { stride: (3, 3), window: Window::Tapered, seeded: false }] {
        let od = Overlapped::new(dec, overlap).unwrap();
        // Rows of 25 views of 13 sums and a weight (and 13 seeds) per lenslet column held:
        // a band and, seeded, the columns its shifted patches reach beside it.
        let needs = od.slots();
        let per = needs.rows * 14 + if overlap.seeded { needs.seed_rows * 13 } else { 0 };
        let margin = if overlap.seeded { 5 } else { 0 };
        for width in [1, 4, COLS] {
            assert_eq!(od.strip_len(width), per * (width + 2 * margin).min(COLS) * 25);
            // (A seeded band whose margins reach past the sensor holds every column: wider
            // bands cost no more.)
            assert!(od.band_width(od.strip_len(width)) >= Some(width));
            assert!(od.strip_len(width) >= od.strip_len(width.saturating_sub(1).max(1)));
        }
        assert!(needs.rows >= 5 && needs.rows <= ROWS, "{needs:?}");
        assert!(needs.seed_rows >= 1 && needs.seed_rows <= needs.rows, "{needs:?}");
        let mut strip = vec![0.0f32; od.strip_len(1) - 1];
        let mut ws = Box::new(PaperWorkspace::new());
        let mut sink = rows();
        let r = od.decode_frame(&Dictionary::dct(), &mut FrameSource::new(&raw), &mut strip, &mut sink, &mut ws);
        assert_eq!(r, Err(OverlapError::Strip));
        assert!(sink.seen.is_empty());
    }
}

#[test]
fn tapered_weights_are_one_two_three_two_one() {
    let w: Vec<f32> = (0..5).map(|s| Window::Tapered.weight::<PaperShape>(s, 2)).collect();
    assert_eq!(w, [3.0, 6.0, 9.0, 6.0, 3.0]);
    assert_eq!(Window::Uniform.weight::<PaperShape>(0, 4), 1.0);
}

#[test]
fn the_devices_overlapped_decode_fits_its_part() {
    // The device (`memory.x`: the stack in the 128 KiB DTCM, statics in 512 KiB of RAM)
    // decodes its 5 x 10-lenslet capture in full-view patches with the host's default
    // (stride 2, seeded, sheared) through one band: the workspace and the whole width fit.
    let full = |lenslets: (u16, u16)| {
        let config = DecoderConfig {
            sensor: SensorGeometry { lenslets, lenslet: L5 },
            mask: Mask::pixel(5, 2, 13, L5).unwrap(),
            raw: RawFormat::NORMALISED,
            defects: DefectList::EMPTY,
            sl0: Sl0Config::DEFAULT,
        };
        let tiles = TileDecoder::<FullViewShape>::new(config).unwrap();
        OverlapDecoder::new(tiles.with_disparities(DisparityRange::DEFAULT), Overlap::DEFAULT).unwrap()
    };
    let ws = core::mem::size_of::<FullViewWorkspace>();
    let device = full((5, 10));
    assert!(ws + 4 * device.strip_len(10) <= 512 * 1024, "{ws} + {} the full width", 4 * device.strip_len(10));
    // A camera-sized sensor, 100 x 100 lenslets. Seeded, a band holds the rows from the
    // first a pending shifted patch reaches to the last an added disjoint patch reaches (17
    // with this halo of 2) and the seeds of those final in the disjoint grid (12), over its
    // columns and the 8 beside it on each side that its seeds are read from: more than the
    // 512 KiB part holds for even one column (`docs/design.md`, "One decode engine"). Unseeded, the RAM beside the workspace holds
    // a band narrower than the sensor, and the patch solves that costs against the full
    // width's (`scripts/budgets.sh` projects the frame with it).
    let ram = 512 * 1024 - ws;
    let camera = full((100, 100));
    assert_eq!(camera.slots().rows, 17);
    assert_eq!(camera.band_width(ram / 4), None, "{} B for one column", 4 * camera.strip_len(1));
    let camera = OverlapDecoder::new(*camera.tiles(), Overlap { seeded: false, ..Overlap::DEFAULT }).unwrap();
    let band = camera.band_width(ram / 4).unwrap();
    assert!(band < 100 && 4 * camera.strip_len(band) <= ram);
    let (banded, whole) = (camera.patch_decodes(band), camera.patch_decodes(100));
    let disjoint = 20 * 20;
    eprintln!(
        "100 x 100, full-view, unseeded: {banded} patch solves in bands of {band} ({:.3} x the disjoint grid), {whole} at full width ({:.3} x), {:?} rows held",
        banded as f64 / disjoint as f64,
        whole as f64 / disjoint as f64,
        camera.slots()
    );
    assert!(banded > whole, "{banded} against {whole}");
}
