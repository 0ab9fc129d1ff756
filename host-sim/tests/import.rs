//! `slf import`: band resampling, the RGB lift, views, cubes and disparity maps, each on
//! fixtures the tests write themselves and checked against values worked by hand.

use slf_host::sim::flags::FromFlags;
use std::path::Path;

use image::{ImageBuffer, Luma, Rgb};
use slf_host::io::import::bands::{BandFilter, CAMERA_FILTER, Resampler, parse_wavelengths};
use slf_host::io::import::cube::{self, CubeConfig, Depth, Light, d65_at};
use slf_host::io::import::parallax::{Disparity, estimate, warp};
use slf_host::io::import::pfm::{parse_pfm, pfm_bytes};
use slf_host::io::import::rgb::{RgbLift, srgb_to_linear};
use slf_host::io::import::rgb_basis_data::MALLETT_2019;
use slf_host::io::import::views::{Fill, Naming, ViewsConfig, import_views, view_name};
use slf_host::io::import::{Crop, Geometry, Plane};
use slf_host::sim::spectra_data::BAND_NM;

/// The slow obvious reference of band resampling: `∫ f(λ) g(λ - c) dλ / ∫ g(λ - c) dλ`
/// over `c ± 50 nm` (2 FWHM), g the camera's Gaussian, in f64 with 0.001 nm steps.
fn slow_band(c: f64, f: impl Fn(f64) -> f64) -> f64 {
    let sigma = 25.0f64 / (2.0 * (2.0 * 2f64.ln()).sqrt());
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..=100_000 {
        let l = c - 50.0 + k as f64 * 0.001;
        let g = (-0.5 * ((l - c) / sigma).powi(2)).exp();
        num += g * f(l);
        den += g;
    }
    num / den
}

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-6)
}

#[test]
fn resampling_keeps_a_flat_spectrum_flat() {
    for wl in ["400:700:10", "380:780:5", "395,430,470,520,560,610,650,705", "390:710:1"] {
        let w = parse_wavelengths(wl).unwrap();
        let r = Resampler::new(&w, &BAND_NM, CAMERA_FILTER).unwrap();
        let mut out = [0.0f32; 13];
        r.apply(&vec![0.37; w.len()], &mut out);
        for (b, v) in out.iter().enumerate() {
            assert!((v - 0.37).abs() < 1e-6, "{wl}: band {b} is {v}, not 0.37");
        }
    }
}

#[test]
fn resampling_integrates_a_narrow_line_over_the_gaussian_filter() {
    // 1 nm samples, all 0 but 1 at 437 nm: the linear interpolant is a triangle of area 1
    // nm, so band c sees g(437 - c) / (sigma sqrt(2 pi)) with g the unnormalised Gaussian.
    let w = parse_wavelengths("380:780:1").unwrap();
    let mut s = vec![0.0f32; w.len()];
    s[437 - 380] = 1.0;
    let r = Resampler::new(&w, &BAND_NM, CAMERA_FILTER).unwrap();
    let mut out = [0.0f32; 13];
    r.apply(&s, &mut out);
    // Against the slow reference, with the triangle 436..=438 nm as the spectrum.
    for (b, &c) in BAND_NM.iter().enumerate() {
        let want = slow_band(f64::from(c), |l| (1.0 - (l - 437.0).abs()).max(0.0));
        assert!((f64::from(out[b]) - want).abs() < 1e-4 * want + 1e-9, "band {c} nm: {} against {want:.4e}", out[b]);
    }
    // By hand, 425 nm, 12 nm off: exp(-0.5 (12 / 10.6165)^2) / (10.6165 sqrt(2 pi))
    // = 0.52793 / 26.6116 = 0.019838.
    assert!((out[1] - 0.019838).abs() < 2e-5, "{}", out[1]);
}

#[test]
fn bad_wavelengths_are_one_line_errors() {
    let e = Resampler::new(&[500.0, 450.0, 600.0], &BAND_NM, CAMERA_FILTER).unwrap_err().to_string();
    assert!(e.contains("must increase") && e.contains("500"), "{e}");
    let e = Resampler::new(&[430.0, 500.0, 860.0], &BAND_NM, CAMERA_FILTER).unwrap_err().to_string();
    assert!(e.contains("400 nm") && e.contains("outside"), "{e}");
    let e = Resampler::new(&[500.0], &BAND_NM, CAMERA_FILTER).unwrap_err().to_string();
    assert!(e.contains("at least 2"), "{e}");
    assert!(Resampler::new(&[400.0, 700.0], &BAND_NM, BandFilter { fwhm_nm: f32::NAN }).is_err());
    for bad in ["400:700", "a,b", "700:400:10", "400:700:0"] {
        let e = parse_wavelengths(bad).unwrap_err().to_string();
        assert!(!e.contains('\n') && e.contains(bad), "{bad}: {e}");
    }
}

