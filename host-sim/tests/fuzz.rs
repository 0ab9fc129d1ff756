//! Fuzz targets of the host's readers: the `.npy` reader and the capture loader, on
//! arbitrary and mutated files. Each must return (a value or a one-line error) without
//! panicking, hanging or allocating what the file cannot back, and what it returns must
//! hold together (values match the shape; a loaded capture's frames match its geometry).
//!
//! Why proptest and how to run it long: see `firmware/tests/fuzz.rs` (`SLF_FUZZ_CASES`,
//! `SLF_FUZZ_SEED`):
//!
//!     SLF_FUZZ_CASES=20000 cargo test --release --test fuzz -- --nocapture

use std::sync::atomic::{AtomicU32, Ordering};

use proptest::prelude::*;

#[path = "../../firmware/tests/common/fuzz_runner.rs"]
mod fuzz_runner;
use fuzz_runner::{cases, runner};
use slf_host::io::capture::Capture;
use slf_host::io::npy::{self, Values};
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;
use common::{npy_bytes, small_smooth};

/// Inputs that were read (or loaded) successfully.
static READ: AtomicU32 = AtomicU32::new(0);
static LOADED: AtomicU32 = AtomicU32::new(0);

/// Reads `bytes` as an `.npy`; a success must be consistent with its shape and with the
/// number of bytes it came from.
fn check_npy(bytes: &[u8]) -> Result<(), TestCaseError> {
    if let Ok(a) = npy::read_from(bytes, bytes.len() as u64) {
        READ.fetch_add(1, Ordering::Relaxed);
        let n: usize = a.shape.iter().product();
        let (len, item) = match &a.values {
            Values::F32(v) => (v.len(), 4),
            Values::U16(v) => (v.len(), 2),
        };
        prop_assert_eq!(len, n);
        prop_assert!(n * item <= bytes.len() * 2, "more values than the file can hold");
    }
    Ok(())
}

/// A valid header's pieces, recombined and corrupted: the parser's hard cases.
fn header_text() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("{".to_string()),
        Just("}".to_string()),
        Just("(".to_string()),
        Just(")".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just(", ".to_string()),
        Just(": ".to_string()),
        Just("'descr'".to_string()),
        Just("'<f4'".to_string()),
        Just("'<u2'".to_string()),
        Just("'>f8'".to_string()),
        Just("'fortran_order'".to_string()),
        Just("True".to_string()),
        Just("False".to_string()),
        Just("'shape'".to_string()),
        (0u64..20).prop_map(|n| n.to_string()),
        any::<u64>().prop_map(|n| n.to_string()),
        Just("L".to_string()),
        Just("\"".to_string()),
        Just("'".to_string()),
        Just(" ".to_string()),
        Just("\n".to_string()),
    ];
    prop::collection::vec(token, 0..60).prop_map(|t| t.concat())
}

#[test]
fn fuzz_npy_reader() {
    // Random bytes, with and without the magic.
    runner()
        .run(&(prop::collection::vec(any::<u8>(), 0..512), any::<bool>()), |(bytes, magic)| {
            let bytes = if magic { [b"\x93NUMPY".as_slice(), &bytes].concat() } else { bytes };
            check_npy(&bytes)
        })
        .unwrap();
    // Headers built from the grammar's own tokens, any order, any nesting.
    runner()
        .run(&(header_text(), 1u8..4, prop::collection::vec(any::<u8>(), 0..256)), |(h, v, body)| {
            check_npy(&npy_bytes(v, &h, &body))
        })
        .unwrap();
    // Valid headers with any shape and dtype, and a body of any length.
    let valid = (
        prop::sample::select(vec!["<f4", ">f4", "<f8", "<u2", ">u2", "<i4", "|u1"]),
        any::<bool>(),
        prop::collection::vec(prop_oneof![8 => 0u64..5, 1 => any::<u64>()], 0..6),
        0usize..600,
    );
    runner()
        .run(&valid, |(descr, fortran, shape, body)| {
            let shape: String = shape.iter().map(|n| format!("{n}, ")).collect();
            let t = if fortran { "True" } else { "False" };
            let h = format!("{{'descr': '{descr}', 'fortran_order': {t}, 'shape': ({}), }}", shape.trim_end());
            check_npy(&npy_bytes(1, &h, &vec![0x3f; body]))
        })
        .unwrap();
    let read = READ.load(Ordering::Relaxed);
    eprintln!("fuzz npy reader: {} cases x 3 generators ({read} read as arrays), no failure", cases());
    assert!(read > 0, "the generators must reach a successful read");
}

