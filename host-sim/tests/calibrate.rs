//! Calibration (issue 43, part 2): `slf calibrate`'s estimate from a simulated sensor's
//! calibration captures against the sensor that made them, within the tolerances
//! (the response matrix within 1 % per entry above 1 % of its row's peak, flats and
//! vignetting within 0.5 %); every hot pixel found; bad inputs refused in one line; the
//! calibration folder read back as written and refused when corrupt.

use slf_host::decode::calibrate::calibrate;
use slf_host::io::calibration::Calibration;
use slf_host::io::capture::{Capture, Light};
use slf_host::io::sensor::{FilterDescription, SensorDescription};
use slf_host::sim::calibration::calibration_captures;
use slf_host::sim::camera::CameraConfig;
use slf_host::sim::flags::FromFlags;
use slf_host::sim::sensor::{Sensor, response};
use slf_host::sim::spectra::BAND_NM;

const LENSLETS: [usize; 2] = [24, 24];
const VIEWS: [usize; 2] = [5, 5];

fn sensor(leakage: f32) -> SensorDescription {
    SensorDescription {
        filters: FilterDescription { leakage, ..FilterDescription::IDEAL },
        dark_sd_dn: 3.0,
        hot_fraction: 0.002,
        prnu: 0.01,
        vignetting: 0.5,
        seed: 21,
    }
}

fn camera(d: SensorDescription, k: u8) -> CameraConfig {
    let mut cam = CameraConfig::pixel(5, k);
    cam.sensor = d;
    cam
}

fn captures(d: SensorDescription, k: u8, exposures: usize) -> Vec<(String, Capture)> {
    calibration_captures(&camera(d, k), LENSLETS, VIEWS, BAND_NM.len(), exposures).unwrap()
}

#[test]
fn the_calibration_recovers_the_simulated_sensor() {
    for (leakage, k) in [(0.1f32, 1u8), (0.3, 3)] {
        let d = sensor(leakage);
        let caps = captures(d, k, 8);
        let (cal, report) = calibrate(&caps, None).unwrap();
        assert_eq!(report.lines.len(), 2);
        let desc = &caps[0].1.description;
        let range = desc.white_level - desc.black_level;
        let truth = Sensor::new(&d, LENSLETS, VIEWS, &BAND_NM, range, None).unwrap();
        let b = BAND_NM.len();

        // The response matrix, per entry above 1 % of its row's peak.
        let r = response(&d.filters, &BAND_NM).unwrap();
        let mut worst = 0.0f64;
        for f in 0..b {
            let peak = r[f * b..(f + 1) * b].iter().fold(0.0f64, |m, &x| m.max(x));
            for band in 0..b {
                let want = r[f * b + band];
                if want > 0.01 * peak {
                    let got = f64::from(cal.description.response[f][band]);
                    worst = worst.max((got - want).abs() / want);
                }
            }
        }
        assert!(worst < 0.01, "leakage {leakage}: a response entry {:.2} % off", 100.0 * worst);

        // Hot pixels: every one found, few working pixels taken for them.
        let listed: std::collections::BTreeSet<[u32; 2]> = cal.description.hot_pixels.iter().copied().collect();
        assert!(truth.hot.iter().all(|p| listed.contains(p)), "a hot pixel missed");
        assert!(listed.len() <= truth.hot.len() + truth.dark.len() / 1000, "{} listed", listed.len());

        // Dark levels and flats of the working pixels.
        let working: Vec<usize> = (0..truth.dark.len())
            .filter(|&p| {
                !listed.contains(&[(p / (LENSLETS[1] * VIEWS[1])) as u32, (p % (LENSLETS[1] * VIEWS[1])) as u32])
            })
            .collect();
        let rms = |e: &dyn Fn(usize) -> f64| {
            (working.iter().map(|&p| e(p).powi(2)).sum::<f64>() / working.len() as f64).sqrt()
        };
        let dark_rms = rms(&|p| f64::from(cal.dark[p] - desc.black_level - truth.dark[p]));
        assert!(dark_rms < 1.0, "dark levels {dark_rms} DN RMS off");
        let flat_rms = rms(&|p| f64::from(cal.flat[p] / truth.gain[p] - 1.0));
        assert!(flat_rms < 0.005, "flats {:.3} % RMS off", 100.0 * flat_rms);
        eprintln!(
            "leakage {leakage}, k = {k}: response worst {:.3} %, dark {dark_rms:.3} DN RMS, flat {:.3} % RMS, {} hot listed of {}",
            100.0 * worst,
            100.0 * flat_rms,
            listed.len(),
            truth.hot.len()
        );

        // Vignetting per view: the truth's mean flat per view over the brightest's.
        let cols = LENSLETS[1] * VIEWS[1];
        let mut sums = vec![(0.0f64, 0usize); VIEWS[0] * VIEWS[1]];
        for &p in &working {
            let (u, v) = ((p / cols) % VIEWS[0], (p % cols) % VIEWS[1]);
            let s = &mut sums[u * VIEWS[1] + v];
            *s = (s.0 + f64::from(truth.gain[p]), s.1 + 1);
        }
        let means: Vec<f64> = sums.iter().map(|s| s.0 / s.1 as f64).collect();
        let top = means.iter().fold(0.0f64, |m, &x| m.max(x));
        for u in 0..VIEWS[0] {
            for v in 0..VIEWS[1] {
                let want = means[u * VIEWS[1] + v] / top;
                let got = f64::from(cal.description.vignetting[u][v]);
                assert!((got / want - 1.0).abs() < 0.005, "view ({u}, {v}): {got} against {want}");
            }
        }
        assert!(cal.description.vignetting[0][0] < 0.6, "the corner view is vignetted");
    }
}

