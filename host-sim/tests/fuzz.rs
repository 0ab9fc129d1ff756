//! Fuzz targets of the host's readers and flags: the `.npy` reader and the capture loader,
//! on arbitrary and mutated files; `slf import views` / `cube`'s options and `slf decode`'s
//! solver, noise and gain flags, with any values. Each must return (a value or a one-line
//! error) without panicking, hanging or allocating what the input cannot back, and what it
//! returns must hold together (values match the shape; a loaded capture's frames match its
//! geometry; an accepted flag is within its stated range and decodes into the sensor's
//! physical range).
//!
//! Why proptest and how to run it long: see `firmware/tests/fuzz.rs` (`SLF_FUZZ_CASES`,
//! `SLF_FUZZ_SEED`):
//!
//!     SLF_FUZZ_CASES=20000 cargo test --release --test fuzz -- --nocapture

use slf_host::sim::flags::FromFlags;
use std::sync::atomic::{AtomicU32, Ordering};

use proptest::prelude::*;

#[path = "../../firmware/tests/common/fuzz_runner.rs"]
mod fuzz_runner;
use fuzz_runner::{cases, runner};
use slf_host::io::capture::Capture;
use slf_host::io::npy::{self, Values};
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;
use common::{npy_bytes, png_claiming, small_smooth};

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
    // Valid headers with any shape and dtype, and a body of any length or, half the time,
    // of the length the header states (the reader refuses bytes past it).
    let valid = (
        prop::sample::select(vec!["<f4", ">f4", "<f8", "<u2", ">u2", "<i4", "|u1"]),
        any::<bool>(),
        prop::collection::vec(prop_oneof![8 => 0u64..5, 1 => any::<u64>()], 0..6),
        0usize..600,
        any::<bool>(),
    );
    runner()
        .run(&valid, |(descr, fortran, shape, body, exact)| {
            let size = match &descr[1..] {
                "f8" => 8,
                "f4" | "i4" => 4,
                "u2" => 2,
                _ => 1,
            };
            let stated = shape.iter().try_fold(1u64, |a, &d| a.checked_mul(d)).filter(|&c| c <= 150);
            let body = match (exact, stated) {
                (true, Some(c)) => c as usize * size,
                _ => body,
            };
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
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(base.path().join("capture.json")).unwrap()).unwrap();
    // Without its file records (a folder from another tool), so a corrupted frame reaches
    // the frame readers; "files" is among the fields mutated below.
    json.as_object_mut().unwrap().remove("files");
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
        "files",
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
                    prop_assert!(c.held_frames().unwrap().iter().all(|f| f.len() == rows * cols));
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

/// A number as a flag value: mostly small and plausible, sometimes anything a user could
/// type (huge, negative, zero, not finite, not a number).
fn flag_number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (0u32..40).prop_map(|n| n.to_string()),
        2 => (-2.0f64..3.0).prop_map(|x| format!("{x}")),
        1 => any::<f64>().prop_map(|x| format!("{x:e}")),
        1 => any::<u64>().prop_map(|n| n.to_string()),
        1 => prop::sample::select(vec!["0", "-1", "1e30", "1e-30", "inf", "-inf", "NaN", "", "x", "1,2"])
            .prop_map(String::from),
    ]
}

/// A table field: one of `valid` nine times in ten, else one of `invalid`.
fn field(valid: &[&'static str], invalid: &[&'static str]) -> impl Strategy<Value = &'static str> {
    prop_oneof![9 => prop::sample::select(valid.to_vec()), 1 => prop::sample::select(invalid.to_vec())]
}

/// `A,B` or `A,B,C,D` of flag numbers (sizes, windows, crops).
fn flag_list(n: usize) -> impl Strategy<Value = String> {
    prop::collection::vec(flag_number(), n).prop_map(|v| v.join(","))
}

/// A folder of 9 x 9 views of 8 x 8 pixels in both namings, and an `(8, 8, 31)` cube.
fn import_inputs() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let views = dir.path().join("views");
    std::fs::create_dir(&views).unwrap();
    for r in 0..9u8 {
        for c in 0..9u8 {
            let img = image::RgbImage::from_fn(8, 8, |x, y| image::Rgb([20 * r, 20 * c, (8 * x + y) as u8]));
            img.save(views.join(format!("input_Cam{:03}.png", u32::from(r) * 9 + u32::from(c)))).unwrap();
            img.save(views.join(format!("lf_{:02}_{:02}.png", r + 1, c + 1))).unwrap();
        }
    }
    // The same views with one of the default window's missing, for --fill warp.
    let missing = dir.path().join("views-missing");
    std::fs::create_dir(&missing).unwrap();
    for entry in std::fs::read_dir(&views).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        if name != "input_Cam020.png" && name != "lf_03_03.png" {
            std::fs::copy(entry.path(), missing.join(name)).unwrap();
        }
    }
    let body: Vec<u8> = (0..8 * 8 * 31).flat_map(|i| (0.2 + (i % 7) as f32 * 0.1).to_le_bytes()).collect();
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (8, 8, 31), }";
    std::fs::write(dir.path().join("cube.npy"), npy_bytes(1, header, &body)).unwrap();
    dir
}