#[test]
fn the_rgb_basis_is_mallett_and_yuksel_and_white_lifts_to_d65() {
    // Published property: the three spectra sum to 1 at every wavelength (to the table's
    // rounding), and each lies in [0, 1].
    for (i, p) in MALLETT_2019.iter().enumerate() {
        let s: f32 = p.iter().sum();
        assert!((s - 1.0).abs() < 2e-5, "sample {i}: sum {s}");
        assert!(p.iter().all(|v| (0.0..=1.0).contains(v)));
    }
    let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER).unwrap();
    let mut white = [0.0f32; 13];
    lift.lift([1.0, 1.0, 1.0], &mut white);
    // White is D65 over the filters (the slow reference), 1 in the brightest band.
    let peak = white.iter().fold(0.0f32, |m, &v| m.max(v));
    assert!((peak - 1.0).abs() < 1e-6, "{peak}");
    let slow: Vec<f64> = BAND_NM.iter().map(|&c| slow_band(f64::from(c), |l| f64::from(d65_at(l as f32)))).collect();
    let slow_peak = slow.iter().fold(0.0f64, |m, &v| m.max(v));
    for (b, &c) in BAND_NM.iter().enumerate() {
        let want = slow[b] / slow_peak;
        assert!((f64::from(white[b]) - want).abs() < 2e-4, "band {c}: {} against {want}", white[b]);
    }
    // Linear: grey 0.25 is a quarter of white; red + green + blue is white.
    let mut grey = [0.0f32; 13];
    lift.lift([0.25; 3], &mut grey);
    for b in 0..13 {
        assert!(close(grey[b], 0.25 * white[b], 1e-5));
        let sum = lift.primary(b, 0) + lift.primary(b, 1) + lift.primary(b, 2);
        assert!(close(sum, white[b], 1e-5));
    }
    // Red peaks in the long bands, blue in the short ones.
    assert!(lift.primary(11, 0) > 5.0 * lift.primary(1, 0));
    assert!(lift.primary(1, 2) > 5.0 * lift.primary(11, 2));
}

#[test]
fn srgb_decoding_matches_hand_values() {
    assert_eq!(srgb_to_linear(0.0), 0.0);
    assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
    assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-7);
    // 188 / 255: ((0.737255 + 0.055) / 1.055)^2.4 = 0.50289.
    assert!((srgb_to_linear(188.0 / 255.0) - 0.50289).abs() < 2e-5);
}