#[test]
fn measured_filter_curves_stand_in_for_the_sweep() {
    let d = sensor(0.1);
    let caps: Vec<_> =
        captures(d, 1, 2).into_iter().filter(|(_, c)| !matches!(c.description.light, Light::Band { .. })).collect();
    let e = calibrate(&caps, None).unwrap_err().to_string();
    assert!(e.contains("no capture under band 0") && e.contains("--response"), "{e}");
    let b = BAND_NM.len();
    let r = response(&d.filters, &BAND_NM).unwrap();
    let curves: Vec<Vec<f32>> = (0..b).map(|f| (0..b).map(|x| r[f * b + x] as f32).collect()).collect();
    let (cal, _) = calibrate(&caps, Some(curves.clone())).unwrap();
    assert_eq!(cal.description.response, curves);
}

#[test]
fn calibration_captures_that_do_not_belong_together_are_refused() {
    let caps = captures(sensor(0.1), 1, 1);
    let e = calibrate(&[], None).unwrap_err().to_string();
    assert!(e.contains("no calibration capture"), "{e}");
    let no_dark: Vec<_> = caps.iter().filter(|(_, c)| c.description.light != Light::Dark).cloned().collect();
    let e = calibrate(&no_dark, None).unwrap_err().to_string();
    assert!(e.contains("no dark capture"), "{e}");
    let no_flat: Vec<_> =
        caps.iter().filter(|(_, c)| !matches!(c.description.light, Light::Flat { .. })).cloned().collect();
    assert!(calibrate(&no_flat, None).unwrap_err().to_string().contains("no flat capture"));
    // Another camera's flat (another mask seed) among them: named.
    let other = captures(sensor(0.1), 3, 1);
    let mut mixed = caps.clone();
    mixed.push(("other/flat-00".into(), other[1].1.clone()));
    let e = calibrate(&mixed, None).unwrap_err().to_string();
    assert!(e.contains("other/flat-00") && e.contains("another camera"), "{e}");
    // A scene's capture is no calibration capture.
    let mut scene = caps[1].1.clone();
    scene.description.light = Light::Scene;
    let mut with_scene = caps.clone();
    with_scene.push(("scene".into(), scene));
    assert!(calibrate(&with_scene, None).unwrap_err().to_string().contains("scene: a scene's capture"));
}