/// Imports that succeeded.
static IMPORTED: AtomicU32 = AtomicU32::new(0);

/// `slf import views` and `slf import cube` with any values of their options (issue 32's
/// sizes, wavelengths and indices among them): a light field of the sizes asked for, within
/// the size cap, or one error line; never a panic or an allocation the cap forbids.
#[test]
fn fuzz_import_options() {
    use slf_host::io::lightfield::LightField;
    use slf_host::sim::import::{CubeSettings, ViewsSettings};
    let inputs = import_inputs();
    let folder = inputs.path().join("views").display().to_string();
    let missing = inputs.path().join("views-missing").display().to_string();
    let cube = inputs.path().join("cube.npy").display().to_string();
    let check = |result: anyhow::Result<slf_host::io::import::views::Imported>| -> Result<(), TestCaseError> {
        match result {
            Ok(i) => {
                IMPORTED.fetch_add(1, Ordering::Relaxed);
                let lf = &i.lightfield;
                prop_assert_eq!(lf.data.len(), lf.shape().iter().product::<usize>());
                prop_assert!(lf.data.len() <= LightField::MAX_VALUES);
                prop_assert!(lf.data.iter().all(|v| v.is_finite()));
            }
            Err(e) => {
                let text = format!("{e:#}");
                prop_assert_eq!(text.lines().count(), 1, "not one line: {}", text);
            }
        }
        Ok(())
    };
    // A parser's refusal is one line; what it accepts imports or fails as `check` says.
    let parsed = |r: Result<anyhow::Result<slf_host::io::import::views::Imported>, String>| match r {
        Ok(imported) => check(imported),
        Err(e) => {
            prop_assert_eq!(e.lines().count(), 1, "not one line: {}", e);
            Ok(())
        }
    };
    let option = |name: &'static str, value: BoxedStrategy<String>| {
        prop::option::weighted(0.4, value.prop_map(move |v| vec![format!("--{name}={v}")]))
    };
    let views = (
        option("views", flag_list(2).boxed()),
        option("grid", flag_list(2).boxed()),
        option("start", flag_list(2).boxed()),
        option("crop", flag_list(4).boxed()),
        option("resize", flag_list(2).boxed()),
        option("index-base", flag_number().boxed()),
        any::<bool>(),
        // Filling a missing view (issue 41: --max-disparity 1e9 asked for 17 GB).
        option("fill", prop::sample::select(vec!["warp", "none", "x"]).prop_map(String::from).boxed()),
        option("max-disparity", flag_number().boxed()),
        any::<bool>(),
    );
    runner()
        .run(&views, |(a, b, c, d, e, f, pattern, g, h, one_missing)| {
            let mut flags = vec![if one_missing { missing.clone() } else { folder.clone() }];
            if pattern {
                flags.push("--pattern=lf_{row:02}_{col:02}.png".into());
            }
            flags.extend([a, b, c, d, e, f, g, h].into_iter().flatten().flatten());
            parsed(ViewsSettings::from_flags(&flags).map(|s| s.run()))
        })
        .unwrap();
    let wavelengths = prop_oneof![
        (flag_number(), flag_number(), flag_number()).prop_map(|(a, b, c)| format!("{a}:{b}:{c}")),
        flag_list(31),
        Just("400:700:10".to_string()),
    ];
    let cubes = (
        option("wavelengths", wavelengths.boxed()),
        option("views", flag_list(2).boxed()),
        option("disparity", flag_number().boxed()),
        option("white", flag_number().boxed()),
        option("crop", flag_list(4).boxed()),
        option("resize", flag_list(2).boxed()),
    );
    runner()
        .run(&cubes, |(a, b, c, d, e, f)| {
            let mut flags = vec![cube.clone()];
            flags.extend([a, b, c, d, e, f].into_iter().flatten().flatten());
            parsed(CubeSettings::from_flags(&flags).map(|s| s.run()))
        })
        .unwrap();
    let imported = IMPORTED.load(Ordering::Relaxed);
    eprintln!("fuzz import options: {} cases x 2 commands ({imported} imported), no failure", cases());
    assert!(imported > 0, "the generators must reach a successful import");
}

/// Decodes that ran.
static DECODED: AtomicU32 = AtomicU32::new(0);

