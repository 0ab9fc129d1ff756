//! The simulator behind a real lenslet array (issue 52): rotated, a non-integer pitch,
//! offset. Each pixel is checked against an f64 reference written here: the pixel's square
//! sampled at 200 x 200 points, each point's lenslet found by solving the grid's 2 x 2
//! system (not the crate's mapping), the light field's view cell looked up, the values
//! averaged.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use slf_firmware::FullViewShape;
use slf_host::io::capture::VERSION_SENSOR;
use slf_host::io::lightfield::LightField;
use slf_host::io::sensor::SensorDescription;
use slf_host::sim::camera::{CameraConfig, GridSettings, simulate};
use slf_host::sim::flags::FromFlags;

const LENSLETS: [usize; 2] = [6, 7];
const VIEWS: usize = 5;
/// Points per pixel side in the reference.
const POINTS: usize = 200;

fn field() -> LightField {
    let mut rng = ChaCha8Rng::seed_from_u64(52);
    let values: Vec<f32> =
        (0..VIEWS * VIEWS * LENSLETS[0] * LENSLETS[1] * 13).map(|_| rng.random_range(0.0..0.9)).collect();
    LightField::from_fn((VIEWS, VIEWS), LENSLETS[0], LENSLETS[1], 13, |u, v, s, t, b| {
        values[(((u * VIEWS + v) * LENSLETS[0] + s) * LENSLETS[1] + t) * 13 + b]
    })
}

/// A 16-bit noiseless camera, black at 0 and white at the top code: a frame holds the
/// light to 1/65535.
fn camera(grid: Option<GridSettings>, vignetting: f32) -> CameraConfig {
    let mut cam = CameraConfig::pixel(3, 2).noiseless();
    (cam.bits, cam.black_level, cam.white_fraction) = (16, 0, 1.0);
    cam.sensor = SensorDescription { vignetting, ..SensorDescription::IDEAL };
    cam.grid = grid;
    cam
}

/// The cos^4 law as `docs/capture-format.md` states it for a grid: view `(u, v)` gets
/// `1 / (1 + a r^2)^2`, `r` its distance from the middle view over the corner's.
fn shade(vignetting: f64, u: usize, v: usize) -> f64 {
    if vignetting == 0.0 {
        return 1.0;
    }
    let a = 1.0 / (1.0 - vignetting).sqrt() - 1.0;
    let r2 = ((u as f64 - 2.0).powi(2) + (v as f64 - 2.0).powi(2)) / 8.0;
    1.0 / (1.0 + a * r2).powi(2)
}

/// Where sensor point `(y, x)` looks: lenslet `(s, t)`'s centre is
/// `offset + s p0 (cos, -sin) + t p1 (sin, cos)`, so the point's continuous lenslet
/// coordinates solve that 2 x 2 system; views divide a lenslet's `[-1/2, 1/2)` into 5.
/// Returns the view's shade and the light field's `(u, v, s, t)` there, `None` off the light
/// field.
fn light(
    rotation_deg: f64,
    pitch: [f64; 2],
    offset: [f64; 2],
    vignetting: f64,
    p: [f64; 2],
) -> Option<(f64, [usize; 4])> {
    let [s, t] = lenslet_coordinates(rotation_deg, pitch, offset, p);
    let (cs, ct) = ((s + 0.5).floor(), (t + 0.5).floor());
    let u = ((s + 0.5 - cs) * VIEWS as f64).floor() as usize;
    let v = ((t + 0.5 - ct) * VIEWS as f64).floor() as usize;
    if cs < 0.0 || ct < 0.0 || cs as usize >= LENSLETS[0] || ct as usize >= LENSLETS[1] {
        return None;
    }
    Some((shade(vignetting, u, v), [u, v, cs as usize, ct as usize]))
}

/// Sensor point `p`'s continuous lenslet coordinates `[s, t]` (lenslet `(s, t)` spans
/// `[s - 1/2, s + 1/2)`): lenslet `(s, t)`'s centre is `offset + s p0 (cos, -sin) + t p1
/// (sin, cos)`, so they solve that 2 x 2 system.
fn lenslet_coordinates(rotation_deg: f64, pitch: [f64; 2], offset: [f64; 2], p: [f64; 2]) -> [f64; 2] {
    let (sin, cos) = rotation_deg.to_radians().sin_cos();
    // Columns of the system: the lenslet row step and the lenslet column step.
    let (a, b) = ([pitch[0] * cos, -pitch[0] * sin], [pitch[1] * sin, pitch[1] * cos]);
    let d = [p[0] - offset[0], p[1] - offset[1]];
    let det = a[0] * b[1] - b[0] * a[1];
    [(d[0] * b[1] - b[0] * d[1]) / det, (a[0] * d[1] - d[0] * a[1]) / det]
}

/// Whether pixel `(row, col)`'s centre lies outside `lenslets` lenslets of `g` by the f64
/// solve; `None` within `1e-3` lenslet of the array's edge, where f32 and f64 may disagree.
fn outside_array(
    g: &slf_host::io::grid::GridDescription,
    lenslets: [usize; 2],
    (row, col): (usize, usize),
) -> Option<bool> {
    let c = lenslet_coordinates(g.rotation_deg, g.pitch, g.offset, [row as f64 + 0.5, col as f64 + 0.5]);
    let near = |x: f64, n: usize| (x + 0.5).abs() < 1e-3 || (x + 0.5 - n as f64).abs() < 1e-3;
    if near(c[0], lenslets[0]) || near(c[1], lenslets[1]) {
        return None;
    }
    let inside = |x: f64, n: usize| x + 0.5 >= 0.0 && x + 0.5 < n as f64;
    Some(!(inside(c[0], lenslets[0]) && inside(c[1], lenslets[1])))
}

