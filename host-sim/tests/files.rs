//! Light-field `.npy` files and capture folders: round trips, and bad files rejected with
//! a message that says what is wrong.

use std::io::Write;

use slf_host::io::capture::{Capture, MaskDescription, MaskSource};
use slf_host::io::lightfield::{Dtype, LightField, read_npy, write_npy};
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{self, SceneSize};

fn small() -> LightField {
    scene::named("texture").unwrap().render(SceneSize { views: (5, 5), rows: 10, cols: 15 })
}

#[test]
fn npy_round_trips_f32_and_u16() {
    let dir = tempfile::tempdir().unwrap();
    let lf = small();
    let p = dir.path().join("a.npy");
    write_npy(&p, &lf, Dtype::F32).unwrap();
    assert_eq!(read_npy(&p).unwrap(), lf);
    write_npy(&p, &lf, Dtype::U16).unwrap();
    let back = read_npy(&p).unwrap();
    assert_eq!(back.shape(), lf.shape());
    let worst = back.data.iter().zip(&lf.data).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
    assert!(worst <= 0.5 / 65535.0 + 1e-7, "u16 quantisation error {worst}");
}

/// Writes an .npy by hand: header dict and body bytes.
fn raw_npy(path: &std::path::Path, descr: &str, shape: &str, body: &[u8]) {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut f = std::fs::File::create(path).unwrap();
    f.write_all(b"\x93NUMPY\x01\x00").unwrap();
    f.write_all(&(header.len() as u16).to_le_bytes()).unwrap();
    f.write_all(header.as_bytes()).unwrap();
    f.write_all(body).unwrap();
}

#[test]
fn bad_npy_files_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.npy");
    let err = |p: &std::path::Path| read_npy(p).unwrap_err().to_string();

    raw_npy(&p, "<i4", "(1, 1, 2, 2, 1)", &[0; 16]);
    assert!(err(&p).contains("dtype '<i4'"), "{}", err(&p));
    raw_npy(&p, "<f4", "(2, 2, 3)", &[0; 48]);
    assert!(err(&p).contains("3 axes"), "{}", err(&p));
    raw_npy(&p, "<f4", "(1, 1, 2, 2, 3)", &[0; 20]);
    assert!(err(&p).contains("truncated body: header promises 12 values, file holds 5"), "{}", err(&p));
    raw_npy(&p, "<u2", "(1, 1, 0, 2, 3)", &[]);
    assert!(err(&p).contains("empty axis"), "{}", err(&p));
    std::fs::write(&p, b"not an npy file at all").unwrap();
    assert!(err(&p).contains("bad.npy"), "{}", err(&p));
    assert!(err(&dir.path().join("missing.npy")).contains("missing.npy"));
    // uint16 bodies are read and scaled.
    raw_npy(&p, "<u2", "(1, 1, 1, 1, 2)", &[0, 0, 255, 255]);
    assert_eq!(read_npy(&p).unwrap().data, vec![0.0, 1.0]);
}

#[test]
fn captures_round_trip_in_every_frame_format() {
    let lf = small();
    for ext in ["pgm", "png", "npy"] {
        let dir = tempfile::tempdir().unwrap();
        let mut cam = CameraConfig::pixel(3, 2);
        cam.frame_ext = ext.into();
        cam.defect_fraction = 0.01;
        let cap = simulate(&lf, &cam).unwrap();
        assert!(!cap.description.defective_pixels.is_empty());
        cap.save(dir.path()).unwrap();
        let back = Capture::load(dir.path()).unwrap();
        assert_eq!(back.description, cap.description, "{ext}");
        assert_eq!(back.held_frames().unwrap(), cap.held_frames().unwrap(), "{ext}");
    }
}

fn saved_capture() -> (tempfile::TempDir, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    simulate(&small(), &CameraConfig::pixel(3, 2)).unwrap().save(dir.path()).unwrap();
    let json = std::fs::read_to_string(dir.path().join("capture.json")).unwrap();
    (dir, serde_json::from_str(&json).unwrap())
}

