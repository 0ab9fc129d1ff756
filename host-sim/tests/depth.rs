//! Depth-aware decoding (issue 19) on rendered scenes: the disparity chosen on fronto-parallel
//! planes of known integer disparity through the camera model (noise, white balance), the
//! sheared decode against the unsheared one, the host's tile sums against the device's
//! overlap ring, and the command line.

use assert_cmd::Command;
use slf_firmware::PatchShape;
use slf_host::decode::cs::{Basis, DecodeOptions, PatchViews, decode_with, disparity_per_lenslet, tile_decoder};
use slf_host::decode::options::Maps;
use slf_host::eval::metrics::psnr;
use slf_host::firmware::disparity::Disparity;
use slf_host::firmware::{DisparityRange, FrameSource, MaskFamily, Overlap, OverlapDecoder, Workspace};
use slf_host::io::capture::MaskDescription;
use slf_host::io::lightfield::{Dtype, LightField, write_npy};
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{Layer, Scene, SceneSize, Shape, Texture};
use slf_host::sim::spectra::{D65, colorchecker};

mod common;
use common::Rows;

/// Fronto-parallel textured planes: `(disparity, shape)`, the first behind the others.
fn planes(planes: &[(f32, Shape)], size: usize) -> LightField {
    let cc = |n: &str| colorchecker(n).unwrap();
    let layers = planes
        .iter()
        .enumerate()
        .map(|(i, (d, shape))| {
            Layer::flat(
                *d,
                shape.clone(),
                Texture::Noise { cell: 3.0, seed: 7 + i as u64 },
                [cc("moderate red"), cc(if i == 0 { "bluish green" } else { "yellow green" })],
            )
        })
        .collect();
    let scene = Scene { name: "planes".into(), layers, gain: 1.0, illuminant: D65 };
    scene.render(SceneSize { views: (5, 5), rows: size, cols: size })
}

fn range(min: i8, max: i8) -> Option<DisparityRange> {
    Some(DisparityRange::new(min, max).unwrap())
}