#[test]
fn a_pixel_behind_a_turned_grid_records_the_light_over_its_square() {
    let lf = field();
    for (rotation_deg, pitch, offset, vignetting) in [
        (0.6, [5.07, 4.93], None, 0.0f32),
        (-1.0, [5.2, 5.2], Some([1.3, 3.9]), 0.4),
        (0.0, [5.0, 5.0], Some([2.25, 2.5]), 0.0),
    ] {
        let cap = simulate(&lf, &camera(Some(GridSettings { rotation_deg, pitch: Some(pitch), offset }), vignetting))
            .unwrap();
        let g = cap.description.lenslet_grid.expect("the capture records its grid");
        assert_eq!((g.rotation_deg, g.pitch, cap.description.version), (rotation_deg, pitch, VERSION_SENSOR));
        if let Some(o) = offset {
            assert_eq!(g.offset, o);
        }
        let want_size = [(6.0 * pitch[0]).round() as usize, (7.0 * pitch[1]).round() as usize];
        assert_eq!(g.sensor, want_size);
        assert_eq!(cap.frame_size(), (want_size[0], want_size[1]));
        let mask = cap.mask().unwrap();
        let mut worst = 0.0f64;
        let mut lit = 0;
        for row in 0..g.sensor[0] {
            for col in 0..g.sensor[1] {
                let bands = mask.bands_at(row, col);
                let mut sums = [0.0f64; 2];
                for a in 0..POINTS {
                    for b in 0..POINTS {
                        let p = [
                            row as f64 + (a as f64 + 0.5) / POINTS as f64,
                            col as f64 + (b as f64 + 0.5) / POINTS as f64,
                        ];
                        let l = light(rotation_deg, pitch, g.offset, f64::from(vignetting), p);
                        for (sum, &band) in sums.iter_mut().zip(bands.iter()) {
                            *sum += l.map_or(0.0, |(shade, at)| {
                                shade * f64::from(lf.get(at[0], at[1], at[2], at[3], band as usize))
                            });
                        }
                    }
                }
                for (j, sum) in sums.iter().enumerate() {
                    let want = sum / (POINTS * POINTS) as f64;
                    let got = f64::from(cap.held_frames().unwrap()[j][row * g.sensor[1] + col]) / 65535.0;
                    worst = worst.max((got - want).abs());
                    lit += usize::from(want > 0.0);
                }
            }
        }
        // Sampling 200 x 200 points misplaces a cell border by at most 1/200 of a pixel
        // side, and the borders' errors mostly cancel: 2e-3 of white is 5 times the largest
        // seen; a view off by one, a turn the wrong way or a lost vignetting is 0.1 or more.
        assert!(worst < 2e-3, "rotation {rotation_deg}, pitch {pitch:?}: worst {worst}");
        assert!(lit > g.sensor[0] * g.sensor[1] * 3 / 2, "{lit} lit");
    }
}

#[test]
fn the_aligned_grid_is_todays_capture_byte_for_byte() {
    let lf = field();
    let plain = simulate(&lf, &camera(None, 0.3)).unwrap();
    let aligned = GridSettings { rotation_deg: 0.0, pitch: None, offset: None };
    let gridded = simulate(&lf, &camera(Some(aligned), 0.3)).unwrap();
    assert_eq!(plain.held_frames().unwrap(), gridded.held_frames().unwrap());
    assert_eq!(plain.description, gridded.description);
    assert!(gridded.description.lenslet_grid.is_none());
}

