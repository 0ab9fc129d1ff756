//! The streamed decode (issue 50): a frame decoded down its rows in batches is the same bit
//! for bit whatever the batches (one tile at a time, or the whole frame at once), and the
//! rows it holds are bounded by the tiles' height, not the frame's.

use slf_host::decode::cs::{Basis, DecodeOptions, DecodeReport, Window, decode_with};
use slf_host::firmware::DisparityRange;
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::flags::FromFlags;
use slf_host::sim::scene::{SceneSize, named};

/// The depth scene (its blocks sheared, so tiles reach past their rows) at `rows x 16`
/// lenslets, pixel mask, one snapshot.
fn capture(rows: usize) -> Capture {
    let truth = named("depth").unwrap().render(SceneSize { views: (5, 5), rows, cols: 16 });
    simulate(&truth, &CameraConfig::pixel(5, 1)).unwrap()
}

/// The decode with `batch_tiles`, its report without the wall time and without what the
/// batch sets by design (the rows held, and the strip's allocation for them).
fn decode(capture: &Capture, opts: &DecodeOptions, batch_tiles: usize) -> (LightField, DecodeReport) {
    let (lf, mut report) = decode_with(capture, &Basis::Dct, &DecodeOptions { batch_tiles, ..*opts }).unwrap();
    report.seconds = 0.0;
    report.rows_held = 0;
    report.strip_bytes = 0;
    report.seed_rows = 0;
    (lf, report)
}

/// Every way the strip decodes: seeded shifted grids at stride 2 (the default's), with
/// whole and half-pixel shears; unseeded at stride 3; the adaptive rule; the disjoint grid with the
/// sheared fallback (the preview's); an unsheared frame.
fn settings() -> Vec<(&'static str, DecodeOptions)> {
    let base = DecodeOptions {
        disparities: Some(DisparityRange::new(-1, 1).unwrap().with_halves(true)),
        ..DecodeOptions::default()
    };
    vec![
        ("stride 2 seeded", base),
        ("stride 3 unseeded", DecodeOptions { stride: (3, 3), seeded: false, ..base }),
        ("adaptive 1.1", DecodeOptions { adaptive: Some(1.1), ..base }),
        (
            "disjoint, sheared fallback",
            DecodeOptions { stride: (5, 5), window: Window::Uniform, sheared_fallback: true, ..base },
        ),
        ("unsheared", DecodeOptions { disparities: Some(DisparityRange::OFF), ..base }),
    ]
}

#[test]
fn a_streamed_decode_is_the_same_bit_for_bit_whatever_its_batches() {
    // 23 rows: four rows of tiles and the end-aligned edge strip.
    let capture = capture(23);
    for (name, opts) in settings() {
        let (whole, whole_report) = decode(&capture, &opts, usize::MAX);
        assert!(whole_report.patches.decoded > 0, "{name}: nothing decoded");
        for batch in [1, 3] {
            let (streamed, report) = decode(&capture, &opts, batch);
            assert!(whole.data == streamed.data, "{name}: batches of {batch} differ from the whole frame's");
            assert_eq!(report, whole_report, "{name}: batches of {batch}");
        }
    }
}

#[test]
fn the_rows_a_streamed_decode_holds_do_not_grow_with_the_frame() {
    let held = |rows: usize, opts: &DecodeOptions| {
        let (_, report) = decode_with(&capture(rows), &Basis::Dct, &DecodeOptions { batch_tiles: 1, ..*opts }).unwrap();
        (report.rows_held, report.strip_bytes)
    };
    for (name, opts) in settings() {
        let ((short, short_bytes), (tall, tall_bytes)) = (held(60, &opts), held(120, &opts));
        // A tile is 10 lenslet rows; a shifted one waits for the disjoint tiles below it,
        // and a sheared patch reaches a halo of rows beyond its tile.
        assert!(short == tall && tall <= 30, "{name}: {short} rows held at 60 rows, {tall} at 120");
        // The strip's allocation (sums and seeds) is as bounded as its rows.
        assert!(
            short_bytes == tall_bytes && tall_bytes > 0,
            "{name}: {short_bytes} B at 60 rows, {tall_bytes} B at 120"
        );
    }
    // The whole frame at once holds every row.
    let (_, report) =
        decode_with(&capture(60), &Basis::Dct, &DecodeOptions { batch_tiles: usize::MAX, ..settings()[0].1 }).unwrap();
    assert_eq!(report.rows_held, 60);
}

