//! Overlapping patches against the slow obvious reference: every patch decoded on its own
//! (a one-patch tile each), then averaged with the window's weights in f64; for the paper's
//! patch (four angular windows a block) and the full-view patch (one).

use slf_firmware::Shape;
use slf_firmware::shape::PerValue;
use slf_host::decode::cs::{Basis, DecodeOptions, PatchViews, SolveSchedule, Window, decode_with, tile_decoder};
use slf_host::firmware::tile::PatchSeed;
use slf_host::firmware::{
    DisparityRange, FrameSource, Overlap, OverlapDecoder, PatchOrigin, PatchReport, PatchShape, PatchSink, SolveError,
    Tile, Workspace,
};
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;
use common::Rows;

/// Keeps the patches a one-patch tile sends (one per angular window).
struct Kept(Vec<(PatchOrigin, Vec<f32>)>);

impl<S: Shape> PatchSink<S> for Kept {
    type Error = core::convert::Infallible;
    fn accept(&mut self, o: PatchOrigin, patch: &PerValue<S, f32>, _: &PatchReport) -> Result<(), Self::Error> {
        self.0.push((o, patch.as_ref().to_vec()));
        Ok(())
    }
    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Patch origins along an axis of `total` lenslets for offset `off`: every `off + 5 i`
/// with the patch inside; the unshifted grid also has the last patch flush with the edge.
fn origins(total: usize, off: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..).map(|i| off + 5 * i).take_while(|&o| o + 5 <= total).collect();
    if off == 0 && !total.is_multiple_of(5) {
        v.push(total - 5);
    }
    v
}

/// The default decode without the disparity search: every patch at its own rectangle (the
/// sheared decode is checked in `tests/depth.rs`).
fn unsheared() -> DecodeOptions {
    DecodeOptions { disparities: Some(DisparityRange::OFF), ..DecodeOptions::default() }
}

/// The seed of a patch written out: the first pass's light field at the patch's own
/// lenslets and views (unsheared), as the decode's sink receives a patch.
struct FirstPass<'a, const PU: usize, const PV: usize>(&'a LightField, &'a [f32]);

impl<const PU: usize, const PV: usize, const N: usize> PatchSeed<PatchShape<5, 5, PU, PV, 13, N>>
    for FirstPass<'_, PU, PV>
{
    fn seed(&mut self, o: PatchOrigin, patch: &mut [f32; N]) -> bool {
        for (i, x) in patch.iter_mut().enumerate() {
            let [s, t, u, v, b] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(i);
            let (r, c) = (o.lenslet_row as usize + s, o.lenslet_col as usize + t);
            *x = self.1[self.0.index(o.view_row as usize + u, o.view_col as usize + v, r, c, b)];
        }
        true
    }
}

/// Every `5 x 5 x PU x PV x 13` patch decoded on its own and averaged in f64; `seeded`: the
/// disjoint grid first, averaged alone, and every shifted patch started from that average.
fn reference<const PU: usize, const PV: usize, const N: usize>(
    truth: &LightField,
    k: u8,
    stride: usize,
    window: Window,
    seeded: bool,
) -> Vec<f32> {
    let capture = simulate(truth, &CameraConfig::pixel(3, k)).unwrap();
    // The solver config `decode_with` uses: the capture's noise ball, and the white balance
    // (the gains are the frame's; a patch decoded alone uses the same ones).
    let opts = unsheared();
    let decoder = tile_decoder::<PU, PV, N>(&capture, &opts).unwrap();
    let raw = capture.raw_frames().unwrap();
    let dct = common::DctModel::<PU, PV, N>::shipped();
    let mut ws = Box::new(Workspace::<PatchShape<5, 5, PU, PV, 13, N>>::new());
    let (rows, cols) = (truth.rows, truth.cols);
    let mut sum = vec![0.0f64; truth.data.len()];
    let mut weight = vec![0.0f64; truth.data.len()];
    let mut first: Option<Vec<f32>> = None;
    for dy in (0..5).step_by(stride) {
        for dx in (0..5).step_by(stride) {
            // The unshifted grid's edge patch exists per axis only with offset 0 on that axis.
            let rs = if dx == 0 {
                origins(rows, dy)
            } else {
                origins(rows, dy).into_iter().filter(|&r| r % 5 == dy).collect()
            };
            let cs = if dy == 0 {
                origins(cols, dx)
            } else {
                origins(cols, dx).into_iter().filter(|&c| c % 5 == dx).collect()
            };
            for &r in &rs {
                for &c in &cs {
                    let tile = Tile { lenslet_row: r as u16, lenslet_col: c as u16, lenslet_rows: 5, lenslet_cols: 5 };
                    let mut kept = Kept(Vec::new());
                    let mut source = FrameSource::new(&raw);
                    match (&first, (dy, dx)) {
                        (Some(lf), (dy, dx)) if (dy, dx) != (0, 0) => {
                            let mut seed = FirstPass::<PU, PV>(truth, lf);
                            decoder.decode_tile_seeded(&dct, tile, &mut source, &mut seed, &mut kept, &mut ws)
                        }
                        _ => decoder.decode_tile(&dct, tile, &mut source, &mut kept, &mut ws),
                    }
                    .unwrap();
                    // 4 angular windows of 4 x 4 in 5 x 5 views, 1 of 5 x 5.
                    assert_eq!(kept.0.len(), 5usize.div_ceil(PU) * 5usize.div_ceil(PV), "angular windows");
                    for (o, patch) in &kept.0 {
                        for (i, &x) in patch.iter().enumerate() {
                            let [s, t, u, v, b] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(i);
                            // The taper written out: 1, 2, 3, 2, 1 per axis.
                            const TAPER: [f64; 5] = [1.0, 2.0, 3.0, 2.0, 1.0];
                            let w = match window {
                                Window::Uniform => 1.0,
                                Window::Tapered => TAPER[s] * TAPER[t],
                            };
                            let j = truth.index(o.view_row as usize + u, o.view_col as usize + v, r + s, c + t, b);
                            sum[j] += w * f64::from(x);
                            weight[j] += w;
                        }
                    }
                }
            }
            if seeded && (dy, dx) == (0, 0) {
                first = Some(sum.iter().zip(&weight).map(|(s, w)| (s / w) as f32).collect());
            }
        }
    }
    sum.iter().zip(&weight).map(|(s, w)| (s / w) as f32).collect()
}

