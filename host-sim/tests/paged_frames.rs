//! Raw frames read a band of rows at a time (issue 65, item 3): a capture loaded from `.npy`
//! frames is read from its files as the decode goes down the frame, and every method decodes
//! it to the same bits as the frames held in memory, with the cache of the size the decode
//! picks and with one so small (two bands of three rows) that every pass evicts.

use std::path::Path;
use std::process::Command;

use slf_host::decode::baselines::{DemosaicConfig, PpidConfig, demosaic, interpolate, ppid};
use slf_host::decode::cs::{Basis, DecodeOptions, decode_with};
use slf_host::firmware::DisparityRange;
use slf_host::io::capture::Capture;
use slf_host::io::frames::Frames;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{SceneSize, named};

/// The depth scene at 17 x 13 lenslets, pixel mask, `k` snapshots, saved as `.npy` frames and
/// loaded back: (held, paged).
fn captures(dir: &Path, k: u8) -> (Capture, Capture) {
    captures_as(dir, k, "npy")
}

/// As [`captures`], the frames saved as `ext`.
fn captures_as(dir: &Path, k: u8, ext: &str) -> (Capture, Capture) {
    let truth = named("depth").unwrap().render(SceneSize { views: (5, 5), rows: 17, cols: 13 });
    let cam = CameraConfig { frame_ext: ext.into(), ..CameraConfig::pixel(5, k) };
    let held = simulate(&truth, &cam).unwrap();
    held.save(dir).unwrap();
    let paged = Capture::load_paged(dir).unwrap();
    assert!(paged.frames.is_paged(), "a capture of .{ext} frames is read as the decode asks");
    assert!(!held.frames.is_paged());
    (held, paged)
}

/// `capture` with a cache of two bands of three rows per frame (every pass evicts).
fn starved(capture: &Capture) -> Capture {
    let Frames::Paged(frames) = &capture.frames else { panic!("not paged") };
    let small = Frames::Paged(frames.iter().map(|f| f.with_cache(3, 2)).collect());
    Capture::with_frames(capture.description.clone(), small).unwrap()
}

#[test]
fn a_paged_capture_decodes_to_the_held_ones_bits_by_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let (held, paged) = captures(dir.path(), 2);
    let small = starved(&paged);
    let opts = DecodeOptions {
        disparities: Some(DisparityRange::new(-1, 1).unwrap().with_halves(true)),
        error_estimate: true,
        ..DecodeOptions::default()
    };
    let (want, want_report) = decode_with(&held, &Basis::Dct, &opts).unwrap();
    assert!(want_report.patches.decoded > 0);
    for (name, cap) in [("paged", &paged), ("two bands of three rows", &small)] {
        let (got, report) = decode_with(cap, &Basis::Dct, &opts).unwrap();
        assert!(got.data == want.data, "{name}: the decode differs from the held frames'");
        assert_eq!(report.patches, want_report.patches, "{name}");
        let (e, w) = (&report.error_lenslets, &want_report.error_lenslets);
        assert!(e.len() == w.len() && e.iter().zip(w).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: error map");
        assert!(cap.frames.read_error().is_ok());
        assert!(cap.frames.loads() > 0, "{name}: read from the files");
        assert_eq!(interpolate(cap).unwrap().0.data, interpolate(&held).unwrap().0.data, "{name}: interpolate");
        let d = DemosaicConfig::default();
        assert_eq!(demosaic(cap, &d).unwrap().0.data, demosaic(&held, &d).unwrap().0.data, "{name}: demosaic");
        let p = PpidConfig::default();
        assert_eq!(ppid(cap, &p).unwrap().0.data, ppid(&held, &p).unwrap().0.data, "{name}: ppid");
    }
    // The decode's own cache holds the frame here (17 x 5 rows): each band is read once.
    let once = Capture::load_paged(dir.path()).unwrap();
    decode_with(&once, &Basis::Dct, &opts).unwrap();
    let bands = 2 * (17 * 5usize).div_ceil(slf_host::io::paged_frame::MIN_BAND_ROWS);
    assert!(once.frames.loads() as usize <= bands, "{} band reads for {bands} bands", once.frames.loads());
}