/// The micro-image grid's RMS distance between two grids' centres of the `S x T` lenslets.
fn centres_rms(
    a: &slf_host::io::grid::GridDescription,
    b: &slf_host::io::grid::GridDescription,
    lenslets: [usize; 2],
) -> f64 {
    let mut sq = 0.0;
    for s in 0..lenslets[0] {
        for t in 0..lenslets[1] {
            let (p, q) = (a.centre(s as f64, t as f64), b.centre(s as f64, t as f64));
            sq += (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        }
    }
    (sq / (lenslets[0] * lenslets[1]) as f64).sqrt()
}

/// `slf calibrate` finds the grid from noisy flats (shot and read noise, 1 % PRNU, 30 %
/// vignetting, two exposures) within the targets: rotation 0.02 degrees, pitch
/// 0.005 px, centres 0.05 px RMS, on grids turned either way up to a degree with pitches
/// from 4.9 to 5.2 px, and on an unturned 5-pixel grid only offset (every micro-image
/// then at the same phase, where a biased centre would not average out).
#[test]
fn the_calibration_finds_the_grid_from_its_flats() {
    use slf_host::decode::calibrate::calibrate;
    use slf_host::sim::calibration::calibration_captures;
    let lenslets = [40, 44];
    for (rotation_deg, pitch, offset) in [
        (0.0, [5.0, 5.0], Some([2.8, 2.3])),
        (0.3, [5.04, 5.04], None),
        (-1.0, [5.2, 4.9], None),
        (0.1, [4.9, 5.1], None),
    ] {
        let mut cam = CameraConfig::pixel(7, 1);
        cam.sensor = SensorDescription { vignetting: 0.3, prnu: 0.01, ..SensorDescription::IDEAL };
        cam.grid = Some(GridSettings { rotation_deg, pitch: Some(pitch), offset });
        let truth = cam.grid.unwrap().grid(lenslets, [5, 5]);
        let captures = calibration_captures(&cam, lenslets, [5, 5], 13, 2).unwrap();
        let (cal, report) = calibrate(&captures, None).unwrap();
        let g = cal.description.lenslet_grid.expect("a grid found");
        let rms = centres_rms(&g, &truth, lenslets);
        assert!(
            (g.rotation_deg - rotation_deg).abs() < 0.02
                && (g.pitch[0] - pitch[0]).abs() < 0.005
                && (g.pitch[1] - pitch[1]).abs() < 0.005
                && rms < 0.05,
            "rotation {rotation_deg}, pitch {pitch:?}: found {g:?}, centres {rms} px RMS off"
        );
        assert!(report.lines.iter().any(|l| l.starts_with("lenslet grid: rotation")), "{report:?}");
        assert_eq!(cal.frame_size(), (truth.sensor[0], truth.sensor[1]));
    }
}

/// Flats without vignetting show no micro-image: the grid is refused in one line, not
/// made up.
#[test]
fn flats_without_micro_images_give_no_grid() {
    use slf_host::decode::calibrate::calibrate;
    use slf_host::sim::calibration::calibration_captures;
    let mut cam = CameraConfig::pixel(7, 1);
    cam.sensor = SensorDescription { prnu: 0.01, ..SensorDescription::IDEAL };
    cam.grid = Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None });
    let captures = calibration_captures(&cam, [30, 30], [5, 5], 13, 1).unwrap();
    let e = format!("{:#}", calibrate(&captures, None).unwrap_err());
    assert!(e.contains("lenslet grid") && e.contains("micro-image") && !e.contains('\n'), "{e}");
}

/// The decode through a grid, on a capture behind a turned array (0.5 degrees, 5.08 px,
/// noiseless, pixel k = 1, office at 30 x 30 lenslets): decoding each pixel as the shares
/// of the view cells it covers beats reading the frame as if the array were aligned
/// (`--grid aligned`, slf before grids) by at least 7.5 dB (measured 34.75 against 26.08;
/// reading each view at the pixel under its cell's centre, the decode before the shares,
/// gave 32.65, so a return to it fails); the baselines through the grid beat themselves
/// reading it as aligned by 1 dB (measured: demosaic 28.92, PPID 27.37 against 25.66); and
/// the aligned grid
/// given to the firmware's decoder reads the same pixels as no grid, so its patches are the
/// same bits.
#[test]
fn the_decode_reads_each_view_where_the_grid_puts_it() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let mut cam = CameraConfig::pixel(5, 1).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.5, pitch: Some([5.08, 5.08]), offset: None });
    let cap = simulate(&lf, &cam).unwrap();
    let decode = |flags: &[&str]| {
        let s = DecodeSettings::from_flags(flags.iter().copied()).unwrap();
        evaluate(&lf, &s.run(&cap, false, &|_, _| {}).unwrap().light_field).unwrap()
    };
    let (grid, aligned) = (decode(&[]), decode(&["--grid", "aligned"]));
    eprintln!("through the grid {grid:?}\nas aligned {aligned:?}");
    assert!(grid.psnr > aligned.psnr + 7.5, "through the grid {} dB, as aligned {}", grid.psnr, aligned.psnr);
    assert!(grid.sa < aligned.sa, "spectral angle {} through the grid, {} as aligned", grid.sa, aligned.sa);
    // Issue 66, item 3: the baselines read the grid too (each view cell the pixel under its
    // centre), far above reading the frame as aligned (before: refused behind a grid, and
    // `--grid aligned` their only way).
    for method in ["demosaic", "ppid"] {
        let (grid, aligned) = (decode(&["--method", method]), decode(&["--method", method, "--grid", "aligned"]));
        eprintln!("{method}: through the grid {grid:?}\nas aligned {aligned:?}");
        assert!(
            grid.psnr > aligned.psnr + 1.0,
            "{method}: through the grid {} dB, as aligned {}",
            grid.psnr,
            aligned.psnr
        );
    }

    // The aligned grid through the grid's path: the same bits as the aligned path's runs.
    let plain = simulate(&lf, &CameraConfig::pixel(5, 1)).unwrap();
    let dec = plain.decoder::<5, 5, 8125>(slf_firmware::Sl0Config::DEFAULT).unwrap();
    let g = slf_host::io::grid::GridDescription::aligned([30, 30], [5, 5]).firmware([5, 5]).unwrap();
    let gridded = plain.decoder::<5, 5, 8125>(slf_firmware::Sl0Config::DEFAULT).unwrap().with_grid(Some(g)).unwrap();
    let raw = plain.raw_frames().unwrap();
    let dct = Box::new(slf_firmware::Dictionary::<FullViewShape>::dct());
    let mut outs = Vec::new();
    for d in [&dec, &gridded] {
        let mut got = Vec::new();
        let mut ws = Box::new(slf_firmware::FullViewWorkspace::new());
        for tile in d.tiles((2, 2)) {
            d.decode_tile(&*dct, tile, &mut slf_firmware::FrameSource::new(&raw), &mut Collect(&mut got), &mut ws)
                .unwrap();
        }
        outs.push(got);
    }
    assert!(!outs[0].is_empty());
    assert!(outs[0] == outs[1], "the aligned grid's patches differ from no grid's");
}