#[test]
fn pfm_rows_run_bottom_up_and_bad_headers_are_refused() {
    // A 2 x 3 map written by hand: bottom row first, little-endian (negative scale).
    let mut bytes = b"Pf\n3 2\n-1.0\n".to_vec();
    for v in [4.0f32, 5.0, 6.0, 1.0, 2.0, 3.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let p = parse_pfm(&bytes).unwrap();
    assert_eq!((p.rows, p.cols), (2, 3));
    assert_eq!(p.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert_eq!(pfm_bytes(&p), bytes);
    // Big-endian (positive scale).
    let mut be = b"Pf 1 1 1.0\n".to_vec();
    be.extend_from_slice(&2.5f32.to_be_bytes());
    assert_eq!(parse_pfm(&be).unwrap().data, vec![2.5]);
    for (bad, why) in [
        (b"P5\n3 2\n-1.0\n".to_vec(), "magic"),
        (b"Pf\n3 2\n-1.0\n\0\0\0\0".to_vec(), "need 24 bytes"),
        (b"Pf\n99999999 2\n-1.0\n".to_vec(), "not within"),
        (b"Pf\nx 2\n-1.0\n".to_vec(), "width"),
        (b"Pf\n1 1\n0\n\0\0\0\0".to_vec(), "scale"),
    ] {
        let e = format!("{:#}", parse_pfm(&bad).unwrap_err());
        assert!(e.contains(why) && !e.contains('\n'), "{why}: {e}");
    }
}

/// Writes a `rows x cols` 8-bit RGB PNG of one colour plus a column ramp in green.
fn write_view(path: &Path, rgb: [u8; 3], rows: u32, cols: u32) {
    let img = ImageBuffer::from_fn(cols, rows, |x, _| Rgb([rgb[0], rgb[1].saturating_add(x as u8), rgb[2]]));
    img.save(path).unwrap();
}

#[test]
fn hci_views_are_read_by_their_numbers_windowed_and_lifted() {
    let dir = tempfile::tempdir().unwrap();
    // A 4 x 4 grid; view (r, c) is red 20 r + 10, blue 20 c + 10.
    for r in 0..4u8 {
        for c in 0..4u8 {
            let name = format!("input_Cam{:03}.png", r * 4 + c);
            write_view(&dir.path().join(name), [20 * r + 10, 100, 20 * c + 10], 6, 8);
        }
    }
    let cfg = ViewsConfig { grid: (4, 4), views: (2, 3), start: Some((1, 0)), linear: true, ..Default::default() };
    let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER).unwrap();
    let imported = import_views(dir.path(), &cfg, &lift).unwrap();
    let lf = &imported.lightfield;
    assert_eq!(lf.shape(), [2, 3, 6, 8, 13]);
    assert!(imported.disparity.is_none());
    // View (u, v) of the window is grid view (1 + u, v); pixel x adds x to green.
    for u in 0..2 {
        for v in 0..3 {
            for x in [0usize, 7] {
                let rgb = [(20 * (1 + u) + 10) as f32 / 255.0, (100 + x) as f32 / 255.0, (20 * v + 10) as f32 / 255.0];
                let mut want = [0.0f32; 13];
                lift.lift(rgb, &mut want);
                for (b, w) in want.iter().enumerate() {
                    let got = lf.get(u, v, 3, x, b);
                    assert!(close(got, *w, 1e-5), "({u}, {v}) x {x} band {b}: {got} vs {w}");
                }
            }
        }
    }
    // sRGB-encoded files (the default) are decoded: 188 / 255 grey is 0.50289 linear.
    let grey = tempfile::tempdir().unwrap();
    for i in 0..81 {
        ImageBuffer::from_pixel(3, 3, Rgb([188u8, 188, 188]))
            .save(grey.path().join(format!("input_Cam{i:03}.png")))
            .unwrap();
    }
    let lf = import_views(grey.path(), &ViewsConfig::default(), &lift).unwrap().lightfield;
    assert_eq!(lf.shape(), [5, 5, 3, 3, 13]);
    let mut white = [0.0f32; 13];
    lift.lift([1.0; 3], &mut white);
    for (b, w) in white.iter().enumerate() {
        assert!(close(lf.get(4, 4, 2, 2, b), 0.50289 * w, 1e-4));
    }
}

#[test]
fn pattern_names_sixteen_bit_views_crop_resize_and_the_disparity_map() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = ViewsConfig {
        naming: Naming::Pattern("lf_{row:02}_{col}.png".into()),
        index_base: 1,
        grid: (5, 5),
        views: (5, 5),
        linear: true,
        geometry: Geometry { crop: Some(Crop { row: 2, col: 4, rows: 6, cols: 8 }), resize: Some((3, 4)) },
        ..Default::default()
    };
    assert_eq!(view_name(&cfg, 0, 3).unwrap(), "lf_01_4.png");
    // 16-bit grey views: value (row * 16 + col) * 1000 at pixel (row, col), same in every view.
    for r in 0..5 {
        for c in 0..5 {
            let img = ImageBuffer::from_fn(12, 8, |x, y| Luma([((y * 16 + x) * 400) as u16]));
            img.save(dir.path().join(view_name(&cfg, r, c).unwrap())).unwrap();
        }
    }
    // A disparity map of 2 everywhere, as HCI would give it.
    let d = Plane { rows: 8, cols: 12, channels: 1, data: vec![2.0; 96] };
    std::fs::write(dir.path().join("disp.pfm"), pfm_bytes(&d)).unwrap();
    let cfg = ViewsConfig { disparity: Some(dir.path().join("disp.pfm")), ..cfg };
    let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER).unwrap();
    let imported = import_views(dir.path(), &cfg, &lift).unwrap();
    assert_eq!(imported.lightfield.shape(), [5, 5, 3, 4, 13]);
    // Halving keeps a linear ramp where the filter is whole: output (1, 1)'s centre is
    // crop pixel (2.5, 2.5), pixel (4.5, 6.5) of the view: (4.5 * 16 + 6.5) * 400 / 65535
    // (grey, so r = g = b).
    let mut white = [0.0f32; 13];
    lift.lift([1.0; 3], &mut white);
    let want = (4.5 * 16.0 + 6.5) * 400.0 / 65535.0;
    let got = imported.lightfield.get(0, 0, 1, 1, 0) / white[0];
    assert!((got - want).abs() < 2e-3, "{got} vs {want}");
    // The map is cut and scaled with the views: 2 px a view at half width is 1.
    let disp = imported.disparity.unwrap();
    assert_eq!((disp.rows, disp.cols), (3, 4));
    assert!(disp.data.iter().all(|v| (v - 1.0).abs() < 1e-6), "{:?}", disp.data);
}