/// PNG frames are paged too (one decoder going down each file, started again for a band
/// above it): the default decode with its error estimate and PPID read them to the held
/// frames' bits, with the decode's cache and with two bands of three rows (every pass
/// starts the decoders again).
#[test]
fn png_frames_are_paged_and_decode_to_the_held_bits() {
    let dir = tempfile::tempdir().unwrap();
    let (held, paged) = captures_as(dir.path(), 2, "png");
    let opts = DecodeOptions { error_estimate: true, ..DecodeOptions::default() };
    let (want, want_report) = decode_with(&held, &Basis::Dct, &opts).unwrap();
    for (name, cap) in [("paged", &paged), ("two bands of three rows", &starved(&paged))] {
        let (got, report) = decode_with(cap, &Basis::Dct, &opts).unwrap();
        assert!(got.data == want.data, "{name}: the decode differs from the held frames'");
        assert_eq!(report.patches, want_report.patches, "{name}");
        assert!(cap.frames.read_error().is_ok() && cap.frames.loads() > 0, "{name}");
        let p = PpidConfig::default();
        assert_eq!(ppid(cap, &p).unwrap().0.data, ppid(&held, &p).unwrap().0.data, "{name}: ppid");
    }
}

/// A frame file cut short during the decode: the decode fails and names the file; it is not
/// passed off as flagged pixels.
#[test]
fn a_frame_cut_short_after_loading_fails_the_decode() {
    let dir = tempfile::tempdir().unwrap();
    let (_, paged) = captures(dir.path(), 1);
    let small = starved(&paged);
    std::fs::File::options().write(true).open(dir.path().join("snapshot_0.npy")).unwrap().set_len(4000).unwrap();
    let decoded = decode_with(&small, &Basis::Dct, &DecodeOptions::default());
    let e = small.frames.read_error().expect_err("the read failed");
    assert!(e.to_string().contains("snapshot_0.npy"), "{e}");
    // The streamed decode reads the frame as it goes: either it stopped, or it flagged and
    // the error is there for the caller (the pipeline refuses the output then).
    if let Ok((_, report)) = decoded {
        assert!(report.patches.flagged + report.patches.failed > 0);
    }
    let e = demosaic(&small, &DemosaicConfig::default()).unwrap_err().to_string();
    assert!(e.contains("snapshot_0.npy") || e.contains("cannot read row"), "{e}");
}