/// A JSON value to put in a capture description's field.
fn json_value() -> impl Strategy<Value = serde_json::Value> {
    use serde_json::json;
    prop_oneof![
        Just(json!(null)),
        any::<bool>().prop_map(|b| json!(b)),
        any::<i64>().prop_map(|n| json!(n)),
        any::<u64>().prop_map(|n| json!(n)),
        (0u64..70_000).prop_map(|n| json!(n)),
        any::<f64>().prop_map(|x| json!(x)),
        "[a-z./]{0,12}".prop_map(|s| json!(s)),
        prop::collection::vec(0u64..70_000, 0..4).prop_map(|v| json!(v)),
        prop::collection::vec(prop::collection::vec(0u64..300, 0..3), 0..3).prop_map(|v| json!(v)),
        Just(json!({"family": "pixel", "tile": [[[0, 1], [2, 3]]]})),
        Just(json!({"family": "kronecker", "snapshots": 2, "seed": 1, "block": [5, 5]})),
        Just(json!(["../x.pgm"])),
        Just(json!(["/dev/zero"])),
    ]
}

#[test]
fn fuzz_capture_loader() {
    // One valid capture, its description mutated field by field, its frames corrupted.
    let lf = small_smooth(5);
    let base = tempfile::tempdir().unwrap();
    let mut cam = CameraConfig::pixel(3, 2);
    cam.frame_ext = "pgm".into();
    simulate(&lf, &cam).unwrap().save(base.path()).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(base.path().join("capture.json")).unwrap()).unwrap();
    let frame0 = std::fs::read(base.path().join("snapshot_0.pgm")).unwrap();
    let frame1 = std::fs::read(base.path().join("snapshot_1.pgm")).unwrap();
    let keys = vec![
        "format",
        "version",
        "lenslets",
        "views",
        "bands_nm",
        "mask",
        "frames",
        "bits",
        "black_level",
        "white_level",
        "saturation_level",
        "noise",
        "defective_pixels",
        "extra",
    ];
    let edits = prop::collection::vec((prop::sample::select(keys), json_value()), 0..4);
    let frame_edit = (any::<usize>(), any::<u8>(), prop::option::of(any::<usize>()));

    runner()
        .run(&(edits, frame_edit), |(edits, (at, byte, cut))| {
            let dir = tempfile::tempdir().unwrap();
            let mut j = json.clone();
            for (k, v) in edits {
                j[k] = v;
            }
            std::fs::write(dir.path().join("capture.json"), j.to_string()).unwrap();
            let mut f0 = frame0.clone();
            let n = f0.len();
            f0[at % n] = byte;
            if let Some(c) = cut {
                f0.truncate(c % n);
            }
            std::fs::write(dir.path().join("snapshot_0.pgm"), f0).unwrap();
            std::fs::write(dir.path().join("snapshot_1.pgm"), &frame1).unwrap();
            match Capture::load(dir.path()) {
                Ok(c) => {
                    LOADED.fetch_add(1, Ordering::Relaxed);
                    let (rows, cols) = c.frame_size();
                    prop_assert!(c.frames.iter().all(|f| f.len() == rows * cols));
                    prop_assert_eq!(c.mask().map(|m| m.snapshots()).ok(), Some(c.frames.len()));
                }
                Err(e) => {
                    let text = format!("{e:#}");
                    prop_assert_eq!(text.lines().count(), 1, "not one line: {}", text);
                }
            }
            Ok(())
        })
        .unwrap();
    let loaded = LOADED.load(Ordering::Relaxed);
    eprintln!("fuzz capture loader: {} cases ({loaded} loaded), no failure", cases());
    assert!(loaded > 0, "the generator must reach a successful load");
}