/// `slf decode`'s solver, noise and gain flags with any values (issue 32, item 4): refused
/// in one line naming the flag, or accepted with every value within the ranges the help
/// states, and then decoded to finite values in the sensor's physical range.
#[test]
fn fuzz_decode_flag_ranges() {
    use slf_host::decode::settings::DecodeSettings;
    let lf = slf_host::sim::scene::named("texture").unwrap().render(slf_host::sim::scene::SceneSize {
        views: (5, 5),
        rows: 5,
        cols: 5,
    });
    let cap = simulate(&lf, &CameraConfig::pixel(3, 1)).unwrap();
    let (lo, hi) = cap.raw_format().range();
    let names = vec![
        "mu",
        "sigma-min",
        "tolerance",
        "noise",
        "shot",
        "flat",
        "sigma-f",
        "steps",
        "max-iterations",
        "warm-start",
        "warm-sigma-f",
        "warm-steps",
        "seed-sigma-f",
        "cold-start",
        "min-bands",
        "gains",
    ];
    let flag = (prop::sample::select(names), flag_number(), flag_list(13));
    runner()
        .run(&prop::collection::vec(flag, 1..4), |flags| {
            let args: Vec<String> = flags
                .iter()
                .map(|(name, one, thirteen)| format!("--{name}={}", if *name == "gains" { thirteen } else { one }))
                .chain(["--stride=5".to_string(), "--dictionary=dct".to_string()])
                .collect();
            let settings = match DecodeSettings::from_flags(&args) {
                Ok(s) => s,
                Err(e) => {
                    prop_assert_eq!(e.lines().count(), 1, "not one line: {}", e);
                    return Ok(());
                }
            };
            let (_, o) = match settings.resolve() {
                Ok(r) => r,
                Err(e) => {
                    let text = e.to_string();
                    prop_assert!(text.starts_with("--") && text.lines().count() == 1, "{:?}: {}", args, text);
                    return Ok(());
                }
            };
            let c = o.sl0;
            prop_assert!(c.mu > 0.0 && c.mu <= 2.0, "{:?}", args);
            prop_assert!(c.sigma_min > 0.0 && c.sigma_min <= 1.0, "{:?}", args);
            prop_assert!(c.seed_sigma_f > 0.0 && c.seed_sigma_f < 1.0, "{:?}", args);
            for v in [c.tolerance, c.noise, c.shot, c.flat] {
                prop_assert!((0.0..=1.0).contains(&v), "{:?}", args);
            }
            let Ok(decoded) = settings.run(&cap, false, &|_, _| {}) else { return Ok(()) };
            DECODED.fetch_add(1, Ordering::Relaxed);
            let data = &decoded.light_field.data;
            prop_assert!(data.iter().all(|v| (lo..=hi).contains(v)), "{:?}: outside the physical range", args);
            Ok(())
        })
        .unwrap();
    let decoded = DECODED.load(Ordering::Relaxed);
    eprintln!("fuzz decode flag ranges: {} cases ({decoded} decoded), no failure", cases());
    assert!(decoded > 0, "the generator must reach a decode");
}

/// Frames read as a capture's (its frame size known).
static FRAMES: AtomicU32 = AtomicU32::new(0);

/// Frame files whose headers state any size, the file as long as the header claims (sparse)
/// or not: a frame is read only at the capture's size, and a header that claims another is
/// refused before its pixels are allocated (issue 41: 65535 x 65535 PGMs and `.npy` frames,
/// a small PNG claiming 15000 x 15000).
#[test]
fn fuzz_frame_headers() {
    use slf_host::io::frame_file::read_frame;
    let dir = tempfile::tempdir().unwrap();
    let expect = (10usize, 15usize);
    let size = |right: u32| prop_oneof![3 => Just(right), 4 => 0u32..20, 2 => 0u32..70_000, 1 => any::<u32>()];
    let inputs = (prop::sample::select(vec!["pgm", "npy", "png"]), size(15), size(10), 0u32..3, any::<bool>());
    runner()
        .run(&inputs, |(ext, w, h, depth, sparse)| {
            let path = dir.path().join(format!("f.{ext}"));
            let (header, body): (Vec<u8>, u64) = match ext {
                "pgm" => {
                    let top = [255u32, 4095, 65535][depth as usize];
                    let per = if top > 255 { 2 } else { 1 };
                    (format!("P5\n{w} {h}\n{top}\n").into_bytes(), (per * u64::from(w)).saturating_mul(u64::from(h)))
                }
                "npy" => {
                    let h = format!("{{'descr': '<u2', 'fortran_order': False, 'shape': ({h}, {w}), }}");
                    (npy_bytes(1, &h, &[]), (2 * u64::from(w)).saturating_mul(u64::from(h_of(&h))))
                }
                _ => (png_claiming(w, h), 0),
            };
            let file = std::fs::File::create(&path).unwrap();
            std::io::Write::write_all(&mut &file, &header).unwrap();
            // A sparse body of the claimed length (or a short one): no disk is used.
            let len = header.len() as u64 + if sparse { body.min(1 << 40) } else { body.min(64) };
            file.set_len(len).unwrap();
            match read_frame(&path, Some(expect)) {
                Ok(f) => {
                    FRAMES.fetch_add(1, Ordering::Relaxed);
                    prop_assert_eq!((f.rows, f.cols), expect);
                    prop_assert_eq!(f.data.len(), expect.0 * expect.1);
                }
                Err(e) => {
                    let text = format!("{e:#}");
                    prop_assert!(!text.contains('\n'), "not one line: {}", text);
                    prop_assert!(text.contains("f."), "names no file: {}", text);
                }
            }
            Ok(())
        })
        .unwrap();
    eprintln!("fuzz frame headers: {} cases ({} read), no failure", cases(), FRAMES.load(Ordering::Relaxed));
    assert!(FRAMES.load(Ordering::Relaxed) > 0, "the generator must reach a frame of the capture's size");
}