#[test]
fn bad_captures_say_what_and_where() {
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        ("format", Box::new(|j| j["format"] = "other".into()), "format is \"other\""),
        ("version", Box::new(|j| j["version"] = 9.into()), "version 9"),
        ("unknown field", Box::new(|j| j["colour"] = 1.into()), "unknown field `colour`"),
        ("mask family", Box::new(|j| j["mask"]["family"] = "stripes".into()), "unknown variant `stripes`"),
        ("snapshots", Box::new(|j| j["mask"]["snapshots"] = 3.into()), "mask has 3 snapshots, capture has 2 frames"),
        ("band count", Box::new(|j| j["mask"]["snapshots"] = 14.into()), "14 snapshots with 13 bands"),
        (
            "defect",
            Box::new(|j| j["defective_pixels"] = serde_json::json!([[500, 1]])),
            "defective pixel [500, 1] outside",
        ),
        ("levels", Box::new(|j| j["white_level"] = 10.into()), "black_level < white_level"),
        (
            "lenslets",
            Box::new(|j| j["lenslets"] = serde_json::json!([11, 15])),
            "frame is 50 x 75, the capture's frames are 55 x 75",
        ),
        (
            "tile",
            Box::new(|j| j["mask"] = serde_json::json!({"family": "pixel", "tile": [[[0, 1]], [[0, 2]]]})),
            "repeated",
        ),
        ("missing frame", Box::new(|j| j["frames"][1] = "nope.pgm".into()), "nope.pgm"),
    ];
    for (what, edit, want) in cases {
        let (dir, mut json) = saved_capture();
        edit(&mut json);
        std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
        let e = format!("{:#}", Capture::load(dir.path()).unwrap_err());
        assert!(e.contains(want), "{what}: {e}");
        assert!(e.contains("capture.json") || e.contains(".pgm"), "{what}: names no file: {e}");
    }
    // A truncated frame file.
    let (dir, _) = saved_capture();
    let f = dir.path().join("snapshot_0.pgm");
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() / 2]).unwrap();
    let e = format!("{:#}", Capture::load(dir.path()).unwrap_err());
    assert!(e.contains("snapshot_0.pgm"), "{e}");
}

#[test]
fn a_capture_written_by_another_tool_loads() {
    // What a user's own tool writes: JSON by hand, an explicit 2 x 2 band tile per
    // snapshot, frames as 16-bit PNG written by the image crate.
    let dir = tempfile::tempdir().unwrap();
    let (rows, cols) = (25, 30);
    for j in 0..2 {
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(cols, rows, |x, y| {
            image::Luma([(64 + x * 10 + y) as u16 + j])
        });
        img.save(dir.path().join(format!("f{j}.png"))).unwrap();
    }
    let json = serde_json::json!({
        "format": "slf-capture", "version": 1,
        "lenslets": [5, 6], "views": [5, 5],
        "bands_nm": [400, 425, 450, 475, 500, 525, 550, 575, 600, 625, 650, 675, 700],
        "mask": {"family": "pixel", "tile": [[[0, 4], [8, 12]], [[1, 5], [9, 2]]]},
        "frames": ["f0.png", "f1.png"],
        "bits": 12, "black_level": 64, "white_level": 4000, "saturation_level": 4095
    });
    std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
    let cap = Capture::load(dir.path()).unwrap();
    assert_eq!(cap.held_frames().unwrap()[1][cols as usize + 2], 64 + 20 + 1 + 1);
    let mask = cap.mask().unwrap();
    assert_eq!(mask.bands_at(1, 1).as_slice(), &[12, 2]);
    assert_eq!(mask.bands_at(3, 2).as_slice(), &[8, 9]);
    assert!(matches!(cap.description.mask, MaskDescription::Pixel(MaskSource { tile: Some(_), .. })));
}

#[test]
fn previews_are_scaled_at_least_4x_and_labelled() {
    let truth = small();
    let mut recon = truth.clone();
    recon.data.iter_mut().enumerate().for_each(|(i, x)| *x += 0.01 * (i % 7) as f32);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("preview.png");
    slf_host::eval::preview::write_comparison(&p, &truth, &recon, "a label").unwrap();
    let img = image::open(&p).unwrap().into_rgb8();
    let (w, h) = (truth.cols as u32, truth.rows as u32);
    // Three panels, each at least 4x, with room for the labels and the colour bar.
    assert!(img.width() >= 3 * 4 * w && img.height() >= 4 * h + 60, "{} x {}", img.width(), img.height());
    // Labels: bright text pixels in the band above the panels (the background is dark grey).
    let text =
        (0..img.width()).flat_map(|x| (0..30).map(move |y| (x, y))).filter(|&(x, y)| img.get_pixel(x, y)[0] > 150);
    assert!(text.count() > 200, "no labels drawn");
    // The method's label under the reconstruction (the middle panel): text there that an
    // empty label does not draw.
    let q = dir.path().join("unlabelled.png");
    slf_host::eval::preview::write_comparison(&q, &truth, &recon, "").unwrap();
    let bare = image::open(&q).unwrap().into_rgb8();
    let s4 = 4.max(300u32.div_ceil(w.max(h)));
    let (x0, y0) = (2 * 12 + w * s4, 34 + h * s4 + 8);
    let bright = |im: &image::RgbImage| {
        (x0..x0 + w * s4)
            .flat_map(|x| (y0..y0 + 24).map(move |y| (x, y)))
            .filter(|&(x, y)| im.get_pixel(x, y)[0] > 150)
            .count()
    };
    assert!(bright(&img) > bright(&bare) + 20, "no label under the reconstruction");
    // The colour bar's ends: black at 0, white at full scale.
    let scale = 4.max(300u32.div_ceil(w.max(h)));
    let (bar_x, bar_y) = (3 * 12 + 2 * w * scale, 34 + h * scale + 10 + 7);
    assert_eq!(img.get_pixel(bar_x, bar_y).0, [0, 0, 0]);
    assert_eq!(img.get_pixel(bar_x + w * scale - 1, bar_y).0, [255, 255, 255]);
}
