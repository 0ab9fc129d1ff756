//! Hostile and unusual input files: every one a clear one-line error or a documented
//! conversion, never a hang, a panic or an allocation the file cannot back.
//!
//! `.npy` files are written byte by byte here (no numpy needed), so each case is exactly the
//! file named in the test.

use slf_host::sim::flags::FromFlags;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use slf_host::io::capture::Capture;
use slf_host::io::frame_file::{read_frame, write_frame};
use slf_host::io::lightfield::{LightField, read_npy, read_npy_with_notes};
use slf_host::io::npy::{self, NpyErrorKind, Values};
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;
use common::{forget_records, npy_bytes, png_claiming, small_smooth};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::File::create(&p).unwrap().write_all(bytes).unwrap();
    p
}

/// Runs `f` on another thread and fails the test if it takes longer than `secs`.
fn within<T: Send + 'static>(secs: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(secs)).expect("did not finish in time (or panicked)")
}

#[test]
fn nested_brackets_in_a_header_are_refused_at_once() {
    // Before: the header parser backtracked exponentially (12 braces 1.6 s, 14 braces 14 s,
    // 20 braces hours). Now the header is read in one pass.
    let dir = tempfile::tempdir().unwrap();
    for open in ["{", "(", "["] {
        let close = match open {
            "{" => "}",
            "(" => ")",
            _ => "]",
        };
        let header =
            format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {}{}}}", open.repeat(40), close.repeat(40));
        let p = write(dir.path(), "nested.npy", &npy_bytes(1, &header, &[]));
        let e = within(5, move || read_npy(&p).unwrap_err().to_string());
        assert!(e.contains("nested.npy") && e.contains("header, byte"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // Also as the descr and as a key.
    let header = format!("{{'descr': {}", "[".repeat(60));
    let p = write(dir.path(), "nested2.npy", &npy_bytes(1, &header, &[]));
    let e = within(5, move || read_npy(&p).unwrap_err().to_string());
    assert!(e.contains("structured dtypes are not supported"), "{e}");
}

#[test]
fn a_header_longer_than_numpys_limit_is_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    // A 20-byte v3 file whose header length field says 0xfffffff7: refused, nothing allocated.
    let mut bytes = b"\x93NUMPY\x03\x00".to_vec();
    bytes.extend_from_slice(&0xffff_fff7u32.to_le_bytes());
    bytes.extend_from_slice(b"{'descr'");
    assert_eq!(bytes.len(), 20);
    let p = write(dir.path(), "v3.npy", &bytes);
    let e = read_npy(&p).unwrap_err();
    assert!(matches!(e.kind, NpyErrorKind::HeaderTooLong(0xffff_fff7)), "{e}");
    // Within the limit but past the end of the file.
    let mut bytes = b"\x93NUMPY\x02\x00".to_vec();
    bytes.extend_from_slice(&9000u32.to_le_bytes());
    bytes.extend_from_slice(b"{}");
    let p = write(dir.path(), "short.npy", &bytes);
    let e = read_npy(&p).unwrap_err();
    assert!(matches!(e.kind, NpyErrorKind::HeaderPastEnd { header: 9000, file: 14 }), "{e}");
}

#[test]
fn shapes_that_overflow_or_outgrow_the_file_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    // The product wraps u64 to 256 values (2^56 + 1) * 256 = 2^64 + 256: before, this read
    // 256 values and then indexed out of bounds.
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (72057594037927937, 1, 16, 16, 1), }";
    let p = write(dir.path(), "wrap.npy", &npy_bytes(1, header, &[0; 1024]));
    let e = read_npy(&p).unwrap_err();
    assert!(matches!(e.kind, NpyErrorKind::Overflow { .. }), "{e}");
    assert!(e.to_string().contains("wrap.npy"), "{e}");
    // A shape that fits u64 but not the file (2.8 EB): truncation, counted, not allocated.
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (1000000000, 1000, 1000, 1, 1), }";
    let p = write(dir.path(), "huge.npy", &npy_bytes(1, header, &[0; 64]));
    let e = read_npy(&p).unwrap_err();
    assert!(matches!(e.kind, NpyErrorKind::Truncated { expected: 1_000_000_000_000_000, found: 16 }), "{e}");
    // An axis length beyond u64.
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999999999999, 1), }";
    let p = write(dir.path(), "digits.npy", &npy_bytes(1, header, &[]));
    assert!(read_npy(&p).unwrap_err().to_string().contains("does not fit in 64 bits"));
}