#[test]
fn missing_views_are_refused_or_filled_by_the_disparity() {
    let dir = tempfile::tempdir().unwrap();
    // A 3 x 3 grid of a random texture at disparity 1: view (r, c) shows the centre view's
    // point (y, x) at (y - (r - 1), x - (c - 1)).
    let (rows, cols) = (24u32, 24u32);
    let tex = |y: i32, x: i32| -> u8 { (((y * 37 + x * 91) ^ (y * x)) % 200 + 20) as u8 };
    let view = |r: i32, c: i32| {
        ImageBuffer::from_fn(cols, rows, |x, y| {
            let v = tex(y as i32 + (r - 1), x as i32 + (c - 1));
            Rgb([v, v, v])
        })
    };
    for r in 0..3 {
        for c in 0..3 {
            if (r, c) != (0, 2) {
                view(r, c).save(dir.path().join(format!("input_Cam{:03}.png", r * 3 + c))).unwrap();
            }
        }
    }
    let cfg = ViewsConfig { grid: (3, 3), views: (3, 3), linear: true, max_disparity: 2.0, ..Default::default() };
    let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER).unwrap();
    let e = format!("{:#}", import_views(dir.path(), &cfg, &lift).unwrap_err());
    assert!(e.contains("1 of 9 views") && e.contains("input_Cam002.png") && e.contains("--fill warp"), "{e}");
    // Issue 41, item 3: a sweep bound past any real disparity (1e9 asked for 17 GB of
    // candidates) is refused, in the library and by the flag.
    for bad in [1e9, 32.5, f32::NAN, 0.0] {
        let e = format!(
            "{:#}",
            import_views(dir.path(), &ViewsConfig { fill: Fill::Warp, max_disparity: bad, ..cfg.clone() }, &lift)
                .unwrap_err()
        );
        assert!(e.contains("--max-disparity") && e.contains("<= 32"), "{e}");
    }
    let folder = dir.path().display().to_string();
    let e =
        slf_host::sim::import::ViewsSettings::from_flags([folder.as_str(), "--fill", "warp", "--max-disparity", "1e9"])
            .unwrap_err();
    assert!(e.contains("1e9 pixels per view is more than the 32"), "{e}");
    let imported = import_views(dir.path(), &ViewsConfig { fill: Fill::Warp, ..cfg }, &lift).unwrap();
    assert!(
        imported.notes.iter().any(|n| n.contains("view (0, 2)") && n.contains("from view (0, 1)")),
        "{:?}",
        imported.notes
    );
    // The estimated disparity is 1 away from the edges, and the made view matches the real one there.
    let d = imported.disparity.unwrap();
    let truth = view(0, 2);
    let mut white = [0.0f32; 13];
    lift.lift([1.0; 3], &mut white);
    for y in 4..20usize {
        for x in 4..20usize {
            assert!((d.data[y * 24 + x] - 1.0).abs() < 0.051, "disparity at ({y}, {x}): {}", d.data[y * 24 + x]);
            let want = f32::from(truth.get_pixel(x as u32, y as u32).0[0]) / 255.0;
            let got = imported.lightfield.get(0, 2, y, x, 0) / white[0];
            assert!((got - want).abs() < 1e-4, "({y}, {x}): {got} vs {want}");
        }
    }
}