/// The overlapped decode of one patch shape against the reference and the device's strip.
fn overlap_matches_the_reference<const PU: usize, const PV: usize, const N: usize>(views: PatchViews) {
    // 12 x 11 lenslets: edge strips on both axes, shifted grids that stop short, and
    // axes that differ.
    let truth = common::small_smooth(5).window(0, 0, 12, 11);
    for (stride, window, k) in
        [(5, Window::Uniform, 1), (2, Window::Uniform, 1), (3, Window::Tapered, 3), (1, Window::Tapered, 1)]
    {
        let capture = simulate(&truth, &CameraConfig::pixel(3, k)).unwrap();
        let opts = DecodeOptions {
            stride: (stride as u8, stride as u8),
            window,
            seeded: false,
            patch_views: Some(views),
            ..unsheared()
        };
        let (fast, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
        assert_eq!(report.uncovered, 0);
        assert_eq!(report.patch_views, Some(views));
        let slow = reference::<PU, PV, N>(&truth, k, stride, window, false);
        let worst = fast.data.iter().zip(&slow).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst <= 1e-6, "{views} views, stride {stride}, {window:?}, k = {k}: off by {worst}");
        // The device's strip walks the same patches: the same light field, in bands of 4
        // lenslet columns (patches straddling a band border decoded twice).
        let overlap = Overlap { stride: (stride as u8, stride as u8), window, seeded: false };
        let od = OverlapDecoder::new(tile_decoder::<PU, PV, N>(&capture, &opts).unwrap(), overlap).unwrap();
        let mut strip = vec![0.0f32; od.strip_len(4)];
        let mut rows = Rows(LightField::zeros(truth.views, truth.rows, truth.cols, 13));
        let raw = capture.raw_frames().unwrap();
        let mut ws = Box::new(Workspace::<PatchShape<5, 5, PU, PV, 13, N>>::new());
        let dct = common::DctModel::<PU, PV, N>::shipped();
        let r = od.decode_frame(&dct, &mut FrameSource::new(&raw), &mut strip, &mut rows, &mut ws).unwrap();
        assert_eq!((r.bands, r.uncovered), (3, 0));
        let worst = fast.data.iter().zip(&rows.0.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst <= 1e-6, "{views} views, strip, stride {stride}, {window:?}, k = {k}: off by {worst}");
    }
}

#[test]
fn overlapping_patches_average_as_every_patch_decoded_alone() {
    overlap_matches_the_reference::<4, 4, 5200>(PatchViews::Four);
    overlap_matches_the_reference::<5, 5, 8125>(PatchViews::Five);
}