/// A grid offset by exactly half a pixel (pitch 5.00, unturned): the pixel under each view
/// cell's centre has its own centre on the cell's border. Each cell still takes it (cells a
/// pixel wide never share one), so every patch decodes (before, every cell refused its pixel
/// and 156 of 169 patches failed on office at 64 x 64 lenslets), within 10 dB of the aligned
/// sensor: each pixel is the mean of two rows of views, which costs information (measured
/// here 35.60 against 42.85 dB: pixel k = 3, noiseless, disjoint unsheared patches).
#[test]
fn a_grid_half_a_pixel_off_decodes_every_patch() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let mut cam = CameraConfig::pixel(5, 3).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.0, pitch: Some([5.0, 5.0]), offset: Some([2.0, 2.5]) });
    let cap = simulate(&lf, &cam).unwrap();
    let s = DecodeSettings::from_flags(["--disparities", "0:0", "--stride", "5"]).unwrap();
    let run = s.run(&cap, false, &|_, _| {}).unwrap();
    let slf_host::decode::pipeline::Outcome::Cs { report, .. } = &run.outcome else { panic!("not a CS decode") };
    assert!(report.patches.decoded > 0 && report.patches.failed == 0, "{:?}", report.patches);
    let m = evaluate(&lf, &run.light_field).unwrap();
    let aligned = simulate(&lf, &CameraConfig::pixel(5, 3).noiseless()).unwrap();
    let r = evaluate(&lf, &s.run(&aligned, false, &|_, _| {}).unwrap().light_field).unwrap();
    eprintln!("half a pixel off {m:?}\naligned {r:?}");
    assert!(m.psnr > r.psnr - 10.0 && m.psnr > 30.0, "half a pixel off {} dB, aligned {}", m.psnr, r.psnr);
}

/// A grid whose first lenslet column lies left of the sensor: the decode reports its 30
/// lenslets' 750 views as off the sensor (never measured), and decodes the rest.
#[test]
fn the_decode_counts_the_views_off_the_sensor() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let mut cam = CameraConfig::pixel(5, 2).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.0, pitch: Some([5.02, 5.02]), offset: Some([2.5, -2.5]) });
    let cap = simulate(&lf, &cam).unwrap();
    let s = DecodeSettings::from_flags(["--disparities", "0:0", "--stride", "5"]).unwrap();
    let run = s.run(&cap, false, &|_, _| {}).unwrap();
    let slf_host::decode::pipeline::Outcome::Cs { report, .. } = &run.outcome else { panic!("not a CS decode") };
    assert_eq!((report.off_sensor.lenslets, report.off_sensor.views), (30, 30 * 25));
    assert!(report.patches.decoded > 0, "{:?}", report.patches);
    // On a grid that keeps every view on the sensor: none.
    cam.grid = Some(GridSettings { rotation_deg: 0.0, pitch: Some([5.02, 5.02]), offset: None });
    let run = s.run(&simulate(&lf, &cam).unwrap(), false, &|_, _| {}).unwrap();
    let slf_host::decode::pipeline::Outcome::Cs { report, .. } = &run.outcome else { panic!("not a CS decode") };
    assert_eq!(report.off_sensor.lenslets, 0);
}

/// At pixel k = 1 the default searches half-pixel disparities on the aligned sensor, and
/// whole ones only behind a grid (where, read by the cells' shares, the halves were ahead of
/// whole disparities by more than 0.1 dB on 3 of 14 decodes: `DecodeOptions::disparities_for`);
/// asked for, halves are searched there too.
#[test]
fn behind_a_grid_the_default_disparities_are_whole() {
    use slf_host::decode::pipeline::Outcome;
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let halves = |cap: &slf_host::io::capture::Capture, flags: &[&str]| {
        let run = DecodeSettings::from_flags(flags.iter().copied()).unwrap().run(cap, false, &|_, _| {}).unwrap();
        let Outcome::Cs { report, .. } = &run.outcome else { panic!("not a CS decode") };
        assert!(!report.disparity_counts.is_empty());
        report.disparity_counts.iter().filter(|(d, _)| d.in_halves() % 2 != 0).map(|(_, n)| n).sum::<usize>()
    };
    let mut cam = CameraConfig::pixel(5, 1).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None });
    let gridded = simulate(&lf, &cam).unwrap();
    assert_eq!(halves(&gridded, &["--shear-trial", "false"]), 0);
    assert!(halves(&gridded, &["--shear-trial", "false", "--disparities", "-1:1:0.5"]) > 0);
    let aligned = simulate(&lf, &CameraConfig::pixel(5, 1).noiseless()).unwrap();
    assert!(halves(&aligned, &["--shear-trial", "false"]) > 0);
}