#[test]
fn fifos_and_folders_are_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let e = read_npy(dir.path()).unwrap_err();
    assert!(matches!(e.kind, NpyErrorKind::NotAFile), "{e}");
    #[cfg(unix)]
    {
        let fifo = dir.path().join("fifo.npy");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let e = within(5, move || read_npy(&fifo).unwrap_err().to_string());
        assert!(e.contains("not a regular file"), "{e}");
    }
}

/// `data` (C order, shape `s`) laid out in Fortran order, by the obvious index formula.
fn to_fortran(data: &[f64], s: &[usize]) -> Vec<f64> {
    let mut out = vec![0.0; data.len()];
    for (c, &x) in data.iter().enumerate() {
        let mut rest = c;
        let mut idx = vec![0; s.len()];
        for a in (0..s.len()).rev() {
            idx[a] = rest % s[a];
            rest /= s[a];
        }
        let mut f = 0;
        for a in (0..s.len()).rev() {
            f = f * s[a] + idx[a];
        }
        out[f] = x;
    }
    out
}

#[test]
fn numpys_defaults_are_converted_with_a_note() {
    // np.save of a float64 array, and of np.asfortranarray: accepted, converted, noted.
    let dir = tempfile::tempdir().unwrap();
    let shape = [2usize, 3, 4, 5, 2];
    let c: Vec<f64> = (0..240).map(|i| f64::from(i) / 240.0 + 1e-9).collect();
    let body = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let want: Vec<f32> = c.iter().map(|&x| x as f32).collect();

    let h = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3, 4, 5, 2), }";
    let p = write(dir.path(), "f64.npy", &npy_bytes(1, h, &body(&c)));
    let (lf, notes) = read_npy_with_notes(&p).unwrap();
    assert_eq!(lf.data, want);
    assert_eq!(lf.shape(), shape);
    assert_eq!(notes, ["float64 converted to float32"]);

    let h = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3, 4, 5, 2), }";
    let p = write(dir.path(), "fortran.npy", &npy_bytes(1, h, &body(&to_fortran(&c, &shape))));
    let (lf, notes) = read_npy_with_notes(&p).unwrap();
    assert_eq!(lf.data, want, "Fortran order read back in C order");
    assert!(notes.iter().any(|n| n.contains("Fortran")), "{notes:?}");

    // Big-endian float32, in a version 2 file, with a Python 2 long suffix.
    let h = "{'descr': '>f4', 'fortran_order': False, 'shape': (1L, 1L, 1L, 2L, 2L), }";
    let be: Vec<u8> = [0.25f32, 0.5, 0.75, 1.0].iter().flat_map(|x| x.to_be_bytes()).collect();
    let p = write(dir.path(), "be.npy", &npy_bytes(2, h, &be));
    let (lf, notes) = read_npy_with_notes(&p).unwrap();
    assert_eq!(lf.data, [0.25, 0.5, 0.75, 1.0]);
    assert!(notes[0].contains("big-endian"), "{notes:?}");

    // A plain file: no notes. Double quotes and no trailing comma are valid Python too.
    let h = r#"{"descr": "<u2", "fortran_order": False, "shape": (1, 1, 1, 1, 2)}"#;
    let p = write(dir.path(), "u2.npy", &npy_bytes(1, h, &[0, 0, 255, 255]));
    let (lf, notes) = read_npy_with_notes(&p).unwrap();
    assert_eq!(lf.data, [0.0, 1.0]);
    assert!(notes.is_empty());

    // A finite float64 beyond float32's range is named as such (issue 41, item 15), not
    // called "not finite".
    let h = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1, 1, 1, 2), }";
    let body: Vec<u8> = [0.5f64, 1e300].iter().flat_map(|x| x.to_le_bytes()).collect();
    let p = write(dir.path(), "big.npy", &npy_bytes(1, h, &body));
    let e = read_npy(&p).unwrap_err().to_string();
    assert!(e.contains("value 1 (in the file's order) is 1e300, beyond float32's range"), "{e}");
}