/// The seeded decode of one patch shape against the reference.
fn seeded_matches_the_reference<const PU: usize, const PV: usize, const N: usize>(views: PatchViews) {
    let truth = common::small_smooth(5).window(0, 0, 12, 11);
    for (stride, window, k) in [(3, Window::Tapered, 1), (2, Window::Uniform, 3)] {
        let capture = simulate(&truth, &CameraConfig::pixel(3, k)).unwrap();
        let opts =
            DecodeOptions { stride: (stride as u8, stride as u8), window, patch_views: Some(views), ..unsheared() };
        assert!(opts.seeded);
        let (fast, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
        let slow = reference::<PU, PV, N>(&truth, k, stride, window, true);
        let worst = fast.data.iter().zip(&slow).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst <= 1e-5, "{views} views, stride {stride}, {window:?}, k = {k}: off by {worst}");
        // And it is not the unseeded decode: the seeds changed the shifted patches.
        let cold = reference::<PU, PV, N>(&truth, k, stride, window, false);
        let apart = fast.data.iter().zip(&cold).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(apart > 1e-3, "{views} views, stride {stride}: seeded within {apart} of the cold decode");
        // One solve a patch either way with the DCT; the seeded ones take fewer steps.
        assert_eq!(report.solves, u64::from(report.patches.decoded));
        // The device's driver of the same engine, seeded, one patch a tile, in bands: the
        // host's decode to float rounding (the host sums a tile's patches before they join
        // the rows, the device adds each to the rows).
        let overlap = Overlap { stride: (stride as u8, stride as u8), window, seeded: true };
        let od = OverlapDecoder::new(tile_decoder::<PU, PV, N>(&capture, &opts).unwrap(), overlap).unwrap();
        let raw = capture.raw_frames().unwrap();
        let dct = common::DctModel::<PU, PV, N>::shipped();
        for width in [11, 4] {
            let mut strip = vec![0.0f32; od.strip_len(width)];
            let mut rows = Rows(LightField::zeros(truth.views, truth.rows, truth.cols, 13));
            let mut ws = Box::new(Workspace::<PatchShape<5, 5, PU, PV, 13, N>>::new());
            let r = od.decode_frame(&dct, &mut FrameSource::new(&raw), &mut strip, &mut rows, &mut ws).unwrap();
            assert_eq!(r.uncovered, 0);
            let scale = fast.data.iter().fold(0.0f32, |m, x| m.max(x.abs()));
            let worst = fast.data.iter().zip(&rows.0.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            assert!(worst <= 1e-5 * scale, "{views} views, stride {stride}, band {width}: device off by {worst}");
        }
    }
}

#[test]
fn seeded_patches_start_from_the_disjoint_grids_average() {
    // The seeded decode (the default) against the reference written out: the disjoint grid
    // decoded and averaged alone, each shifted patch's seed read from that average at its
    // own lenslets, every estimate averaged in f64.
    seeded_matches_the_reference::<4, 4, 5200>(PatchViews::Four);
    seeded_matches_the_reference::<5, 5, 8125>(PatchViews::Five);
}

#[test]
fn stride_five_is_todays_decode_and_bad_strides_are_refused() {
    let truth = common::small_smooth(5);
    let capture = simulate(&truth, &CameraConfig::pixel(4, 1)).unwrap();
    let (a, ra) = decode_with(&capture, &Basis::Dct, &DecodeOptions::disjoint()).unwrap();
    let tapered = DecodeOptions { window: Window::Tapered, ..DecodeOptions::disjoint() };
    let (b, _) = decode_with(&capture, &Basis::Dct, &tapered).unwrap();
    // With disjoint patches (and the edge strips) a taper changes only where patches overlap.
    let differ = a.data.iter().zip(&b.data).filter(|(x, y)| x != y).count();
    assert!(differ > 0 && differ < a.data.len() / 2, "{differ}");
    let three = DecodeOptions { stride: (3, 3), ..unsheared() };
    let (_, r3) = decode_with(&capture, &Basis::Dct, &three).unwrap();
    // 12 x 12 lenslets, the full-view patch: rows and columns {0, 5, 7} give 9 patches;
    // stride 3 adds the grids at offsets (0, 3), (3, 0), (3, 3): 2 + 2 + 1. The paper's
    // patch decodes each in 4 angular windows.
    assert_eq!((ra.patches.decoded, r3.patches.decoded), (9, 14));
    let four = DecodeOptions { patch_views: Some(PatchViews::Four), ..three };
    assert_eq!(decode_with(&capture, &Basis::Dct, &four).unwrap().1.patches.decoded, 14 * 4);
    for bad in [(0, 5), (5, 6)] {
        let e =
            decode_with(&capture, &Basis::Dct, &DecodeOptions { stride: bad, ..DecodeOptions::default() }).unwrap_err();
        assert!(e.to_string().contains("1..=5"), "{e}");
    }
}

/// Mean absolute step between neighbouring lenslet columns of every view and band, split
/// into steps across the disjoint grid's patch borders (columns 4|5, 9|10, ...) and the rest.
fn steps(lf: &LightField) -> (f64, f64) {
    let (mut border, mut inside, mut nb, mut ni) = (0.0, 0.0, 0usize, 0usize);
    for u in 0..lf.views.0 {
        for v in 0..lf.views.1 {
            for y in 0..lf.rows {
                for x in 0..lf.cols - 1 {
                    for b in 0..lf.bands {
                        let d = f64::from((lf.get(u, v, y, x + 1, b) - lf.get(u, v, y, x, b)).abs());
                        if x % 5 == 4 {
                            border += d;
                            nb += 1;
                        } else {
                            inside += d;
                            ni += 1;
                        }
                    }
                }
            }
        }
    }
    (border / nb as f64, inside / ni as f64)
}

#[test]
fn with_overlap_the_grid_is_gone_on_a_smooth_ramp() {
    // A ramp in x and y, smooth in the bands: every true step is the same size, so a step
    // across patch borders larger than inside is the decoder's grid.
    let truth = LightField::from_fn((5, 5), 20, 20, 13, |_, _, y, x, b| {
        (0.15 + 0.02 * x as f32 + 0.01 * y as f32) * (0.8 + 0.03 * b as f32)
    });
    // Without noise, the error is the decoder's alone.
    let capture = simulate(&truth, &CameraConfig::pixel(6, 1).noiseless()).unwrap();
    // Steps of the error (reconstruction - truth): the truth's own steps are all alike,
    // so what differs between border and inside is the decoder's.
    // The hand-set schedule: its disjoint patches show the grid the overlap must remove (the
    // trained one's show little of it: measured 1.13 times the inside steps).
    let decode = |stride: u8, window: Window| {
        let opts = DecodeOptions {
            stride: (stride, stride),
            window,
            schedule: SolveSchedule::Annealed,
            ..DecodeOptions::default()
        };
        let mut e = decode_with(&capture, &Basis::Dct, &opts).unwrap().0;
        e.data.iter_mut().zip(&truth.data).for_each(|(r, t)| *r -= t);
        steps(&e)
    };
    let (truth_border, truth_inside) = steps(&truth);
    assert!((truth_border - truth_inside).abs() < 1e-6);
    let (b5, i5) = decode(5, Window::Uniform);
    let (b2, i2) = decode(2, Window::Tapered);
    let (b3, i3) = decode(3, Window::Uniform);
    // The default: stride 3, tapered.
    let defaults = DecodeOptions::default();
    let (bd, id) = decode(defaults.stride.0, defaults.window);
    // Disjoint patches show the grid (measured: border steps 1.9 times the inside ones);
    // with overlap the border steps are no larger than inside (measured 0.69 times at
    // stride 2, 1.005 at the default; tolerance 10 %). Stride 3 with the uniform window
    // leaves a trace (measured 1.18): lenslets covered by one patch and by two alternate.
    assert!(b5 > 1.2 * i5, "stride 5: border {b5:.5}, inside {i5:.5}");
    assert!(b2 <= 1.1 * i2, "stride 2: border {b2:.5}, inside {i2:.5}");
    assert!(bd <= 1.1 * id, "default: border {bd:.5}, inside {id:.5}");
    assert!(b3 > bd * (i3 / id), "stride 3 uniform {:.3} not above tapered {:.3}", b3 / i3, bd / id);
}

/// The adaptive rule: a shifted patch is decoded where the first pass shows a seam. With an
/// infinite threshold none is (the decode is the disjoint one, same window); with 0 every
/// one whose seams move at all (the full stride decode). (The score itself is worked by hand
/// in `decode::seams`'s unit test.)
#[test]
fn adaptive_overlap_decodes_shifted_patches_only_at_seams() {
    let truth = common::small_smooth(5);
    let capture = simulate(&truth, &CameraConfig::pixel(4, 1)).unwrap();
    let opts = |stride: u8, adaptive| DecodeOptions { stride: (stride, stride), adaptive, ..DecodeOptions::default() };
    let (none, r_none) = decode_with(&capture, &Basis::Dct, &opts(3, Some(f32::INFINITY))).unwrap();
    let (disjoint, r_disjoint) = decode_with(&capture, &Basis::Dct, &opts(5, None)).unwrap();
    assert_eq!(none.data, disjoint.data);
    assert_eq!(r_none.patches.decoded, r_disjoint.patches.decoded);
    let (all, r_all) = decode_with(&capture, &Basis::Dct, &opts(3, Some(0.0))).unwrap();
    let (full, r_full) = decode_with(&capture, &Basis::Dct, &opts(3, None)).unwrap();
    assert_eq!(r_all.patches.decoded, r_full.patches.decoded);
    let worst = all.data.iter().zip(&full.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "adaptive 0 vs every shifted patch: {worst}");
    // Unseeded alike: every shifted patch from nothing.
    let cold = |adaptive| DecodeOptions { seeded: false, ..opts(3, adaptive) };
    let (all, _) = decode_with(&capture, &Basis::Dct, &cold(Some(0.0))).unwrap();
    let (full, _) = decode_with(&capture, &Basis::Dct, &cold(None)).unwrap();
    let worst = all.data.iter().zip(&full.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "unseeded: adaptive 0 vs every shifted patch: {worst}");
}