#[test]
fn a_band_folder_becomes_a_light_field_at_a_disparity() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("scene_ms");
    std::fs::create_dir(&sub).unwrap();
    // 31 bands, 400..=700 nm: reflectance 0.5 everywhere except a bright column (x = 5) at 0.9.
    for b in 1..=31 {
        let img = ImageBuffer::from_fn(10, 6, |x, _| Luma([if x == 5 { 58982u16 } else { 32768 }]));
        img.save(sub.join(format!("scene_ms_{b:02}.png"))).unwrap();
    }
    let files = cube::band_files(dir.path()).unwrap();
    assert_eq!(files.len(), 31);
    assert!(files[30].ends_with("scene_ms_31.png"));
    let data = cube::read_band_folder(dir.path()).unwrap();
    assert_eq!((data.rows, data.cols, data.channels), (6, 10, 31));
    let wl = parse_wavelengths("400:700:10").unwrap();
    let bands = cube::to_camera_bands(&data, &wl, &BAND_NM, CAMERA_FILTER, 1.0, Light::Reflectance).unwrap();
    // Flat reflectance 0.5 under D65: half of white, whose brightest band is 1.
    let white = cube::to_camera_bands(
        &Plane { rows: 1, cols: 1, channels: 31, data: vec![1.0; 31] },
        &wl,
        &BAND_NM,
        CAMERA_FILTER,
        1.0,
        Light::Reflectance,
    )
    .unwrap();
    assert!((white.data.iter().fold(0.0f32, |m, &v| m.max(v)) - 1.0).abs() < 1e-6);
    for b in 0..13 {
        let want = 0.5 * white.data[b] * 32768.0 / 32767.5;
        assert!(close(bands.data[b], want, 1e-4), "band {b}: {} vs {want}", bands.data[b]);
    }
    let cfg = CubeConfig { views: (3, 5), depth: Depth::Plane(2.0), ..Default::default() };
    let (lf, map) = cube::to_lightfield(&bands, &cfg, (6, 10)).unwrap();
    assert!(map.is_none());
    assert_eq!(lf.shape(), [3, 5, 6, 10, 13]);
    // The bright column sits at x = 5 - 2 (v - 2) in view column v (HCI's sign).
    for v in 0..5 {
        let x = (5 - 2 * (v as i32 - 2)) as usize;
        if x < 10 {
            assert!(lf.get(1, v, 3, x, 6) > 0.85 * white.data[6], "view {v}: column {x}");
            assert!(lf.get(1, v, 3, (x + 1) % 10, 6) < 0.55 * white.data[6]);
        }
    }
}

#[test]
fn warping_matches_a_slow_shift_and_the_plane_sweep_finds_a_plane() {
    let src =
        Plane { rows: 20, cols: 20, channels: 2, data: (0..800).map(|i| ((i * 7919) % 101) as f32 / 101.0).collect() };
    // An integer disparity is a pure shift: out(y, x) = src(y + d du, x + d dv), edges clamped.
    let out = warp(&src, Disparity::Plane(1.0), 2.0, -1.0).unwrap();
    for y in 0..20 {
        for x in 0..20 {
            let (sy, sx) = ((y + 2).min(19), (x as i64 - 1).max(0) as usize);
            assert_eq!(out.pixel(y, x), src.pixel(sy, sx));
        }
    }
    // Half a pixel: the mean of two neighbours.
    let half = warp(&src, Disparity::Plane(0.5), 0.0, 1.0).unwrap();
    assert!((half.pixel(5, 5)[0] - 0.5 * (src.pixel(5, 5)[0] + src.pixel(5, 6)[0])).abs() < 1e-6);
    // Views of a plane at disparity -1.5 give back -1.5 off the edges.
    let views: Vec<(f64, f64, Plane)> = [(0.0, 1.0), (1.0, 0.0), (-1.0, -1.0)]
        .iter()
        .map(|&(du, dv)| (du, dv, warp(&src, Disparity::Plane(-1.5), du, dv).unwrap()))
        .collect();
    let others: Vec<(f64, f64, &Plane)> = views.iter().map(|(a, b, p)| (*a, *b, p)).collect();
    let candidates: Vec<f32> = (-20..=20).map(|k| k as f32 * 0.25).collect();
    let d = estimate(&src, &others, &candidates, 2).unwrap();
    for y in 4..16 {
        for x in 4..16 {
            assert_eq!(d.data[y * 20 + x], -1.5, "({y}, {x})");
        }
    }
}

#[test]
fn cube_and_geometry_errors_say_what_is_wrong() {
    let g = Geometry { crop: Some(Crop { row: 4, col: 0, rows: 10, cols: 2 }), resize: None };
    let e = g.output_size(8, 8).unwrap_err().to_string();
    assert!(e.contains("outside the 8 x 8 input"), "{e}");
    let p = Plane::zeros(2, 2, 3);
    let e = cube::to_camera_bands(&p, &[400.0, 500.0], &BAND_NM, CAMERA_FILTER, 1.0, Light::Radiance)
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 wavelengths for a cube of 3 bands"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let e = cube::band_files(dir.path()).unwrap_err().to_string();
    assert!(e.contains("no band images"), "{e}");
}