#[test]
fn malformed_headers_are_one_line_errors_with_the_byte() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("{'descr': '<f4', 'fortran_order': Flase, 'shape': (1,), }", "expected True or False"),
        ("{'descr': '<f4', 'shape': (1,), }", "\"fortran_order\" is missing"),
        ("{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (1,)}", "given twice"),
        ("{'descr': '<f4', 'fortran_order': False, 'shape': (1,), 'x': 1}", "unexpected key \"x\""),
        ("{'descr': '<f4', 'fortran_order': False, 'shape': (1,)} trailing", "after the header's closing brace"),
        ("{'descr': '<f4\\n', 'fortran_order': False, 'shape': (1,)}", "unexpected character"),
        ("{'descr': '<f4', 'fortran_order': False, 'shape': (-1,)}", "expected an axis length"),
        ("{'descr': '<c8', 'fortran_order': False, 'shape': (1,)}", "dtype '<c8'"),
    ];
    for (header, want) in cases {
        let p = write(dir.path(), "h.npy", &npy_bytes(1, header, &[0; 16]));
        let e = read_npy(&p).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains("h.npy"), "{header}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // Too many axes.
    let header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({})}}", "1, ".repeat(65));
    let p = write(dir.path(), "axes.npy", &npy_bytes(1, &header, &[0; 4]));
    assert!(read_npy(&p).unwrap_err().to_string().contains("more than 64 axes"));
}

#[test]
fn light_fields_with_nan_or_inf_are_refused_with_the_first_place() {
    let dir = tempfile::tempdir().unwrap();
    let h = "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1, 2, 2, 2), }";
    let mut v = [0.5f32; 8];
    v[5] = f32::NAN;
    v[7] = f32::INFINITY;
    let body: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    let p = write(dir.path(), "nan.npy", &npy_bytes(1, h, &body));
    let e = read_npy(&p).unwrap_err().to_string();
    assert!(e.contains("2 of 8 values are not finite") && e.contains("(0, 0, 1, 0, 1)"), "{e}");
}

#[test]
fn the_reader_agrees_with_npyz_on_files_npyz_writes() {
    // npyz still writes slf's files; the reader must read them back exactly.
    let dir = tempfile::tempdir().unwrap();
    let lf = LightField {
        views: (2, 3),
        rows: 4,
        cols: 5,
        bands: 3,
        data: (0..360).map(|i| (i as f32 * 0.37).sin().abs()).collect(),
    };
    let p = dir.path().join("lf.npy");
    slf_host::io::lightfield::write_npy(&p, &lf, slf_host::io::lightfield::Dtype::F32).unwrap();
    let a = npy::read(&p).unwrap();
    assert_eq!(a.shape, [2, 3, 4, 5, 3]);
    assert_eq!(a.values, Values::F32(lf.data.clone()));
}