#[test]
fn the_calibration_folder_reads_back_and_refuses_corruption() {
    let dir = tempfile::tempdir().unwrap();
    let (cal, _) = calibrate(&captures(sensor(0.1), 1, 1), None).unwrap();
    let at = dir.path().join("cal");
    cal.save(&at).unwrap();
    assert_eq!(Calibration::load(&at).unwrap(), cal);

    let json = at.join("calibration.json");
    let good = std::fs::read_to_string(&json).unwrap();
    let value: serde_json::Value = serde_json::from_str(&good).unwrap();
    let spoil = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v = value.clone();
        f(&mut v);
        std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
        let e = format!("{:#}", Calibration::load(&at).unwrap_err());
        assert!(!e.contains('\n'), "{e}");
        e
    };
    assert!(spoil(&|v| v["version"] = 9.into()).contains("version 9"));
    // Issue 51, item 16: a ragged row is named with its length (before: "response is 13
    // x 13, expected 13 x 13").
    let e = spoil(&|v| v["response"][3] = serde_json::json!([1.0]));
    assert!(e.contains("response[3] has 1 entries, expected 13"), "{e}");
    // Item 9: rows of another scale than 1 would rescale the output, and a row summing to 0
    // was accepted by the baselines; item 6: a matrix a decode cannot invert.
    let scaled = |k: f64| {
        move |v: &mut serde_json::Value| {
            for row in v["response"].as_array_mut().unwrap() {
                for x in row.as_array_mut().unwrap() {
                    *x = (x.as_f64().unwrap() * k).into();
                }
            }
        }
    };
    let e = spoil(&scaled(0.3));
    assert!(e.contains("response[0] sums to 0.3") && e.contains("each row sums to 1"), "{e}");
    assert!(spoil(&scaled(1.2)).contains("sums to 1.2"));
    let e = spoil(&|v| v["response"] = serde_json::json!(vec![vec![1.0 / 13.0; 13]; 13]));
    assert!(e.contains("condition number"), "{e}");
    assert!(spoil(&|v| v["response"][2][2] = 0.0.into()).contains("response[2][2]"));
    assert!(spoil(&|v| v["vignetting"][0][0] = (-1.0).into()).contains("vignetting"));
    assert!(spoil(&|v| v["hot_pixels"] = serde_json::json!([[5000, 1]])).contains("outside"));
    assert!(spoil(&|v| v["lenslets"] = serde_json::json!([25, 24])).contains("[125, 120]"));
    std::fs::write(&json, &good).unwrap();
    // A frame written in place of the calibration's own is refused by its recorded size and
    // checksum (issue 51, item 2); one whose record is written too (a hand-made
    // calibration) by its shape from the header or its values.
    let put = |name: &str, values: &[f32], rows: usize, cols: usize, record: bool| {
        slf_host::io::lightfield::write_npy_f32_2d(&at.join(name), values, rows, cols).unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
        if record {
            let r = slf_host::io::folder::record(&at, name).unwrap();
            let files = v["files"].as_array_mut().unwrap();
            let i = files.iter().position(|f| f["name"] == name).unwrap();
            files[i] = serde_json::to_value(r).unwrap();
        }
        std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
        let e = format!("{:#}", Calibration::load(&at).unwrap_err());
        // A decode opens the calibration with its maps read by rows (issue 65): the same
        // refusal, from a pass of bands.
        assert_eq!(format!("{:#}", Calibration::open(&at).unwrap_err()), e);
        e
    };
    let e = put("flat.npy", &[1.0; 6], 2, 3, false);
    assert!(e.contains("flat.npy: 152 bytes, but") && e.contains("calibration.json records"), "{e}");
    let e = put("flat.npy", &[1.0; 6], 2, 3, true);
    assert!(e.contains("flat.npy") && e.contains("[2, 3]"), "{e}");
    let (rows, cols) = cal.frame_size();
    let mut flat = cal.flat.clone();
    flat[7] = f32::NAN;
    let e = put("flat.npy", &flat, rows, cols, false);
    assert!(e.contains("flat.npy: CRC-32"), "{e}");
    let e = put("flat.npy", &flat, rows, cols, true);
    assert!(e.contains("flat.npy: flat[0, 7]"), "{e}");
    cal.save(&at).unwrap();
    // Item 5: a working pixel's dark level above half the range (at the raw values' top, it
    // made every output zero) or below 0 DN (-65535 made every value 18.05) is refused,
    // naming its file.
    let white = cal.description.white_level;
    let hot = cal.description.hot_pixels.iter().map(|p| p[0] as usize * cols + p[1] as usize).collect::<Vec<_>>();
    let first = (0..rows * cols).find(|p| !hot.contains(p)).unwrap();
    let last = (0..rows * cols).rev().find(|p| !hot.contains(p)).unwrap();
    assert!(last / cols >= slf_host::io::map::MAP_BAND_ROWS, "the last row is past the first band of rows");
    for (level, working) in [(white, first), (-65535.0, last), (f32::NAN, first), (f32::NAN, last)] {
        let mut dark = cal.dark.clone();
        dark[working] = level;
        let e = put("dark.npy", &dark, rows, cols, true);
        let at_pixel = format!("dark.npy: dark[{}, {}] is", working / cols, working % cols);
        assert!(e.contains(&at_pixel) && e.contains("list it in hot_pixels"), "{level}: {e}");
    }
}