/// Half-pixel shears behind a grid read it by the cells' shares (a half view's cell the mean
/// of two grid positions, `slf_firmware::shares`): on a textured plane at half a pixel of
/// disparity behind a grid turned 0.3 degrees at 5.04 px (pixel k = 1, noiseless, 30 x 30
/// lenslets, scored without the 2 edge lenslets), searching the halves beats whole
/// disparities alone by at least 3 dB. Measured: 43.75 dB against 36.76 with the shares;
/// with each half view read at the pixel under its cell's centre (the decode before), the
/// halves gave 36.34, below the whole disparities, so a return to that read fails.
#[test]
fn behind_a_grid_a_plane_at_half_a_pixel_decodes_better_with_the_halves() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::{Layer, Scene, SceneSize, Shape, Texture};
    use slf_host::sim::spectra::{D65, colorchecker};
    let cc = |n: &str| colorchecker(n).unwrap();
    let layers = vec![Layer::flat(
        0.5,
        Shape::Everywhere,
        Texture::Noise { cell: 3.0, seed: 7 },
        [cc("moderate red"), cc("bluish green")],
    )];
    let scene = Scene { name: "plane".into(), layers, gain: 1.0, illuminant: D65 };
    let lf = scene.render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let mut cam = CameraConfig::pixel(5, 1).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None });
    let cap = simulate(&lf, &cam).unwrap();
    let decode = |range: &str| {
        let s = DecodeSettings::from_flags(["--disparities", range, "--shear-trial", "false"]).unwrap();
        let out = s.run(&cap, false, &|_, _| {}).unwrap().light_field;
        evaluate(&lf.window(2, 2, 26, 26), &out.window(2, 2, 26, 26)).unwrap().psnr
    };
    let (whole, halves) = (decode("-1:1"), decode("-1:1:0.5"));
    eprintln!("whole {whole:.2} dB, with the halves {halves:.2}");
    assert!(halves > whole + 3.0, "with the halves {halves:.2} dB, whole disparities {whole:.2}");
}

/// Behind a grid a patch sheared by a whole lenslet finds its outer views' neighbours across
/// the micro-image borders outside itself at every lenslet; the shifted patches of the
/// default decode take those cells' shares out of their measurements by the frame's first
/// decode (`CellShares::known_outside`), where the own-cell rule gave them to the pixel's
/// own cell. On office behind a grid turned 0.3 degrees at 5.04 px (pixel k = 3,
/// noiseless, 64 x 64 lenslets, scored without the 2 edge lenslets) the shears then beat
/// the unsheared decode by at least 0.5 dB. Measured: 45.60 dB against 43.99; with the
/// own-cell rule (`slf decode` of main at 7dbfe82 on the same scene's `--no-noise` capture)
/// the shears gave 43.40 against 44.01, so a return to it fails. At 48 x 48 lenslets the
/// shears did not gain (42.15 against 42.61): not yet understood.
#[test]
fn behind_a_grid_the_shears_gain_with_the_cells_outside_known() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::eval::metrics::evaluate;
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 64, cols: 64 });
    let mut cam = CameraConfig::pixel(5, 3).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None });
    let cap = simulate(&lf, &cam).unwrap();
    let decode = |range: &str| {
        let s = DecodeSettings::from_flags(["--disparities", range]).unwrap();
        let out = s.run(&cap, false, &|_, _| {}).unwrap().light_field;
        evaluate(&lf.window(2, 2, 60, 60), &out.window(2, 2, 60, 60)).unwrap().psnr
    };
    let (unsheared, sheared) = (decode("0:0"), decode("-1:1"));
    eprintln!("unsheared {unsheared:.2} dB, sheared {sheared:.2}");
    assert!(sheared > unsheared + 0.5, "sheared {sheared:.2} dB, unsheared {unsheared:.2}");
}

/// Behind a turned grid a patch sheared by whole lenslets finds the cell across a
/// micro-image border outside itself, and the read leaves out, at k = 3, the pixels whose
/// square lies largely there (`slf_firmware::shares::MAX_OUTSIDE_SHARE`, whose shares are
/// tested against their definition in the firmware's `shares.rs`): only pixels of the outer
/// views or lenslets (the patch's rim, where a shear puts the next view's lenslet), on some
/// patch. At k = 1 every pixel stays, and an unsheared patch reads the same pixels at k = 1
/// and 3.
#[test]
fn a_sheared_patch_behind_a_grid_leaves_out_pixels_mostly_outside_it() {
    use slf_firmware::{Disparity, FrameSource, FullViewWorkspace, PatchOrigin, Shape};
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 24, cols: 24 });
    let read = |k: u8, d: i8, origin: (u16, u16)| {
        let mut cam = CameraConfig::pixel(5, k).noiseless();
        cam.grid = Some(GridSettings { rotation_deg: 1.0, pitch: Some([5.1, 5.1]), offset: None });
        let cap = simulate(&lf, &cam).unwrap();
        let dec = cap.decoder::<5, 5, 8125>(slf_firmware::Sl0Config::DEFAULT).unwrap();
        let raw = cap.raw_frames().unwrap();
        let mut ws = Box::new(FullViewWorkspace::new());
        let o = PatchOrigin {
            lenslet_row: origin.0,
            lenslet_col: origin.1,
            view_row: 0,
            view_col: 0,
            disparity: Disparity::pixels(d),
        };
        dec.read_patch(o, &mut FrameSource::new(&raw), &mut ws).unwrap();
        let m = ws.measurements();
        let mut pixels = Vec::new();
        for (s, t, u, v) in
            (0..5).flat_map(|s| (0..5).flat_map(move |t| (0..5).flat_map(move |u| (0..5).map(move |v| (s, t, u, v)))))
        {
            let i = FullViewShape::pixel_index(s, t, u, v);
            if (0..13).any(|b| m.get(i + b).is_some()) {
                pixels.push((s, t, u, v));
            }
        }
        pixels
    };
    let mut left_out = 0;
    for origin in [(4u16, 4u16), (6, 12), (12, 6), (12, 12)] {
        assert_eq!(read(1, 0, origin), read(3, 0, origin), "unsheared at {origin:?}");
        for d in [-1i8, 1] {
            let (all, kept) = (read(1, d, origin), read(3, d, origin));
            assert!(kept.iter().all(|p| all.contains(p)), "{origin:?} d {d}: a pixel k = 1 does not read");
            let gone: Vec<_> = all.iter().filter(|p| !kept.contains(p)).collect();
            let edge = |&&(s, t, u, v): &&(usize, usize, usize, usize)| [s, t, u, v].iter().any(|x| [0, 4].contains(x));
            assert!(gone.iter().all(edge), "{origin:?} d {d}: {gone:?}");
            left_out += gone.len();
        }
    }
    assert!(left_out > 0, "no sheared patch left a pixel out");
}