/// The rows the `.npy` header in `h` states (its shape's first number).
fn h_of(h: &str) -> u32 {
    h.split("'shape': (").nth(1).and_then(|r| r.split(',').next()).and_then(|n| n.trim().parse().ok()).unwrap_or(0)
}

/// Bench tables read and drawn again.
static DRAWN: AtomicU32 = AtomicU32::new(0);

/// `slf bench --from` on tables of any rows (times of 0, NaN, negative, huge; no rows;
/// short rows): a table is read only with values in the ranges a decode gives (PSNR within
/// +-1000 dB, SSIM [-1, 1], SA [0, 180], times 1e-9..1e12 ms), and what is read is drawn at
/// once (issue 41: an empty table aborted, a time of 0 or a NaN ran past a
/// minute).
#[test]
fn fuzz_bench_inputs() {
    use slf_host::eval::bench::{read_points, write};
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let header = "mask,k,setting,psnr_db,ssim,sa_deg,ms_per_patch_1_thread,ms_per_patch_all_threads,\
                  solves_per_patch,frame_512_s_1_thread,pareto";
    let row = (
        prop::sample::select(vec!["pixel", "lenslet", "kronecker", ""]),
        field(&["1", "3", "0"], &["x", "300"]),
        // Each field from values in its range and out of it (issue 51: +-1.7e308 dB and
        // times of 1e-200 and 1e200 ms once held the plot for minutes).
        (
            field(&["30", "0", "-1000", "1000"], &["-1.7e308", "1.7e308", "NaN", "x"]),
            field(&["0.9", "-1", "1"], &["1.5", "inf"]),
            field(&["4", "0", "180"], &["200", "-1"]),
            field(&["1", "1e-9", "1e12"], &["0", "1e-200", "1e200", "-2"]),
            field(&["0.5"], &["0", "NaN"]),
            field(&["1", "0"], &["-1", "2e9"]),
            field(&["2", "0"], &["1e300", "-1"]),
        ),
        any::<bool>(),
    )
        .prop_map(|(mask, k, (p, s, a, t1, t2, n, f), pareto)| {
            format!("{mask},{k},a setting,{p},{s},{a},{t1},{t2},{n},{f},{pareto}")
        });
    let table = prop::collection::vec(row, 0..6);
    let drawn_at_most = 25; // drawing is 50 ms a table: a few suffice
    runner()
        .run(&table, |rows| {
            let text = std::iter::once(header.to_string()).chain(rows).collect::<Vec<_>>().join("\n") + "\n";
            std::fs::write(&csv, text).unwrap();
            match read_points(&csv) {
                Ok(points) => {
                    prop_assert!(!points.is_empty());
                    for p in &points {
                        prop_assert!((1e-9..=1e12).contains(&p.ms_one) && (-1000.0..=1000.0).contains(&p.psnr));
                        prop_assert!((-1.0..=1.0).contains(&p.ssim) && (0.0..=180.0).contains(&p.sa));
                    }
                    if DRAWN.fetch_add(1, Ordering::Relaxed) < drawn_at_most {
                        let out = dir.path().join("out");
                        let start = std::time::Instant::now();
                        write(&points, &[], &out).map_err(|e| TestCaseError::fail(format!("{e:#}")))?;
                        prop_assert!(start.elapsed().as_secs() < 20, "drawing took {:?}", start.elapsed());
                    }
                }
                Err(e) => {
                    let text = format!("{e:#}");
                    prop_assert!(!text.contains('\n'), "not one line: {}", text);
                }
            }
            Ok(())
        })
        .unwrap();
    eprintln!("fuzz bench inputs: {} cases ({} read), no failure", cases(), DRAWN.load(Ordering::Relaxed));
    assert!(DRAWN.load(Ordering::Relaxed) > 0, "the generator must reach a table that reads");
}
