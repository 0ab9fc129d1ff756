//! The simulated real sensor (issue 43, part 1): a capture of leaky filters, dark levels,
//! gains, hot pixels and vignetting is what the model says pixel by pixel (against a slow
//! f64 reference written here), one sensor whatever the noise seed, recorded in the capture
//! (format version 2) and read back; the ideal sensor's captures are as before (version 1).

use slf_host::io::capture::{Capture, VERSION, VERSION_SENSOR};
use slf_host::io::lightfield::LightField;
use slf_host::io::sensor::{FilterDescription, SensorDescription};
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::flags::FromFlags;
use slf_host::sim::sensor::{Sensor, response, vignette};
use slf_host::sim::settings::SimulateSettings;
use slf_host::sim::spectra::BAND_NM;

const LENSLETS: usize = 12;

/// A light field whose spectrum changes with band, view and place (values in [0.05, 0.8]).
fn field() -> LightField {
    LightField::from_fn((5, 5), LENSLETS, LENSLETS, BAND_NM.len(), |u, v, y, x, b| {
        0.05 + 0.75
            * (0.5 + 0.5 * ((b as f32 * 0.7 + y as f32 * 0.3 + x as f32 * 0.2 + (u + 2 * v) as f32 * 0.05).sin()))
    })
}

fn real() -> SensorDescription {
    SensorDescription {
        filters: FilterDescription { leakage: 0.3, ..FilterDescription::IDEAL },
        dark_sd_dn: 3.0,
        hot_fraction: 0.01,
        prnu: 0.02,
        vignetting: 0.5,
        seed: 9,
    }
}

fn camera(sensor: SensorDescription, k: u8, seed: u64) -> CameraConfig {
    let mut cam = CameraConfig::pixel(seed, k).noiseless();
    cam.sensor = sensor;
    cam
}

/// Every pixel against `black + dark + (white - black) * gain * vignetting * sum_b R[f][b] L_b`
/// in f64, the response matrix and vignetting from their own formulas, the dark levels and
/// gains from the sensor drawn from the same seed (PRNU alone: the vignetting divided out
/// is checked against the formula).
#[test]
fn a_real_sensors_capture_is_its_model_pixel_by_pixel() {
    let lf = field();
    let d = real();
    for k in [1u8, 3] {
        let cap = simulate(&lf, &camera(d, k, 4)).unwrap();
        let desc = &cap.description;
        let (black, white, top) =
            (f64::from(desc.black_level), f64::from(desc.white_level), f64::from(desc.saturation_level));
        let sensor = Sensor::new(&d, [LENSLETS, LENSLETS], [5, 5], &BAND_NM, (white - black) as f32, None).unwrap();
        let r = response(&d.filters, &BAND_NM).unwrap();
        let mask = cap.mask().unwrap();
        let (rows, cols) = (LENSLETS * 5, LENSLETS * 5);
        let (mut worst, mut shaded) = (0.0f64, 0usize);
        for row in 0..rows {
            for col in 0..cols {
                let p = row * cols + col;
                let (s, u, t, v) = (row / 5, row % 5, col / 5, col % 5);
                let shade = vignette(d.vignetting, [LENSLETS, LENSLETS], [5, 5], s, t, u, v);
                let prnu = f64::from(sensor.gain[p]) / shade;
                assert!((prnu - 1.0).abs() < 0.15, "pixel {p}: gain {prnu} is no PRNU of 0.02");
                shaded += usize::from(shade < 0.99);
                for (j, &f) in mask.bands_at(row, col).iter().enumerate() {
                    let f = f as usize;
                    let light: f64 =
                        (0..BAND_NM.len()).map(|b| r[f * BAND_NM.len() + b] * f64::from(lf.get(u, v, s, t, b))).sum();
                    let want = (black + f64::from(sensor.dark[p]) + (white - black) * prnu * shade * light)
                        .round()
                        .clamp(0.0, top);
                    let got = f64::from(cap.held_frames().unwrap()[j][p]);
                    worst = worst.max((got - want).abs());
                }
            }
        }
        // f32 against f64 may round a value on a .5 boundary the other way.
        assert!(worst <= 1.0, "k = {k}: a pixel {worst} DN from the model");
        assert!(shaded > rows * cols / 2, "vignetting reached {shaded} pixels");
        assert_eq!(cap.description.version, VERSION_SENSOR);
        assert_eq!(cap.description.simulated_sensor, Some(d));
    }
}

/// Leaked light is there: with 30 % leakage a pixel records light of bands its filter
/// does not pass (a light field of one band lights every filter type's pixels).
#[test]
fn leaky_filters_see_other_bands() {
    let one_band =
        LightField::from_fn((5, 5), LENSLETS, LENSLETS, BAND_NM.len(), |_, _, _, _, b| if b == 6 { 0.8 } else { 0.0 });
    let leaky = SensorDescription {
        filters: FilterDescription { leakage: 0.3, ..FilterDescription::IDEAL },
        ..SensorDescription::IDEAL
    };
    for (sensor, lit_others) in [(SensorDescription::IDEAL, false), (leaky, true)] {
        let cap = simulate(&one_band, &camera(sensor, 1, 2)).unwrap();
        let mask = cap.mask().unwrap();
        let black = cap.description.black_level as u16;
        let cols = LENSLETS * 5;
        let lit = (0..cap.held_frames().unwrap()[0].len())
            .filter(|&p| mask.bands_at(p / cols, p % cols)[0] != 6)
            .any(|p| cap.held_frames().unwrap()[0][p] > black + 2);
        assert_eq!(lit, lit_others, "{sensor:?}");
    }
}