/// Every accepted patch's values, in order.
struct Collect<'a>(&'a mut Vec<Vec<u32>>);

impl slf_firmware::PatchSink<FullViewShape> for Collect<'_> {
    type Error = ();
    fn accept(
        &mut self,
        _: slf_firmware::PatchOrigin,
        p: &[f32; 8125],
        _: &slf_firmware::PatchReport,
    ) -> Result<(), ()> {
        self.0.push(p.iter().map(|x| x.to_bits()).collect());
        Ok(())
    }
}

/// A `lenslet_grid` out of its ranges, in a version-1 capture, under a lenslet mask, or of
/// another size than the frames is refused in one line naming the field.
#[test]
fn captures_with_a_wrong_grid_are_refused_by_field() {
    use slf_host::io::capture::{Capture, MaskDescription};
    let lf = field();
    let cam = camera(Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None }), 0.0);
    let cap = simulate(&lf, &cam).unwrap();
    let edit = |f: &dyn Fn(&mut slf_host::io::capture::CaptureDescription)| {
        let mut d = cap.description.clone();
        f(&mut d);
        let e = Capture::new(d, cap.held_frames().unwrap().into_owned()).unwrap_err();
        format!("{e:#}")
    };
    for (says, e) in [
        ("rotation_deg", edit(&|d| d.lenslet_grid.as_mut().unwrap().rotation_deg = 30.0)),
        ("pitch[0]", edit(&|d| d.lenslet_grid.as_mut().unwrap().pitch[0] = 9.0)),
        ("offset[1]", edit(&|d| d.lenslet_grid.as_mut().unwrap().offset[1] = f64::INFINITY)),
        ("expected 31 x 36", edit(&|d| d.lenslet_grid.as_mut().unwrap().sensor = [31, 36])),
        ("needs version 2", edit(&|d| d.version = 1)),
        ("lenslet mask", edit(&|d| d.mask = MaskDescription::seeded(slf_firmware::MaskFamily::Lenslet, 3, 2))),
    ] {
        assert!(e.contains(says) && !e.contains('\n'), "{says}: {e}");
    }
}