/// A tiny HDF5 file: group `lf`, dataset `data` of `shape`, values from `f` in file order.
fn write_h5(path: &Path, shape: &[u64], f: impl Fn(usize) -> f32) {
    let n = shape.iter().product::<u64>() as usize;
    let values: Vec<f32> = (0..n).map(f).collect();
    let mut b = hdf5_pure::FileBuilder::new();
    let mut g = b.create_group("lf");
    g.create_dataset("data").with_f32_data(&values).with_shape(shape);
    b.add_group(g.finish());
    std::fs::write(path, b.finish().unwrap()).unwrap();
}

#[test]
fn hdf5_light_fields_are_read_in_any_axis_order() {
    use slf_host::io::import::hdf5::{Hdf5Layout, read_hdf5};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lf.h5");
    // Stored as (H, W, U, V, B) = (3, 4, 2, 5, 13); value = 1000 h + 100 w + 10 u + v + b / 100.
    let shape = [3u64, 4, 2, 5, 13];
    write_h5(&path, &shape, |i| {
        let (b, i) = (i % 13, i / 13);
        let (v, i) = (i % 5, i / 5);
        let (u, i) = (i % 2, i / 2);
        let (w, h) = (i % 4, i / 4);
        (1000 * h + 100 * w + 10 * u + v) as f32 + b as f32 / 100.0
    });
    let layout = Hdf5Layout { dataset: "/lf/data".into(), axes: "hwuvb".into() };
    let lf = read_hdf5(&path, &layout, 2.0).unwrap();
    assert_eq!(lf.shape(), [2, 5, 3, 4, 13]);
    for (u, v, h, w, b) in [(0, 0, 0, 0, 0), (1, 4, 2, 3, 12), (1, 2, 1, 0, 7)] {
        let want = ((1000 * h + 100 * w + 10 * u + v) as f32 + b as f32 / 100.0) / 2.0;
        assert_eq!(lf.get(u, v, h, w, b), want, "({u}, {v}, {h}, {w}, {b})");
    }
    for (axes, why) in [("uvhwx", "'x' is not one of"), ("uvhwu", "appears twice"), ("uvhw", "need 5 letters")] {
        let e = read_hdf5(&path, &Hdf5Layout { dataset: "lf/data".into(), axes: axes.into() }, 1.0).unwrap_err();
        assert!(e.to_string().contains(why), "{axes}: {e}");
    }
    // Issue 41, item 10: a white that makes the values infinite is refused, with the value.
    let e = read_hdf5(&path, &layout, 1e-40).unwrap_err().to_string();
    assert!(e.contains("divided by --white 1e-40 is inf"), "{e}");
    let e = read_hdf5(&path, &Hdf5Layout { dataset: "lf/nope".into(), axes: "uvhwb".into() }, 1.0).unwrap_err();
    assert!(e.to_string().contains("no dataset \"lf/nope\""), "{e}");
    let flat = dir.path().join("flat.h5");
    write_h5(&flat, &[4, 13], |_| 0.5);
    let e = read_hdf5(&flat, &Hdf5Layout { dataset: "lf/data".into(), axes: "uvhwb".into() }, 1.0).unwrap_err();
    assert!(e.to_string().contains("has 2 axes"), "{e}");
    // A type the reader does not convert is named, with the conversion (issue 41, item 15;
    // before: "type mismatch: expected numeric, got ...").
    let mut b = hdf5_pure::FileBuilder::new();
    let mut g = b.create_group("lf");
    g.create_dataset("data").with_complex32_data(&[(0.5, 0.0); 13]).with_shape(&[1, 1, 1, 1, 13]);
    b.add_group(g.finish());
    std::fs::write(dir.path().join("complex.h5"), b.finish().unwrap()).unwrap();
    let e = read_hdf5(&dir.path().join("complex.h5"), &layout, 1.0).unwrap_err().to_string();
    assert!(e.contains("holds") && e.contains("slf reads 32- or 64-bit floats and integers"), "{e}");
    std::fs::write(dir.path().join("junk.h5"), b"not hdf5 at all").unwrap();
    let e = read_hdf5(&dir.path().join("junk.h5"), &layout, 1.0).unwrap_err();
    assert!(e.to_string().contains("not an HDF5 file"), "{e}");
}