/// A binary PGM as a 12-bit camera tool writes it: MAXVAL 4095, big-endian samples.
fn pgm_4095(path: &Path, rows: usize, cols: usize, data: &[u16]) {
    let mut bytes = format!("P5\n# 12-bit raw\n{cols} {rows}\n4095\n").into_bytes();
    bytes.extend(data.iter().flat_map(|x| x.to_be_bytes()));
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn pgm_values_are_dn_as_stored_whatever_maxval_says() {
    // Before: the image library rescaled MAXVAL 4095 by 65535 / 4095, so every pixel read
    // as saturated and the decode "succeeded" at 1 dB.
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u16> = (0..60u16).map(|i| i * 68).collect(); // 0..=4012
    let p = dir.path().join("f.pgm");
    pgm_4095(&p, 6, 10, &data);
    let f = read_frame(&p, None).unwrap();
    assert_eq!((f.rows, f.cols, f.top), (6, 10, 4095));
    assert_eq!(f.data, data);
    // A sample above MAXVAL is an invalid file.
    let mut bad = data.clone();
    bad[13] = 4096;
    pgm_4095(&p, 6, 10, &bad);
    let e = format!("{:#}", read_frame(&p, None).unwrap_err());
    assert!(e.contains("pixel (1, 3) is 4096, above MAXVAL 4095"), "{e}");
    // Bytes after the image (a writer that disagrees with its header): refused (issue 32,
    // item 7), not read as a valid frame.
    pgm_4095(&p, 6, 10, &data);
    let mut long = std::fs::read(&p).unwrap();
    long.extend([0u8; 100]);
    std::fs::write(&p, long).unwrap();
    let e = format!("{:#}", read_frame(&p, None).unwrap_err());
    assert!(e.contains("bytes after the 10 x 6 pixels"), "{e}");
    // slf writes P5 (not P7/PAM) with the values as they are.
    let q = dir.path().join("w.pgm");
    write_frame(&q, &data, 6, 10).unwrap();
    assert_eq!(&std::fs::read(&q).unwrap()[..3], b"P5\n");
    assert_eq!(read_frame(&q, None).unwrap().data, data);
}

#[test]
fn a_capture_from_a_12_bit_tool_decodes_like_its_16_bit_copy() {
    let lf = small_smooth(5);
    let dir = tempfile::tempdir().unwrap();
    let cap = simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap();
    cap.save(dir.path()).unwrap();
    forget_records(dir.path()); // another tool's folder
    let (rows, cols) = cap.frame_size();
    pgm_4095(&dir.path().join("snapshot_0.pgm"), rows, cols, &cap.held_frames().unwrap()[0]);
    let back = Capture::load(dir.path()).unwrap();
    assert_eq!(back.held_frames().unwrap(), cap.held_frames().unwrap());
    // MAXVAL below the capture's saturation level: saturated pixels would pass as
    // measurements, so the file is refused.
    let mut bytes = format!("P5\n{cols} {rows}\n255\n").into_bytes();
    bytes.extend(cap.held_frames().unwrap()[0].iter().map(|&x| (x / 16) as u8));
    std::fs::write(dir.path().join("snapshot_0.pgm"), bytes).unwrap();
    let e = format!("{:#}", Capture::load(dir.path()).unwrap_err());
    assert!(e.contains("snapshot_0.pgm") && e.contains("below saturation_level 4095"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// A capture saved, then its description's file records dropped: a folder from another tool
/// (or an older slf), so that every check of the frames themselves is reached when a test
/// writes a frame in place.
fn saved_capture() -> (tempfile::TempDir, serde_json::Value) {
    let lf = small_smooth(5);
    let dir = tempfile::tempdir().unwrap();
    simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap().save(dir.path()).unwrap();
    forget_records(dir.path());
    let json = std::fs::read_to_string(dir.path().join("capture.json")).unwrap();
    (dir, serde_json::from_str(&json).unwrap())
}

#[test]
fn hostile_capture_descriptions_are_one_line_errors() {
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let tile_rows = |rows: usize| serde_json::json!({"family": "pixel", "tile": [vec![vec![0]; rows]]});
    let cases: Vec<(&str, Edit, &str)> = vec![
        // Before: a debug build panicked on the multiplication, a release build wrapped.
        (
            "overflow",
            Box::new(|j| j["lenslets"] = serde_json::json!([9223372036854775808u64, 5])),
            "lenslets [9223372036854775808, 5] out of range 1..=65535",
        ),
        ("big frame", Box::new(|j| j["lenslets"] = serde_json::json!([60000, 2])), "at most 65535 x 65535"),
        // Before: "tile size is zero" (65536 as u16) and "0 snapshots" (256 as u8).
        ("tile rows", Box::new(move |j| j["mask"] = tile_rows(65536)), "mask.tile is 65536 x 1 cells, at most 65535"),
        (
            "tile snapshots",
            Box::new(|j| j["mask"] = serde_json::json!({"family": "pixel", "tile": vec![[[0]]; 256]})),
            "mask.tile has 256 snapshots, at most 32",
        ),
        (
            "absolute",
            Box::new(|j| j["frames"][0] = "/etc/passwd".into()),
            "frames[0]: \"/etc/passwd\" is not a path inside the capture folder",
        ),
        (
            "dot dot",
            Box::new(|j| j["frames"][0] = "../x/snapshot_0.pgm".into()),
            "is not a path inside the capture folder",
        ),
        ("no frames", Box::new(|j| j["frames"] = serde_json::json!([])), "frames lists 0 files"),
        // JSON has no infinity: a level past f32's range is named, not read as infinity.
        (
            "huge white level",
            Box::new(|j| j["white_level"] = serde_json::json!(1e39)),
            "white_level: number out of range",
        ),
        // Issue 41, item 11: finite levels whose difference is not (before: all zeros, exit 0).
        (
            "huge levels",
            Box::new(|j| {
                j["black_level"] = serde_json::json!(-3e38);
                j["white_level"] = serde_json::json!(3e38);
            }),
            "black_level -3e38: must be in 0..=65535",
        ),
        // Issue 41, item 12: wavelengths no filter has, duplicates, a descending list.
        ("band 1e39", Box::new(|j| j["bands_nm"][3] = serde_json::json!(1e38)), "bands_nm[3] is 1e38 nm"),
        ("negative band", Box::new(|j| j["bands_nm"][0] = serde_json::json!(-400)), "bands_nm[0] is -400 nm"),
        (
            "same band",
            Box::new(|j| j["bands_nm"] = serde_json::json!(vec![500.0; 13])),
            "bands_nm[1] is 500 nm after 500",
        ),
        (
            "descending",
            Box::new(|j| {
                let mut b: Vec<f64> = serde_json::from_value(j["bands_nm"].clone()).unwrap();
                b.reverse();
                j["bands_nm"] = serde_json::json!(b);
            }),
            "in increasing wavelength",
        ),
    ];
    for (what, edit, want) in cases {
        let (dir, mut json) = saved_capture();
        edit(&mut json);
        std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
        let e = within(30, {
            let d = dir.path().to_owned();
            move || format!("{:#}", Capture::load(&d).unwrap_err())
        });
        assert!(e.contains(want), "{what}: {e}");
        assert!(e.contains("capture.json"), "{what}: names no file: {e}");
        assert_eq!(e.lines().count(), 1, "{what}: {e}");
    }
    // A FIFO as a frame is refused, not read forever.
    #[cfg(unix)]
    {
        let (dir, mut json) = saved_capture();
        let fifo = dir.path().join("fifo.pgm");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        json["frames"][0] = "fifo.pgm".into();
        std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
        let d = dir.path().to_owned();
        let e = within(5, move || format!("{:#}", Capture::load(&d).unwrap_err()));
        assert!(e.contains("fifo.pgm: not a regular file"), "{e}");
    }
    // An oversized capture.json is refused before reading (a sparse file: no disk used).
    let (dir, _) = saved_capture();
    let f = std::fs::OpenOptions::new().write(true).open(dir.path().join("capture.json")).unwrap();
    f.set_len(slf_host::io::capture::MAX_DESCRIPTION + 1).unwrap();
    let e = format!("{:#}", Capture::load(dir.path()).unwrap_err());
    assert!(e.contains("more than the"), "{e}");
}

#[test]
fn blobs_larger_than_any_real_blob_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("big.slfd");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(slf_host::decode::cs::MAX_BLOB as u64 + 1).unwrap(); // sparse
    let e = format!("{:#}", slf_host::decode::cs::read_blob(&p).unwrap_err());
    assert!(e.contains("big.slfd") && e.contains("of the largest dictionary blob"), "{e}");
    #[cfg(unix)]
    {
        let e = format!("{:#}", slf_host::decode::cs::read_blob(Path::new("/dev/zero")).unwrap_err());
        assert!(e.contains("not a regular file"), "{e}");
    }
    // The shipped blob passes, with its name in any error of a damaged copy.
    std::fs::write(&p, slf_host::firmware::DEFAULT_ENSEMBLE).unwrap();
    assert_eq!(slf_host::decode::cs::read_blob(&p).unwrap(), slf_host::firmware::DEFAULT_ENSEMBLE);
    let mut bad = slf_host::firmware::DEFAULT_ENSEMBLE.to_vec();
    bad[100] ^= 1;
    std::fs::write(&p, bad).unwrap();
    let e = format!("{:#}", slf_host::decode::cs::read_blob(&p).unwrap_err());
    assert!(e.contains("big.slfd: dictionary blob checksum mismatch"), "{e}");
}

#[test]
fn a_capture_the_decoder_refuses_names_its_description() {
    // Before: "decoder: patch has more views than a lenslet", with no file named.
    let lf = small_smooth(3);
    let dir = tempfile::tempdir().unwrap();
    simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap().save(dir.path()).unwrap();
    let cap = Capture::load(dir.path()).unwrap();
    let opts = slf_host::decode::cs::DecodeOptions::default();
    let e =
        format!("{:#}", slf_host::decode::cs::decode_with(&cap, &slf_host::decode::cs::Basis::Dct, &opts).unwrap_err());
    assert!(e.contains("capture's lenslets have 3 x 3 views") && e.contains("at least 4 x 4"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    // The tile decoder's own refusal of a patch larger than the lenslet names the file.
    let e = format!("{:#}", cap.decoder::<4, 4, 5200>(slf_host::firmware::Sl0Config::DEFAULT).unwrap_err());
    assert!(e.contains("capture.json") && e.contains("more views than a lenslet"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// A capture's noise description out of any camera's range is refused where the capture
/// is made or loaded, and a capture with no pixel above the black level is not decoded
/// to zeros (issue 32, item 7).
#[test]
fn captures_without_signal_or_with_impossible_noise_are_refused() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::sim::realistic;
    use slf_host::sim::scene::SceneSize;

    let lf = realistic::lookup("depth").unwrap().render(SceneSize { views: (5, 5), rows: 10, cols: 10 });
    let cap = simulate(&lf, &CameraConfig::pixel(1, 1)).unwrap();
    let mut d = cap.description.clone();
    let mut noise = d.noise.unwrap();
    noise.read_noise_dn = 1e30;
    d.noise = Some(noise);
    let e = format!("{:#}", Capture::new(d.clone(), cap.held_frames().unwrap().into_owned()).unwrap_err());
    assert!(e.contains("noise.read_noise_dn 1000000000000000000000000000000: must be finite"), "{e}");
    noise.read_noise_dn = 2.0;
    noise.full_well_electrons = 0.0;
    d.noise = Some(noise);
    let e = format!("{:#}", Capture::new(d, cap.held_frames().unwrap().into_owned()).unwrap_err());
    assert!(e.contains("noise.full_well_electrons 0"), "{e}");
    // Every pixel at the black level: refused by every method, not decoded to zeros.
    let black = cap.description.black_level as u16;
    let dark = Capture::new(cap.description.clone(), vec![vec![black; cap.held_frames().unwrap()[0].len()]]).unwrap();
    for method in ["cs", "demosaic", "ppid", "interpolate"] {
        let s = DecodeSettings::from_flags(["--method", method]).unwrap();
        let e = format!("{:#}", s.run(&dark, false, &|_, _| {}).unwrap_err());
        assert!(e.contains("no light was recorded"), "{method}: {e}");
    }
}

/// Issue 41, item 1: a frame or light field whose header claims more than the capture (or
/// the light-field cap) allows is refused from its header, before its body is allocated or
/// read: sparse files claiming gigabytes, a tiny PNG claiming 15000 x 15000.
#[test]
fn headers_that_lie_about_their_size_are_refused_before_allocating() {
    let (dir, _) = saved_capture();
    let cap = Capture::load(dir.path()).unwrap();
    let (rows, cols) = cap.frame_size();
    let frame = dir.path().join("snapshot_0.pgm");
    let sparse = |path: &Path, header: &[u8], len: u64| {
        let mut f = std::fs::File::create(path).unwrap();
        f.write_all(header).unwrap();
        f.set_len(len).unwrap();
    };
    let load = |dir: PathBuf| within(20, move || format!("{:#}", Capture::load(&dir).unwrap_err()));
    // PGM, 65535 x 65535 16-bit: 8.6 GB, sparse.
    let header = b"P5\n65535 65535\n65535\n";
    sparse(&frame, header, header.len() as u64 + 2 * 65535 * 65535);
    let e = load(dir.path().to_path_buf());
    assert!(e.contains(&format!("frame is 65535 x 65535, the capture's frames are {rows} x {cols}")), "{e}");
    assert_eq!(e.lines().count(), 1);
    // The same frame as a (65535, 65535) uint16 .npy.
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("capture.json")).unwrap()).unwrap();
    json["frames"] = serde_json::json!(["snapshot_0.npy"]);
    std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
    let npy = npy_bytes(1, "{'descr': '<u2', 'fortran_order': False, 'shape': (65535, 65535), }", &[]);
    sparse(&dir.path().join("snapshot_0.npy"), &npy, npy.len() as u64 + 2 * 65535 * 65535);
    let e = load(dir.path().to_path_buf());
    assert!(e.contains(&format!("frame is 65535 x 65535, the capture's frames are {rows} x {cols}")), "{e}");
    // A 60-byte PNG claiming 15000 x 15000.
    json["frames"] = serde_json::json!(["snapshot_0.png"]);
    std::fs::write(dir.path().join("capture.json"), json.to_string()).unwrap();
    std::fs::write(dir.path().join("snapshot_0.png"), png_claiming(15000, 15000)).unwrap();
    let e = load(dir.path().to_path_buf());
    assert!(e.contains(&format!("frame is 15000 x 15000, the capture's frames are {rows} x {cols}")), "{e}");
    // A light field of 5 x 5 x 4000 x 4000 x 13 f4 (20.8 GB, sparse): over the cap.
    let lf = dir.path().join("big.npy");
    let npy = npy_bytes(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 4000, 4000, 13), }", &[]);
    sparse(&lf, &npy, npy.len() as u64 + 4 * 5 * 5 * 4000 * 4000 * 13);
    let e = within(20, move || read_npy(&lf).unwrap_err().to_string());
    assert!(e.contains("shape [5, 5, 4000, 4000, 13]") && e.contains("more than the"), "{e}");
}

/// Issue 41, item 13: frame names outside the folder are refused when a capture is made
/// (so `save` never writes outside it), and a frame that is a symbolic link to a file
/// outside the folder is not read by `load`.
#[test]
fn frames_stay_inside_their_capture_folder() {
    let (dir, json) = saved_capture();
    let cap = Capture::load(dir.path()).unwrap();
    for (names, says) in [
        (vec!["../x.pgm"], "frames[0]: \"../x.pgm\" is not a path inside the capture folder"),
        (vec!["/tmp/abs.pgm"], "is not a path inside the capture folder"),
        (vec!["snapshot_0.txt"], "is not a .pgm, .png or .npy file"),
    ] {
        let mut d = cap.description.clone();
        d.frames = names.iter().map(|s| s.to_string()).collect();
        let e = format!("{:#}", Capture::new(d, cap.held_frames().unwrap().into_owned()).unwrap_err());
        assert!(e.contains(says), "{e}");
    }
    let mut d = cap.description.clone();
    d.frames = vec!["a.pgm".into(), "a.pgm".into()];
    let e = format!("{:#}", Capture::new(d, vec![cap.held_frames().unwrap()[0].clone(); 2]).unwrap_err());
    assert!(e.contains("frames[1]: \"a.pgm\" is named twice"), "{e}");
    // A link to a frame outside the folder.
    #[cfg(unix)]
    {
        let outside = tempfile::tempdir().unwrap();
        let name = json["frames"][0].as_str().unwrap().to_string();
        std::fs::rename(dir.path().join(&name), outside.path().join(&name)).unwrap();
        std::os::unix::fs::symlink(outside.path().join(&name), dir.path().join(&name)).unwrap();
        let e = format!("{:#}", Capture::load(dir.path()).unwrap_err());
        assert!(e.contains("outside the capture folder") && e.lines().count() == 1, "{e}");
        // A link inside the folder is fine.
        std::fs::remove_file(dir.path().join(&name)).unwrap();
        std::fs::rename(outside.path().join(&name), dir.path().join("real.pgm")).unwrap();
        std::os::unix::fs::symlink("real.pgm", dir.path().join(&name)).unwrap();
        assert_eq!(Capture::load(dir.path()).unwrap().held_frames().unwrap(), cap.held_frames().unwrap());
    }
}