/// `slf decode CAP -o OUT -q FLAGS`, its output.
fn slf_decode(cap: &std::path::Path, out: &std::path::Path, flags: &[&str]) -> std::process::Output {
    assert_cmd::Command::cargo_bin("slf")
        .unwrap()
        .arg("decode")
        .arg(cap)
        .arg("-o")
        .arg(out)
        .arg("-q")
        .args(flags)
        .output()
        .unwrap()
}

/// `slf decode -o OUT.npy` writes its rows as they are decoded: the file is the light field
/// the library decodes into memory with the same flags, value for value: compressed sensing
/// streamed by the strip, and a baseline decoded whole and put row by row.
#[test]
fn the_decode_written_as_it_goes_is_the_decode_in_memory() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::io::lightfield::read_npy;
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    let capture = capture(23);
    capture.save(&cap).unwrap();
    for flags in [&["--preset", "default"][..], &["--preset", "preview"], &["--method", "ppid"]] {
        let out = dir.path().join("out.npy");
        let run = assert_cmd::Command::cargo_bin("slf")
            .unwrap()
            .arg("decode")
            .arg(&cap)
            .arg("-o")
            .arg(&out)
            .arg("-q")
            .args(flags)
            .output()
            .unwrap();
        assert!(run.status.success(), "{flags:?}: {}", String::from_utf8_lossy(&run.stderr));
        let settings = DecodeSettings::from_flags(flags.iter().copied()).unwrap();
        let want = settings.run(&Capture::load(&cap).unwrap(), false, &|_, _| {}).unwrap().light_field;
        let got = read_npy(&out).unwrap();
        assert!(got == want, "{flags:?}: the file differs from the decode in memory");
    }
}