/// The loop closed, on one case: the office scene at pixel k = 1, 30 x 30 lenslets, 10 %
/// leakage, 50 % vignetting, one sensor (seed 21). Decoded with the calibration its
/// calibration captures gave, it is within 0.5 dB of the ideal sensor's decode and (CS)
/// within 10 % of its spectral angle, where the uncorrected decode is 5 dB and more below;
/// the demosaic gets the same correction. This case only: across the realistic set and the
/// leakages of `docs/results-sensor.md` the PSNR target holds more widely than the
/// spectral angle's, which holds in 2 of its 14 cases.
#[test]
fn a_calibrated_decode_is_the_ideal_sensors() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let d = SensorDescription { hot_fraction: 0.001, ..sensor(0.1) };
    let ideal = slf_host::sim::camera::simulate(&lf, &CameraConfig::pixel(5, 1)).unwrap();
    let real = slf_host::sim::camera::simulate(&lf, &camera(d, 1)).unwrap();
    let caps = calibration_captures(&camera(d, 1), [30, 30], VIEWS, BAND_NM.len(), 4).unwrap();
    let (cal, _) = calibrate(&caps, None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    cal.save(dir.path()).unwrap();
    let at = dir.path().display().to_string();
    let decode = |cap: &Capture, flags: &[&str]| {
        let s = DecodeSettings::from_flags(flags.iter().copied()).unwrap();
        evaluate(&lf, &s.run(cap, false, &|_, _| {}).unwrap().light_field).unwrap()
    };
    for method in ["cs", "demosaic"] {
        let m = ["--method", method];
        let want = decode(&ideal, &m);
        let raw = decode(&real, &m);
        let got = decode(&real, &[&m[..], &["--calibration", &at]].concat());
        eprintln!("{method}: ideal {want:?}\n  uncorrected {raw:?}\n  calibrated {got:?}");
        assert!(raw.psnr < want.psnr - 5.0, "{method}: the uncorrected decode is too good to test anything");
        assert!(got.psnr > want.psnr - 0.5, "{method}: calibrated {} dB against the ideal {}", got.psnr, want.psnr);
        if method == "cs" {
            assert!(got.sa < 1.1 * want.sa, "spectral angle {} against the ideal {}", got.sa, want.sa);
        }
    }
}