/// One sensor whatever the noise: dark levels and hot pixels depend on the sensor's seed,
/// not the capture's.
#[test]
fn one_sensor_for_every_capture_made_with_it() {
    let black = LightField::zeros((5, 5), LENSLETS, LENSLETS, BAND_NM.len());
    let a = simulate(&black, &camera(real(), 1, 1)).unwrap();
    let b = simulate(&black, &camera(real(), 1, 77)).unwrap();
    assert_eq!(a.held_frames().unwrap(), b.held_frames().unwrap(), "a dark frame without noise is the sensor's alone");
    let other = simulate(&black, &camera(SensorDescription { seed: 10, ..real() }, 1, 1)).unwrap();
    assert_ne!(a.held_frames().unwrap(), other.held_frames().unwrap());
    // The hot pixels stand out of the dark frame.
    let hot = a.held_frames().unwrap()[0].iter().filter(|&&x| f32::from(x) > a.description.black_level + 100.0).count();
    let n = a.held_frames().unwrap()[0].len() as f64;
    assert!((0.005..0.02).contains(&(hot as f64 / n)), "{hot} hot pixels of {n}");
}

#[test]
fn the_capture_records_its_sensor_and_reads_it_back() {
    let dir = tempfile::tempdir().unwrap();
    let lf = field();
    let cap = simulate(&lf, &camera(real(), 1, 3)).unwrap();
    cap.save(&dir.path().join("real")).unwrap();
    let back = Capture::load(&dir.path().join("real")).unwrap();
    assert_eq!(back.description, cap.description);
    assert_eq!(back.held_frames().unwrap(), cap.held_frames().unwrap());

    // The ideal sensor's capture is version 1 and says nothing of a sensor.
    let ideal = simulate(&lf, &camera(SensorDescription::IDEAL, 1, 3)).unwrap();
    ideal.save(&dir.path().join("ideal")).unwrap();
    let text = std::fs::read_to_string(dir.path().join("ideal/capture.json")).unwrap();
    assert!(!text.contains("simulated_sensor"), "{text}");
    assert_eq!(Capture::load(&dir.path().join("ideal")).unwrap().description.version, VERSION);

    // A sensor in a version 1 capture, an unknown version, or a sensor out of its ranges:
    // one line naming what is wrong.
    let path = dir.path().join("real/capture.json");
    let good = std::fs::read_to_string(&path).unwrap();
    for (from, to, says) in [
        ("\"version\": 2", "\"version\": 1", "needs version 2"),
        ("\"version\": 2", "\"version\": 3", "version 3 is not supported"),
        ("\"leakage\": 0.3", "\"leakage\": 1.5", "simulated_sensor.filters.leakage"),
        ("\"vignetting\": 0.5", "\"vignetting\": -1", "simulated_sensor.vignetting"),
    ] {
        assert!(good.contains(from), "{from} not in {good}");
        std::fs::write(&path, good.replace(from, to)).unwrap();
        let e = format!("{:#}", Capture::load(&dir.path().join("real")).unwrap_err());
        assert!(e.contains(says) && !e.contains('\n'), "{to}: {e}");
    }
}

/// `slf simulate`'s sensor flags make the sensor they name; out of range, one line.
#[test]
fn the_sensor_flags() {
    let s = SimulateSettings::from_flags([
        "--leakage=0.1",
        "--filter-width=20",
        "--secondary=0.1",
        "--secondary-nm=100",
        "--leak-floor=0.01",
        "--dark-sd=2",
        "--hot-pixels=0.001",
        "--prnu=0.01",
        "--vignetting=0.4",
        "--sensor-seed=5",
    ])
    .unwrap();
    let want = SensorDescription {
        filters: FilterDescription { leakage: 0.1, width_nm: 20.0, secondary: 0.1, secondary_nm: 100.0, floor: 0.01 },
        dark_sd_dn: 2.0,
        hot_fraction: f64::from(0.001f32),
        prnu: 0.01,
        vignetting: 0.4,
        seed: 5,
    };
    assert_eq!(s.camera().sensor, want);
    assert!(SimulateSettings::from_flags(std::iter::empty::<&str>()).unwrap().camera().sensor.is_ideal());
    for flag in ["--leakage=0.95", "--vignetting=1", "--prnu=nan", "--hot-pixels=-0.1", "--filter-width=0"] {
        let e = SimulateSettings::from_flags([flag]).unwrap_err();
        assert!(e.contains(flag.split('=').next().unwrap()) && !e.contains('\n'), "{flag}: {e}");
    }
}