/// An interrupted decode (Ctrl-C) stops at its next row with an error and leaves nothing:
/// no output file, no temporary file beside it, an old output as it was.
#[cfg(unix)]
#[test]
fn an_interrupted_decode_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    capture(60).save(&cap).unwrap();
    let out = dir.path().join("out.npy");
    std::fs::write(&out, b"the old output").unwrap();
    let entries = || -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("slf"))
        .arg("decode")
        .arg(&cap)
        .arg("-o")
        .arg(&out)
        .args(["-q", "--preset", "best"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The temporary file appears before the decode starts; interrupt then.
    let start = std::time::Instant::now();
    while !entries().iter().any(|n| n.ends_with(".part")) {
        assert!(start.elapsed().as_secs() < 60, "no temporary file: {:?}", entries());
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let killed = std::process::Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(killed.success());
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success() && err.contains("interrupted"), "{status:?}: {err}");
    assert_eq!(entries(), ["cap", "out.npy"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"the old output");
}

/// `slf decode -o OUT.h5`: the same light field as the `.npy`, read back by `slf import
/// hdf5`'s reader bit for bit, compressed or not; the flags of one format refused with the
/// other.
#[test]
fn the_decode_written_to_hdf5_is_the_decode_written_to_npy() {
    use slf_host::io::hdf5_rows::{AXES, DATASET};
    use slf_host::io::import::hdf5::{Hdf5Layout, read_hdf5};
    use slf_host::io::lightfield::read_npy;
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    capture(23).save(&cap).unwrap();
    let decode = |out: &std::path::Path, flags: &[&str]| slf_decode(&cap, out, flags);
    let npy = dir.path().join("lf.npy");
    assert!(decode(&npy, &["--preset", "preview"]).status.success());
    let want = read_npy(&npy).unwrap();
    let layout = Hdf5Layout { dataset: DATASET.into(), axes: AXES.into() };
    for (name, flags) in [("lf.h5", &[][..]), ("lf.hdf5", &["--deflate", "6"]), ("lf.data", &["--format", "hdf5"])] {
        let out = dir.path().join(name);
        let run = decode(&out, &[&["--preset", "preview"][..], flags].concat());
        assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
        assert!(read_hdf5(&out, &layout, 1.0).unwrap() == want, "{name} {flags:?}: differs from the .npy");
    }
    for (name, flags, says) in
        [("x.npy", &["--deflate", "4"][..], "--deflate"), ("x.h5", &["--dtype", "u16"], "--dtype u16")]
    {
        let run = decode(&dir.path().join(name), flags);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success() && err.contains(says), "{name} {flags:?}: {err}");
        assert!(!dir.path().join(name).exists());
    }
}

/// `slf decode -o OUT.zarr` (issue 65, item 4): the Zarr v3 store's `lightfield` array, read
/// back by `zarrs`, is the `.npy` decode value for value, compressed or not, with its
/// dimension names, chunks of 8 lenslet rows, the band centres as the `band` array and the
/// capture's description in the group's attributes. A second decode replaces the store
/// whole; a folder holding anything else is refused and left as it was.
#[test]
fn the_decode_written_to_zarr_is_the_decode_written_to_npy() {
    use slf_host::io::lightfield::read_npy;
    use zarrs::array::Array;
    use zarrs::filesystem::FilesystemStore;
    let dir = tempfile::tempdir().unwrap();
    let cap = dir.path().join("cap");
    let captured = capture(23);
    captured.save(&cap).unwrap();
    let decode =
        |out: &std::path::Path, flags: &[&str]| slf_decode(&cap, out, &[&["--preset", "preview"], flags].concat());
    let npy = dir.path().join("lf.npy");
    assert!(decode(&npy, &[]).status.success());
    let want = read_npy(&npy).unwrap();
    for (name, flags) in [("lf.zarr", &[][..]), ("gz.zarr", &["--deflate", "5"]), ("lf.store", &["--format", "zarr"])] {
        let out = dir.path().join(name);
        // Twice: the second replaces the first's store.
        for _ in 0..2 {
            let run = decode(&out, flags);
            assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
        }
        let store = std::sync::Arc::new(FilesystemStore::new(&out).unwrap());
        let array = Array::open(store.clone(), "/lightfield").unwrap();
        let shape: Vec<u64> = want.shape().iter().map(|&d| d as u64).collect();
        assert_eq!(array.shape(), shape.as_slice());
        let all: Vec<std::ops::Range<u64>> = shape.iter().map(|&d| 0..d).collect();
        let got: Vec<f32> = array.retrieve_array_subset(&all).unwrap();
        assert!(got == want.data, "{name} {flags:?}: differs from the .npy");
        let meta = serde_json::to_value(array.metadata()).unwrap();
        assert_eq!(meta["dimension_names"], serde_json::json!(["u", "v", "h", "w", "band"]), "{name}");
        assert_eq!(meta["chunk_grid"]["configuration"]["chunk_shape"][2], 8, "{name}");
        assert_eq!(flags.contains(&"--deflate"), meta["codecs"].to_string().contains("gzip"), "{name}");
        let band = Array::open(store.clone(), "/band").unwrap();
        let nm: Vec<f32> = band.retrieve_chunk(&[0]).unwrap();
        assert_eq!(nm, captured.description.bands_nm);
        let group = zarrs::group::Group::open(store, "/").unwrap();
        let attrs = group.attributes();
        let text = serde_json::to_string(&captured.description).unwrap();
        assert_eq!(attrs["description"], serde_json::from_str::<serde_json::Value>(&text).unwrap());
        assert!(attrs["command"].as_str().unwrap().contains("decode") && attrs["settings"].is_string());
    }
    // A folder of the user's is never replaced.
    let theirs = dir.path().join("theirs.zarr");
    std::fs::create_dir(&theirs).unwrap();
    std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
    let run = decode(&theirs, &[]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("notes.txt"), "{err}");
    assert_eq!(std::fs::read_to_string(theirs.join("notes.txt")).unwrap(), "mine");
    let run = decode(&dir.path().join("x.zarr"), &["--dtype", "u16"]);
    assert!(!run.status.success() && String::from_utf8_lossy(&run.stderr).contains("--dtype u16"));
    // Nothing the run reads or writes may lie inside the store it replaces whole.
    let store = dir.path().join("lf.zarr");
    for (out, flags, says) in [
        (cap.clone(), vec!["--format", "zarr"], "holds a file of the capture"),
        (store.clone(), vec!["--member-map", "lf.zarr/m.csv"], "is inside -o"),
    ] {
        let flags: Vec<String> = flags.iter().map(|f| f.replace("lf.zarr", &store.display().to_string())).collect();
        let flags: Vec<&str> = flags.iter().map(String::as_str).collect();
        let run = decode(&out, &flags);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success() && err.contains(says), "{flags:?}: {err}");
    }
    assert!(cap.join("capture.json").is_file() && store.join("zarr.json").is_file());
}