/// The decode's in-tile unmixing (the firmware's `ResponseModel::Unmix`, applied per patch
/// and before the overlap's averaging and the output's clamp) against the slow obvious one:
/// the one-hot decode of the same corrected capture with every output spectrum multiplied by
/// `R^-1` in f64 afterwards; and the response in the projection
/// (`--response-model projection`) decodes within 1 dB of it.
#[test]
fn the_decode_unmixes_as_the_inverse_does() {
    use slf_host::decode::correction::corrected;
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 20, cols: 20 });
    let d = sensor(0.3);
    let real = slf_host::sim::camera::simulate(&lf, &camera(d, 3)).unwrap();
    let caps = calibration_captures(&camera(d, 3), [20, 20], VIEWS, BAND_NM.len(), 4).unwrap();
    let (cal, _) = calibrate(&caps, None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    cal.save(dir.path()).unwrap();
    let at = dir.path().display().to_string();
    let run = |cap: &Capture, flags: &[&str]| {
        let s = DecodeSettings::from_flags(flags.iter().copied()).unwrap();
        s.run(cap, false, &|_, _| {}).unwrap().light_field
    };
    // The slow path: one-hot decode of the corrected capture (the white balance the
    // calibrated decode estimates from the same frames), unmixed in f64.
    let mut slow = run(&corrected(&real, &cal.opened(), false).unwrap().0, &[]);
    let r = nalgebra::DMatrix::from_fn(13, 13, |f, b| f64::from(cal.description.response[f][b]));
    let inv = r.try_inverse().unwrap();
    let hi = slow.data.iter().fold(0.0f32, |m, &x| m.max(x));
    for z in slow.data.chunks_exact_mut(13) {
        let x: Vec<f64> = (0..13).map(|b| (0..13).map(|f| inv[(b, f)] * f64::from(z[f])).sum()).collect();
        for (o, v) in z.iter_mut().zip(x) {
            *o = (v as f32).clamp(0.0, hi.max(1.0));
        }
    }
    let fast = run(&real, &["--calibration", &at]);
    // The two differ where the output's clamp cuts: the slow path clamps `z` before it
    // unmixes, the decode `x` after; and a seeded patch starts from its neighbours'
    // unmixed decode mixed back. Nearly every value agrees to f32 rounding.
    let diffs: Vec<f32> = fast.data.iter().zip(&slow.data).map(|(a, b)| (a - b).abs()).collect();
    let off = diffs.iter().filter(|&&d| d > 1e-4).count() as f64 / diffs.len() as f64;
    let rms = (diffs.iter().map(|d| f64::from(d * d)).sum::<f64>() / diffs.len() as f64).sqrt();
    eprintln!("values off by more than 1e-4: {:.3} %, RMS difference {rms:.2e}", 100.0 * off);
    assert!(off < 0.01 && rms < 1e-4, "in-tile unmixing: {off} of the values differ, RMS {rms}");
    // The projection against unmixing by the same model: the model trial has no pilot with
    // the response in the projection (the ensemble decodes), and on this frame its pilots
    // tie with unmixing, where the pixel mask at k = 3 takes the DCT (1.2 dB better here).
    let same = ["--calibration", &at, "--model-trial", "false"];
    let unmixed = run(&real, &same);
    let projected = run(&real, &[&same[..], &["--response-model", "projection"]].concat());
    let (u, p) = (evaluate(&lf, &unmixed).unwrap(), evaluate(&lf, &projected).unwrap());
    eprintln!("unmixed {u:?}\nprojected {p:?}");
    assert!(p.psnr > u.psnr - 1.0 && p.psnr.is_finite(), "projection {} dB against unmixing {}", p.psnr, u.psnr);
}