/// Issue 66, item 4: behind an array turned by 1 degree (pitch 5.1 px, 30 % vignetting, 1 %
/// PRNU, no defect), the pixels at the sensor's edges that no lenslet lights are listed
/// as outside the array, not as hot or dead (before: all of them hot), each one's centre
/// outside the array by the f64 solve, and every unlit pixel outside it listed; the list is
/// saved and read back, and refused without a grid.
#[test]
fn a_turned_arrays_unlit_edge_pixels_are_outside_it_not_dead() {
    use slf_host::decode::calibrate::{DEAD_FLAT, calibrate};
    use slf_host::io::calibration::Calibration;
    use slf_host::sim::calibration::calibration_captures;
    let lenslets = [40, 44];
    let mut cam = CameraConfig::pixel(7, 1);
    cam.sensor = SensorDescription { vignetting: 0.3, prnu: 0.01, ..SensorDescription::IDEAL };
    cam.grid = Some(GridSettings { rotation_deg: 1.0, pitch: Some([5.1, 5.1]), offset: None });
    let captures = calibration_captures(&cam, lenslets, [5, 5], 13, 1).unwrap();
    let (cal, report) = calibrate(&captures, None).unwrap();
    let d = &cal.description;
    let g = d.lenslet_grid.expect("a grid found");
    assert!(
        d.hot_pixels.is_empty(),
        "{} pixels listed hot or dead, e.g. {:?}",
        d.hot_pixels.len(),
        d.hot_pixels.first()
    );
    assert!(d.outside_pixels.len() > 100, "{} outside", d.outside_pixels.len());
    for &[r, c] in &d.outside_pixels {
        assert_ne!(outside_array(&g, lenslets, (r as usize, c as usize)), Some(false), "[{r}, {c}] lies in the array");
    }
    let listed: std::collections::BTreeSet<[u32; 2]> = d.outside_pixels.iter().copied().collect();
    let (_, cols) = cal.frame_size();
    for (p, &f) in cal.flat.iter().enumerate() {
        let at = [(p / cols) as u32, (p % cols) as u32];
        if f < DEAD_FLAT && outside_array(&g, lenslets, (p / cols, p % cols)) == Some(true) {
            assert!(listed.contains(&at), "{at:?} (flat {f}) not listed");
        }
    }
    let line = &report.lines[1];
    assert!(
        line.starts_with("0 hot, dead or defective pixels of ")
            && line.contains(&format!("({} more outside the lenslet array", d.outside_pixels.len())),
        "{line}"
    );

    let dir = tempfile::tempdir().unwrap();
    let at = dir.path().join("cal");
    cal.save(&at).unwrap();
    assert_eq!(Calibration::load(&at).unwrap(), cal);
    let json = at.join("calibration.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("lenslet_grid");
    std::fs::write(&json, v.to_string()).unwrap();
    let e = format!("{:#}", Calibration::load(&at).unwrap_err());
    assert!(e.contains("outside_pixels listed without a lenslet_grid") && !e.contains('\n'), "{e}");
}

/// Issue 66, item 4: the pixels outside a turned array (1 degree, 5.1 px, office at 30 x
/// 30 lenslets, k = 2, noiseless) are no part of the grey world: set to a bright value,
/// the decode's gains and light field are the same bits (before: the gains moved). The
/// lenslets that reach past the sensor, each with its share of views on it, are the f64
/// reference's: a view counts when its cell's centre lies on the sensor.
#[test]
fn pixels_outside_a_turned_array_are_no_part_of_the_decode() {
    use slf_host::decode::settings::DecodeSettings;
    use slf_host::sim::scene::SceneSize;
    let lenslets = [30, 30];
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 30, cols: 30 });
    let mut cam = CameraConfig::pixel(5, 2).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 1.0, pitch: Some([5.1, 5.1]), offset: None });
    let cap = simulate(&lf, &cam).unwrap();
    let g = cap.description.lenslet_grid.unwrap();
    let (rows, cols) = cap.frame_size();
    let mut lit = cap.clone();
    let mut changed = 0;
    for frame in lit.held_frames_mut().unwrap() {
        for (p, x) in frame.iter_mut().enumerate() {
            if outside_array(&g, lenslets, (p / cols, p % cols)) == Some(true) {
                *x = 3000;
                changed += 1;
            }
        }
    }
    assert!(changed > 100, "{changed} pixels outside");
    let s = DecodeSettings::from_flags(["--disparities", "0:0", "--stride", "5"]).unwrap();
    let decode = |c| {
        let run = s.run(c, false, &|_, _| {}).unwrap();
        let slf_host::decode::pipeline::Outcome::Cs { report, .. } = run.outcome else { panic!("not a CS decode") };
        (report, run.light_field)
    };
    let ((a, lf_a), (b, lf_b)) = (decode(&cap), decode(&lit));
    assert_eq!(a.gains, b.gains, "the grey world saw the pixels outside the array");
    assert!(lf_a.data == lf_b.data, "the light field moved");

    // Lenslets past the sensor, against the f64 reference.
    let (sin, cos) = g.rotation_deg.to_radians().sin_cos();
    let mut want = vec![1.0f32; lenslets[0] * lenslets[1]];
    for s in 0..lenslets[0] {
        for t in 0..lenslets[1] {
            let mut on = 0;
            for u in 0..5 {
                for v in 0..5 {
                    let (da, db) = (
                        (s as f64 + (u as f64 + 0.5) / 5.0 - 0.5) * g.pitch[0],
                        (t as f64 + (v as f64 + 0.5) / 5.0 - 0.5) * g.pitch[1],
                    );
                    let (y, x) = (g.offset[0] + da * cos + db * sin, g.offset[1] + db * cos - da * sin);
                    on += usize::from(y >= 0.0 && x >= 0.0 && y < rows as f64 && x < cols as f64);
                }
            }
            want[s * lenslets[1] + t] = on as f32 / 25.0;
        }
    }
    let got = a.off_sensor.coverage(lenslets);
    assert!(want.iter().filter(|&&w| w < 1.0).count() > 10, "the grid keeps its corners on the sensor");
    assert_eq!(got, want);
    assert_eq!(a.off_sensor.lenslets, want.iter().filter(|&&w| w < 1.0).count());
    let error = vec![0.01f32; lenslets[0] * lenslets[1]];
    let left = a.off_sensor.left_out(&error, lenslets[1]);
    assert!(
        left.iter().zip(&want).all(|(e, &w)| e.is_nan() == (w < 1.0)),
        "left out: not the lenslets past the sensor"
    );
}

/// The truth as a frame's first decode would give it (sensor units): a patch's values and
/// each cell's, from the light field (a lenslet past the sensor has none).
struct TruthSeed<'a>(&'a LightField);

impl TruthSeed<'_> {
    fn value(&self, (y, x): (isize, isize), (u, v): (usize, usize), b: usize) -> Option<f32> {
        let l = self.0;
        let (y, x) =
            (usize::try_from(y).ok().filter(|&y| y < l.rows)?, usize::try_from(x).ok().filter(|&x| x < l.cols)?);
        l.data.get((((u * l.views.1 + v) * l.rows + y) * l.cols + x) * l.bands + b).copied()
    }
}