/// Through the command line: a capture of `.npy` frames and the same capture in PGM and in
/// PNG (small: held, the PNG read through its row reader) decode to the same bytes, by the default decode and by PPID; and a frame cut short
/// after `slf decode` checked it is an error, not an output.
#[test]
fn the_command_line_decodes_paged_and_held_frames_alike() {
    let slf = env!("CARGO_BIN_EXE_slf");
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let run = |args: &[&str]| {
        let out = Command::new(slf).args(args).current_dir(dir.path()).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    run(&["scene", "depth", "--size", "14", "-o", "lf.npy"]);
    for f in ["npy", "pgm", "png"] {
        run(&["simulate", "lf.npy", "-o", &format!("cap-{f}"), "-s", "2", "--seed", "3", "--format", f]);
    }
    for method in ["cs", "ppid"] {
        for f in ["npy", "pgm", "png"] {
            run(&["decode", &format!("cap-{f}"), "-q", "--method", method, "-o", &format!("{method}-{f}.npy")]);
        }
        let a = std::fs::read(p(&format!("{method}-npy.npy"))).unwrap();
        for f in ["pgm", "png"] {
            let b = std::fs::read(p(&format!("{method}-{f}.npy"))).unwrap();
            assert!(a == b, "{method}: the {f} capture's output differs from the .npy one's");
        }
    }
}

/// The calibration's correction inside the reader, and the aligned reading's crop: a paged
/// capture stays paged through both, and reads what the slow obvious whole-frame
/// correction and crop give (the formula in the calibration's docs, on the maps read
/// whole); a calibrated decode, and one read as aligned, of the paged capture is the held
/// one's to the bit.
#[test]
fn the_correction_and_the_aligned_crop_are_read_as_the_decode_asks() {
    use slf_host::decode::calibrate::calibrate;
    use slf_host::decode::correction::corrected;
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::io::calibration::Calibration;
    use slf_host::io::sensor::SensorDescription;
    use slf_host::sim::calibration::calibration_captures;
    use slf_host::sim::camera::GridSettings;
    use slf_host::sim::flags::FromFlags;

    let dir = tempfile::tempdir().unwrap();
    let (lenslets, views) = ([70usize, 13usize], [5usize, 5usize]);
    let truth = named("depth").unwrap().render(SceneSize { views: (5, 5), rows: lenslets[0], cols: lenslets[1] });
    let mut cam = CameraConfig { frame_ext: "npy".into(), ..CameraConfig::pixel(5, 2) };
    cam.sensor = SensorDescription { vignetting: 0.5, prnu: 0.02, hot_fraction: 0.003, seed: 3, ..cam.sensor };
    cam.grid = Some(GridSettings { rotation_deg: 0.0, pitch: Some([5.04, 5.04]), offset: None });
    let held = simulate(&truth, &cam).unwrap();
    let capture_dir = dir.path().join("cap");
    held.save(&capture_dir).unwrap();
    let paged = Capture::load_paged(&capture_dir).unwrap();
    assert!(paged.frames.is_paged());
    let caps = calibration_captures(&cam, lenslets, views, held.description.bands_nm.len(), 2).unwrap();
    let (cal, _) = calibrate(&caps, None).unwrap();
    let cal_dir = dir.path().join("cal");
    cal.save(&cal_dir).unwrap();
    let opened = Calibration::open(&cal_dir).unwrap();

    // The slow obvious correction, whole frames and whole maps.
    let (rows, cols) = held.frame_size();
    assert!(rows > slf_host::io::map::MAP_BAND_ROWS, "the maps are read in more than one band");
    let d = &held.description;
    let want: Vec<Vec<u16>> = held
        .held_frames()
        .unwrap()
        .iter()
        .map(|f| {
            (0..rows * cols)
                .map(|p| {
                    if f32::from(f[p]) >= d.saturation_level {
                        u16::MAX
                    } else {
                        let v = d.black_level + (f32::from(f[p]) - cal.dark[p]) / cal.flat[p].max(0.1);
                        v.round().clamp(0.0, 65534.0) as u16
                    }
                })
                .collect()
        })
        .collect();
    let dead = (0..rows * cols).filter(|&p| cal.flat[p] < 0.1).count();
    for (name, cap, c) in [("paged", &paged, &opened), ("held", &held, &cal.opened())] {
        let (fixed, _) = corrected(cap, c, true).unwrap();
        assert_eq!(fixed.frames.is_paged(), cap.frames.is_paged(), "{name}: corrected as it is read");
        assert!(fixed.held_frames().unwrap().as_ref() == want.as_slice(), "{name}: the corrected frames");
        let defects = &fixed.description.defective_pixels;
        assert!(cal.description.hot_pixels.iter().all(|p| defects.contains(p)), "{name}: hot pixels are defects");
        assert!(defects.len() >= cal.description.hot_pixels.len() + dead.min(1), "{name}: dead pixels are defects");
        // Read as aligned: the top-left S*U x T*V of every frame.
        let crop = fixed.aligned().unwrap();
        assert_eq!(crop.frames.is_paged(), cap.frames.is_paged(), "{name}: cropped as it is read");
        let (r, c) = (lenslets[0] * views[0], lenslets[1] * views[1]);
        let cropped: Vec<Vec<u16>> =
            want.iter().map(|f| (0..r * c).map(|p| f[(p / c) * cols + p % c]).collect()).collect();
        assert!(crop.held_frames().unwrap().as_ref() == cropped.as_slice(), "{name}: the aligned crop");
    }
    // Whole decodes through the CLI's settings: the paged capture's are the held one's bits.
    let at = cal_dir.display().to_string();
    for flags in [vec!["--calibration", at.as_str()], vec!["--calibration", &at, "--grid", "aligned"]] {
        let s = DecodeSettings::from_flags(flags.iter().copied()).unwrap();
        let run = |cap: &Capture| s.run(cap, false, &|_, _| {}).unwrap().light_field.data;
        assert!(run(&paged) == run(&held), "{flags:?}: the paged capture's decode differs");
    }
}