/// What the device's compact calibration (`Compact::of`: one dark level, a flat per view and
/// region of 5 x 5 lenslets, the hot pixels, the response) must guarantee against the
/// per-pixel one: the same real sensor's scene decoded with each (the compact one written as
/// a calibration whose every pixel has the mean dark level and its view's flat in its region:
/// the device's model through the host's decode), on two scenes and two sensors. What the
/// compact model leaves in is each pixel's own gain (PRNU, 1 % here) and dark offset (3 DN):
/// noise of that size, so it must recover most of what the per-pixel calibration gains over
/// no correction (asserted: 90 %), and its regions must do better than one flat per view for
/// the whole sensor (the vignetting drifts across it). Issue 51: before, one scene and one
/// seed held it within 0.5 dB where 0.47 was measured.
#[test]
fn the_compact_calibration_is_close_to_the_per_pixel_one() {
    use slf_host::decode::device::Compact;
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    for (scene, seed) in [("office", 21u64), ("outdoor", 5)] {
        let lf =
            slf_host::sim::realistic::named(scene).unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
        let d = SensorDescription { hot_fraction: 0.001, seed, ..sensor(0.1) };
        let real = slf_host::sim::camera::simulate(&lf, &camera(d, 1)).unwrap();
        let caps = calibration_captures(&camera(d, 1), [30, 30], VIEWS, BAND_NM.len(), 4).unwrap();
        let (cal, _) = calibrate(&caps, None).unwrap();
        // The device's regions (5 x 5 lenslets), and one region for the whole sensor.
        let whole = Compact::of(&cal, (1, 1)).unwrap();
        let c = Compact::of(&cal, slf_host::decode::device::regions_for([30, 30])).unwrap();
        let (rows, cols) = cal.frame_size();
        let (u, v) = (VIEWS[0], VIEWS[1]);
        let per_pixel = |c: &Compact| -> Vec<f32> {
            let (rr, rc) = (usize::from(c.regions.0), usize::from(c.regions.1));
            (0..rows * cols)
                .map(|p| {
                    let (row, col) = (p / cols, p % cols);
                    let (i, j) = ((row / u) * rr / 30, (col / v) * rc / 30);
                    c.view_gains[((i * rc + j) * u + row % u) * v + col % v]
                })
                .collect()
        };
        let flat = per_pixel(&c);
        let one = Calibration::new(cal.description.clone(), vec![whole.black; rows * cols], per_pixel(&whole)).unwrap();
        let compact = Calibration::new(cal.description.clone(), vec![c.black; rows * cols], flat).unwrap();
        let dirs = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        cal.save(dirs.0.path()).unwrap();
        compact.save(dirs.1.path()).unwrap();
        one.save(dirs.2.path()).unwrap();
        // One model for all (the model trial could pick another for each): the calibrations
        // are compared, not the models.
        let decode = |flags: &[&str]| {
            let s = DecodeSettings::from_flags([&["--model-trial", "false"], flags].concat()).unwrap();
            evaluate(&lf, &s.run(&real, false, &|_, _| {}).unwrap().light_field).unwrap()
        };
        let with = |dir: &std::path::Path| decode(&["--calibration", dir.to_str().unwrap()]);
        let (full, small, one) = (with(dirs.0.path()), with(dirs.1.path()), with(dirs.2.path()));
        let none = decode(&[]);
        eprintln!(
            "{scene}, sensor seed {seed}: uncorrected {:.2} dB, per-pixel {:.2}, compact {:.2}, one flat per view {:.2}",
            none.psnr, full.psnr, small.psnr, one.psnr
        );
        let gained = full.psnr - none.psnr;
        assert!(gained > 3.0, "{scene}: the per-pixel calibration gains only {gained:.2} dB: nothing to test");
        assert!(
            small.psnr - none.psnr >= 0.9 * gained,
            "{scene}: compact {:.2} dB recovers less than 90 % of the per-pixel {:.2} over uncorrected {:.2}",
            small.psnr,
            full.psnr,
            none.psnr
        );
        assert!(
            one.psnr < small.psnr,
            "{scene}: one flat per view {:.2} dB against regions {:.2}",
            one.psnr,
            small.psnr
        );
    }
}