impl slf_firmware::PatchSeed<FullViewShape> for TruthSeed<'_> {
    fn seed(&mut self, o: slf_firmware::PatchOrigin, patch: &mut [f32; 8125]) -> bool {
        use slf_firmware::Shape;
        for (s, t, u, v) in
            (0..5).flat_map(|s| (0..5).flat_map(move |t| (0..5).flat_map(move |u| (0..5).map(move |v| (s, t, u, v)))))
        {
            let Some(l) = o.lenslet::<FullViewShape>(s, t, u, v, (5, 5)) else { continue };
            for b in 0..13 {
                let view = (o.view_row as usize + u, o.view_col as usize + v);
                patch[FullViewShape::pixel_index(s, t, u, v) + b] = self.value(l, view, b).unwrap_or(0.0);
            }
        }
        true
    }

    fn cell(&mut self, (y, x): (usize, usize), view: (usize, usize), band: usize) -> Option<f32> {
        self.value((y as isize, x as isize), view, band)
    }
}

/// Behind a turned grid a full-view patch with a seed takes each pixel's shares of the
/// cells outside the patch out of its measurement by the seed (`CellShares::known_outside`),
/// unsheared (its rim) or sheared (a whole view ring across a micro-image border). Seeded
/// with the truth, on a noiseless capture, what is left of every measurement is the model
/// (`shares::to_sensor`: the shares of the patch's own cells) applied to the truth, to the
/// 16-bit frame's rounding and the turn the decoder's box leaves out; read without a seed
/// (the share of a cell outside given to the pixel's own) the rim's measurements are off
/// the model by far more, and a sheared patch leaves out the pixels mostly outside it. A
/// seeded read leaves out the pixels more than half outside (`MAX_SEEDED_OUTSIDE_SHARE`):
/// unsheared, only a corner view of a corner lenslet can be (a pixel's centre lies in its
/// cell, so it overhangs less than half along each axis, and an unsheared patch's cells
/// outside lie past its rim), at most 4 pixels of `k` measurements each.
#[test]
fn seeded_behind_a_grid_a_patch_takes_the_cells_outside_it_out_of_its_measurements() {
    use slf_firmware::{Disparity, FrameSource, FullViewWorkspace, PatchOrigin, PatchSeed, Shape};
    use slf_host::sim::scene::SceneSize;
    let lf = slf_host::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 24, cols: 24 });
    let mut cam = CameraConfig::pixel(5, 3).noiseless();
    cam.grid = Some(GridSettings { rotation_deg: 0.3, pitch: Some([5.04, 5.04]), offset: None });
    let cap = simulate(&lf, &cam).unwrap();
    let dec = cap.decoder::<5, 5, 8125>(slf_firmware::Sl0Config::DEFAULT).unwrap();
    let raw = cap.raw_frames().unwrap();
    let gains: Vec<f32> = dec.gains().to_vec();
    let mut ws = Box::new(FullViewWorkspace::new());
    // The largest gap between a measurement and the model applied to the truth, over the
    // brightest measurement, with the read seeded by the truth or not.
    let mut gap = |o: PatchOrigin, seeded: bool| {
        let mut src = FrameSource::new(&raw);
        let mut truth = TruthSeed(&lf);
        dec.read_patch_seeded(o, &mut src, &mut ws, seeded.then_some(&mut truth)).unwrap();
        let m = ws.measurements();
        assert_eq!(m.shares().map(|c| c.known_outside), Some(seeded), "{o:?}");
        let mut patch = Box::new([0.0f32; 8125]);
        TruthSeed(&lf).seed(o, &mut patch);
        for (i, x) in patch.iter_mut().enumerate() {
            *x /= gains[i % 13];
        }
        let mut scratch = Box::new([0.0f32; 8125]);
        slf_firmware::shares::to_sensor::<FullViewShape>(m, &mut patch, &mut scratch);
        let (mut worst, mut peak, mut count) = (0.0f32, 0.0f32, 0);
        for e in 0..FullViewShape::N {
            if let Some(y) = m.get(e) {
                worst = worst.max((y - patch[e]).abs());
                peak = peak.max(y.abs());
                count += 1;
            }
        }
        assert!(count > 800, "{o:?}: {count} measurements");
        (worst / peak, count)
    };
    for (row, col, d) in [(5u16, 5u16, 0i8), (10, 5, 0), (5, 10, -1), (10, 10, 1)] {
        let o = PatchOrigin {
            lenslet_row: row,
            lenslet_col: col,
            view_row: 0,
            view_col: 0,
            disparity: Disparity::pixels(d),
        };
        let ((known, kept), (own, own_kept)) = (gap(o, true), gap(o, false));
        eprintln!("{o:?}: seeded {known:.2e} ({kept} measurements), own cell {own:.2e} ({own_kept})");
        assert!(known < 5e-3, "{o:?}: seeded, a measurement {known:.2e} of the brightest off the model");
        if d == 0 {
            // Every pixel read unseeded; seeded, all but a few corners: the rim's shares
            // outside are the gap.
            assert!(kept <= own_kept && own_kept - kept <= 4 * 3, "{o:?}: {kept} measurements seeded, {own_kept} not");
            assert!(own > 20.0 * known, "{o:?}: own-cell rule {own:.2e}, seeded {known:.2e}");
        } else {
            // Unseeded, a sheared patch leaves out the pixels mostly outside it
            // (`MAX_OUTSIDE_SHARE`); seeded, only those past half outside: the corner
            // views of every lenslet reach outside along both axes, and on this turned
            // grid some of them past half.
            assert!(kept < 625 * 3, "{o:?}: seeded, every pixel kept");
            assert!(kept > own_kept, "{o:?}: {kept} measurements seeded, {own_kept} not");
        }
    }
}