#[test]
fn the_disparity_of_a_plane_is_chosen_everywhere_off_the_edges() {
    for (d, k) in [(1i8, 1u8), (-1, 1), (2, 3)] {
        let truth = planes(&[(f32::from(d), Shape::Everywhere)], 30);
        let capture = simulate(&truth, &CameraConfig::pixel(3, k)).unwrap();
        let opts = DecodeOptions { disparities: range(-2, 2), maps: Maps::ALL, ..DecodeOptions::default() };
        let (sheared, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
        assert_eq!(report.uncovered, 0);
        // Off the edges: the block and the lenslets its shear reaches (2 |d|) in the frame.
        let h = 2 * usize::from(d.unsigned_abs());
        let mut checked = 0;
        for (o, got) in &report.disparity_map {
            let (r, c) = (usize::from(o.lenslet_row), usize::from(o.lenslet_col));
            if r >= h && c >= h && r + 5 + h <= 30 && c + 5 + h <= 30 {
                assert_eq!(*got, Disparity::pixels(d), "k {k}: block at ({r}, {c})");
                checked += 1;
            }
        }
        assert!(checked >= 16, "{checked} blocks off the edges");
        // The map per lenslet: the plane's disparity wherever only such blocks cover it.
        let map = disparity_per_lenslet(&report.disparity_map, 30, 30);
        assert_eq!(map[15 * 30 + 15], f32::from(d));
        // Not asked for, the maps are not kept; the counts are, and are the map's.
        let (_, unasked) =
            decode_with(&capture, &Basis::Dct, &DecodeOptions { maps: Maps::default(), ..opts }).unwrap();
        assert!(unasked.disparity_map.is_empty() && unasked.member_map.is_empty());
        let mut counts = std::collections::BTreeMap::new();
        report.disparity_map.iter().for_each(|(_, d)| *counts.entry(*d).or_insert(0usize) += 1);
        assert_eq!(unasked.disparity_counts, counts.into_iter().collect::<Vec<_>>());
        assert_eq!(unasked.disparity_counts, report.disparity_counts);
        let unsheared = DecodeOptions { disparities: Some(DisparityRange::OFF), ..DecodeOptions::default() };
        let (plain, _) = decode_with(&capture, &Basis::Dct, &unsheared).unwrap();
        let (a, b) = (psnr(&truth.data, &plain.data, 1.0), psnr(&truth.data, &sheared.data, 1.0));
        assert!(b > a + 1.0, "d {d}, k {k}: sheared {b:.2} dB against unsheared {a:.2}");
    }
}

#[test]
fn two_planes_each_get_their_own_disparity() {
    // A background at -1 and a square at +1 over the middle of the frame.
    let square = Shape::Rect { y0: 0.3, x0: 0.3, y1: 0.7, x1: 0.7 };
    let truth = planes(&[(-1.0, Shape::Everywhere), (1.0, square)], 50);
    let capture = simulate(&truth, &CameraConfig::pixel(4, 1)).unwrap();
    let opts = DecodeOptions { disparities: range(-1, 1), maps: Maps::ALL, ..DecodeOptions::default() };
    let (_, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
    // The square covers lenslets 15..35 in the centre view and moves by 2 lenslets in the
    // outer views; blocks with their halo (2) inside it, or clear of it by 4, and in the
    // frame.
    let (mut inside, mut outside) = (0, 0);
    for (o, got) in &report.disparity_map {
        let (r, c) = (usize::from(o.lenslet_row), usize::from(o.lenslet_col));
        let within = |x: usize| x >= 15 + 4 && x + 5 + 4 <= 35;
        let clear = |x: usize| x + 5 + 4 <= 15 || x >= 35 + 4;
        let framed = |x: usize| x >= 2 && x + 5 + 2 <= 50;
        if !(framed(r) && framed(c)) {
            continue;
        }
        if within(r) && within(c) {
            assert_eq!(*got, Disparity::pixels(1), "block ({r}, {c}) on the square");
            inside += 1;
        } else if clear(r) || clear(c) {
            assert_eq!(*got, Disparity::pixels(-1), "block ({r}, {c}) on the background");
            outside += 1;
        }
    }
    assert!(inside >= 1 && outside >= 20, "{inside} blocks on the square, {outside} on the background");
}

/// The ring of one patch shape against the host's decode of the same shape.
fn ring_matches_the_host<const PU: usize, const PV: usize, const N: usize>(views: PatchViews) {
    // Two depths, so blocks shear both ways, edges need fallbacks and the blocks between
    // leave views to fill; 17 x 16 lenslets, decoded by the ring in bands of 6 columns.
    let square = Shape::Rect { y0: 0.25, x0: 0.3, y1: 0.75, x1: 0.8 };
    let truth = planes(&[(-1.0, Shape::Everywhere), (1.0, square)], 20).window(0, 0, 17, 16);
    let capture = simulate(&truth, &CameraConfig::pixel(5, 1)).unwrap();
    // The ring decodes every patch from nothing (not seeded).
    let opts = DecodeOptions {
        disparities: range(-1, 1),
        seeded: false,
        patch_views: Some(views),
        stride: Overlap::DEFAULT.stride,
        window: Overlap::DEFAULT.window,
        maps: Maps::ALL,
        ..DecodeOptions::default()
    };
    let (host, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
    let sheared = report.disparity_map.iter().filter(|(_, d)| *d != Disparity::ZERO).count();
    assert!(sheared > 10, "{views} views: {sheared} sheared blocks");
    let overlap = Overlap { seeded: false, ..Overlap::DEFAULT };
    let od = OverlapDecoder::new(tile_decoder::<PU, PV, N>(&capture, &opts).unwrap(), overlap).unwrap();
    let mut strip = vec![0.0f32; od.strip_len(6)];
    let mut rows = Rows(LightField::zeros(truth.views, truth.rows, truth.cols, 13));
    let raw = capture.raw_frames().unwrap();
    let mut ws = Box::new(Workspace::<PatchShape<5, 5, PU, PV, 13, N>>::new());
    let dct = common::DctModel::<PU, PV, N>::shipped();
    let r = od.decode_frame(&dct, &mut FrameSource::new(&raw), &mut strip, &mut rows, &mut ws).unwrap();
    assert_eq!((r.bands, r.uncovered, r.filled as usize), (3, 0, report.filled), "{views} views");
    let worst = host.data.iter().zip(&rows.0.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "{views} views: ring against host: off by {worst}");
}

#[test]
fn the_device_ring_decodes_sheared_patches_as_the_host_does() {
    ring_matches_the_host::<4, 4, 5200>(PatchViews::Four);
    ring_matches_the_host::<5, 5, 8125>(PatchViews::Five);
}

#[test]
fn the_command_line_writes_the_disparity_map_and_refuses_bad_ranges() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    write_npy(&p("truth.npy"), &planes(&[(1.0, Shape::Everywhere)], 20), Dtype::F32).unwrap();
    let slf = || Command::cargo_bin("slf").unwrap();
    slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).assert().success();
    let out = slf()
        .arg("decode")
        .arg(p("cap"))
        .arg("-o")
        .arg(p("x.npy"))
        .args(["--dictionary", "dct", "--disparities", "-1:1:0.5", "--disparity-map"])
        .arg(p("map.npy"))
        .arg("-q")
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let out = String::from_utf8(out).unwrap();
    assert!(out.contains("disparity: blocks per disparity"), "{out}");
    let map = std::fs::read(p("map.npy")).unwrap();
    let header = String::from_utf8_lossy(&map[..128]);
    assert!(header.contains("(20, 20") && header.contains("<f4"), "{header}");
    // The plane is at disparity 1: blocks off the edges choose it among the halves.
    assert!(out.contains("+1: "), "{out}");
    for (args, want) in [
        (vec!["--disparities", "1:2"], "MIN:MAX"),
        (vec!["--disparities", "-9:1"], "MIN:MAX"),
        (vec!["--disparities", "x"], "MIN:MAX"),
        (vec!["--disparities", "-1:1:0.3"], "STEP"),
        (vec!["--disparities", "-1:1:0.5:1"], "STEP"),
        (vec!["--disparities", "0:0", "--disparity-map", "m.npy"], "needs disparities"),
    ] {
        let o = slf().arg("decode").arg(p("cap")).arg("-o").arg(p("y.npy")).args(&args).assert().failure();
        let err = String::from_utf8(o.get_output().stderr.clone()).unwrap();
        assert!(err.contains(want) && !err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn the_default_search_is_in_half_pixels_for_a_single_snapshot_and_on_the_lenslet_mask() {
    let truth = planes(&[(0.5, Shape::Everywhere)], 10);
    for family in [MaskFamily::Pixel, MaskFamily::Lenslet, MaskFamily::Kronecker] {
        for k in [1u8, 2, 3] {
            let camera = CameraConfig::pixel(3, k).with_mask(MaskDescription::seeded(family, 3, k));
            let capture = simulate(&truth, &camera).unwrap();
            let halves = k == 1 || family == MaskFamily::Lenslet;
            let default = DecodeOptions::default().disparities_for(&capture);
            assert_eq!((default.min(), default.max(), default.has_halves()), (-1, 1, halves), "{family:?} k = {k}");
            let given = DecodeOptions { disparities: range(0, 0), ..DecodeOptions::default() };
            assert!(given.disparities_for(&capture).is_off(), "{family:?} k = {k}: a given range is kept");
        }
    }
}
