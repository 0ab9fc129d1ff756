//! Scenes and spectra: deterministic, correct parallax and occlusion, spectra as published.

use slf_host::eval::preview::{linear_srgb, xyz};
use slf_host::sim::scene::{self, Layer, Scene, SceneSize, Shape, Texture};
use slf_host::sim::spectra::{BAND_NM, CMF_1931, COLORCHECKER, D65, colorchecker, narrow_band, under_d65};

const SIZE: SceneSize = SceneSize { views: (5, 5), rows: 40, cols: 40 };

#[test]
fn scenes_are_deterministic_and_distinct() {
    for name in scene::NAMES {
        let a = scene::named(name).unwrap().render(SIZE);
        assert_eq!(a, scene::named(name).unwrap().render(SIZE), "{name}");
        assert!(a.data.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1.0), "{name}");
    }
    assert_eq!(scene::random(9).render(SIZE), scene::random(9).render(SIZE));
    assert_ne!(scene::random(9).render(SIZE), scene::random(10).render(SIZE));
    assert!(scene::named("nope").is_none());
    // Dark is the depth scene at low exposure.
    let (d, l) = (scene::named("dark").unwrap().render(SIZE), scene::named("depth").unwrap().render(SIZE));
    assert!(d.max() < 0.05 * l.max() + 1e-6 && d.max() > 0.0);
}

/// A flat card at disparity 1 in front of a flat background at disparity -1.
fn two_cards() -> Scene {
    let white = colorchecker("white 9.5 (.05 D)").unwrap();
    let red = colorchecker("red").unwrap();
    Scene {
        name: "cards".into(),
        layers: vec![
            Layer::flat(-1.0, Shape::Everywhere, Texture::Flat, [white, white]),
            Layer::flat(1.0, Shape::Rect { y0: 0.4, x0: 0.4, y1: 0.6, x1: 0.6 }, Texture::Flat, [red, red]),
        ],
        gain: 1.0,
        illuminant: D65,
    }
}

#[test]
fn parallax_and_occlusion_follow_disparity() {
    let lf = two_cards().render(SIZE);
    let red = under_d65(&colorchecker("red").unwrap());
    let is_red =
        |u, v, y, x| (lf.get(u, v, y, x, 12) - red[12]).abs() < 1e-6 && (lf.get(u, v, y, x, 2) - red[2]).abs() < 1e-6;
    // Central view: the card covers pixels 16..24.
    assert!(is_red(2, 2, 16, 16) && is_red(2, 2, 23, 23) && !is_red(2, 2, 15, 20) && !is_red(2, 2, 24, 20));
    // View (2, 4) is two view steps right: the card (disparity 1) sees x + 2, so it appears
    // two pixels to the left; view (0, 2) sees y - 2, so it appears two pixels lower.
    assert!(is_red(2, 4, 20, 14) && !is_red(2, 4, 20, 22));
    assert!(is_red(0, 2, 25, 20) && !is_red(0, 2, 17, 20));
    // The card hides the background in every view (occlusion), and nothing else is red.
    for u in 0..5 {
        for v in 0..5 {
            let n = (0..40 * 40).filter(|p| is_red(u, v, p / 40, p % 40)).count();
            assert_eq!(n, 64, "view ({u}, {v})");
        }
    }
}

#[test]
fn spectra_tables_are_the_published_ones() {
    assert_eq!(BAND_NM[0], 400.0);
    assert_eq!(BAND_NM[12], 700.0);
    // D65 near 560 nm is ~100 by definition; its visible maximum is in the blue.
    assert!((D65[6] - 104.0).abs() < 1.0, "{}", D65[6]);
    let max = D65.iter().position(|&x| x == D65.iter().fold(0.0f32, |m, &y| m.max(y))).unwrap();
    assert_eq!(BAND_NM[max], 450.0);
    // y-bar peaks at 555 nm: the 550 nm sample is the largest, ~0.995.
    assert!((CMF_1931[6][1] - 0.995).abs() < 0.001);
    assert_eq!(COLORCHECKER.len(), 24);
    // The white patch reflects ~90 % from 425 nm on (it falls to ~42 % at 400 nm in the
    // measured data), the black ~3 %; red reflects long wavelengths.
    let w = colorchecker("white 9.5 (.05 D)").unwrap();
    assert!(w[1..].iter().all(|&x| (0.8..0.95).contains(&x)), "{w:?}");
    assert!(colorchecker("black 2 (1.5 D)").unwrap().iter().all(|&x| x < 0.05));
    let r = colorchecker("red").unwrap();
    assert!(r[12] > 4.0 * r[4]);
    // A narrow line peaks at its centre band.
    let n = narrow_band(550.0, 10.0);
    assert_eq!(n.iter().position(|&x| x == n.iter().fold(0.0f32, |m, &y| m.max(y))), Some(6));
}

#[test]
fn white_under_d65_is_white_in_srgb() {
    // A perfect reflector: Y = 1 and linear sRGB (1, 1, 1) within the error of 13 bands.
    let white = under_d65(&[1.0; 13]);
    let c = xyz(&white);
    assert!((c[1] - 1.0).abs() < 1e-6, "{c:?}");
    let rgb = linear_srgb(c);
    assert!(rgb.iter().all(|&x| (x - 1.0).abs() < 0.03), "{rgb:?}");
    // The ColorChecker red is red.
    let rgb = linear_srgb(xyz(&under_d65(&colorchecker("red").unwrap())));
    assert!(rgb[0] > 3.0 * rgb[1] && rgb[0] > 3.0 * rgb[2], "{rgb:?}");
}

#[test]
fn measured_sets_and_illuminants_are_as_published() {
    use slf_host::sim::spectra::{ILLUMINANTS, MEASURED, illuminant};
    // Four colour checkers (24, 24, 24, 30), CIE TCS (14 + 15), NIST CQS (15), RAW to ACES (190).
    assert_eq!(MEASURED.len(), 24 * 3 + 30 + 14 + 15 + 15 + 190);
    let sets: std::collections::BTreeSet<&str> = MEASURED.iter().map(|m| m.0).collect();
    assert_eq!(sets.len(), 8, "{sets:?}");
    assert!(MEASURED.iter().all(|m| m.2.iter().all(|&x| (0.0..=1.0).contains(&x))));
    // The BabelColor entries are the ColorChecker table the test scenes use.
    for (name, r) in COLORCHECKER {
        assert!(MEASURED.iter().any(|m| m.0 == "BabelColor Average" && m.1 == name && m.2 == r), "{name}");
    }
    for (name, p) in ILLUMINANTS {
        assert_eq!(p.iter().fold(0.0f32, |m, &x| m.max(x)), 1.0, "{name}");
    }
    // A (a 2856 K black body) rises through the visible; FL11's terbium line (545 nm) is
    // its peak; LED-B3's blue pump shows as a peak at 450 nm; D65 is flat to within 40 %.
    let a = illuminant("A").unwrap();
    assert!(a.windows(2).all(|w| w[1] > w[0]));
    let fl11 = illuminant("FL11").unwrap();
    assert_eq!(fl11.iter().position(|&x| x == 1.0), Some(6), "{fl11:?}");
    let led = illuminant("LED-B3").unwrap();
    assert!(led[2] > led[1] && led[2] > led[3]);
    let d65 = illuminant("D65").unwrap();
    assert!(d65.iter().all(|&x| x > 0.6));
    assert!(illuminant("nope").is_none());
}

#[test]
fn realistic_scenes_are_deterministic_distinct_and_in_range() {
    use slf_host::sim::realistic::{NAMES, lookup, realistic};
    for name in NAMES {
        let a = lookup(name).unwrap().render(SIZE);
        assert_eq!(a, lookup(name).unwrap().render(SIZE), "{name}");
        assert!(a.data.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1.0), "{name}: max {}", a.max());
        assert!(a.max() > 0.1, "{name}");
    }
    assert_eq!(realistic(3).render(SIZE), realistic(3).render(SIZE));
    assert_ne!(realistic(3).render(SIZE), realistic(4).render(SIZE));
    // The test scenes are found by the same lookup, unchanged.
    assert_eq!(lookup("depth").unwrap(), scene::named("depth").unwrap());
    // Many draws: all in range, and they use more than one illuminant.
    let lights: std::collections::BTreeSet<String> =
        (0..12).map(|s| format!("{:?}", realistic(s).illuminant)).collect();
    assert!(lights.len() >= 3, "{}", lights.len());
}

/// Phase (radians) of the DFT of `row` at `cycles` per row length.
fn phase(row: &[f64], cycles: f64) -> f64 {
    let n = row.len() as f64;
    let (re, im) = row.iter().enumerate().fold((0.0, 0.0), |(re, im), (i, &x)| {
        let a = std::f64::consts::TAU * cycles * i as f64 / n;
        (re + x * a.cos(), im - x * a.sin())
    });
    im.atan2(re)
}

#[test]
fn a_slanted_plane_has_continuous_disparity() {
    // Vertical stripes of period 8 on a plane whose disparity runs from -0.5 at the top to
    // +1.5 at the bottom. View (2, 4), two steps right, sees x + 2 d(y): its stripes sit
    // 2 d(y) pixels left of the central view's, row by row.
    let white = colorchecker("white 9.5 (.05 D)").unwrap();
    let black = colorchecker("black 2 (1.5 D)").unwrap();
    let plane = Layer {
        slope: (2.0, 0.0),
        ..Layer::flat(0.5, Shape::Everywhere, Texture::Stripes { period: 8.0, angle: 0.0 }, [black, white])
    };
    let s = Scene { name: "plane".into(), layers: vec![plane], gain: 1.0, illuminant: D65 };
    let lf = s.render(SIZE);
    for y in 0..40 {
        let row = |v: usize| (0..40).map(|x| f64::from(lf.get(2, v, y, x, 6))).collect::<Vec<_>>();
        let dphi = (phase(&row(4), 5.0) - phase(&row(2), 5.0) + 3.0 * std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        // f4(x) = f2(x + s): the phase at frequency w advances by w s.
        let shift = dphi * 8.0 / std::f64::consts::TAU;
        let d = 0.5 + 2.0 * ((y as f64 + 0.5) / 40.0 - 0.5);
        assert!((shift - 2.0 * d).abs() < 0.08, "row {y}: shift {shift:.3}, expected {:.3}", 2.0 * d);
    }
}

#[test]
fn a_highlight_moves_across_views_unlike_its_surface() {
    use slf_host::sim::scene::Highlight;
    let grey = colorchecker("neutral 5 (.70 D)").unwrap();
    let card = Layer {
        highlight: Some(Highlight { cy: 0.5, cx: 0.5, radius: 0.05, strength: 0.5, shift: 1.5 }),
        ..Layer::flat(0.0, Shape::Everywhere, Texture::Flat, [grey, grey])
    };
    let s = Scene { name: "card".into(), layers: vec![card], gain: 1.0, illuminant: D65 };
    let lf = s.render(SIZE);
    // The surface is at disparity 0 (the same in every view); the highlight's peak moves
    // 1.5 pixels per view step: 3 pixels right in view (2, 4).
    let peak = |v: usize| {
        let row: Vec<f32> = (0..40).map(|x| lf.get(2, v, 20, x, 6)).collect();
        let (w, c): (f64, f64) = row.iter().enumerate().fold((0.0, 0.0), |(w, c), (x, &r)| {
            let e = f64::from(r - row[0]).max(0.0);
            (w + e, c + e * (x as f64 + 0.5))
        });
        c / w
    };
    let (p2, p4) = (peak(2), peak(4));
    assert!((p2 - 20.0).abs() < 0.1, "{p2}");
    assert!((p4 - p2 - 3.0).abs() < 0.1, "{p2} {p4}");
    assert_eq!(lf.get(2, 2, 2, 2, 6), lf.get(2, 4, 2, 2, 6), "away from it, the surface is the same");
}

/// Mean DFT magnitude of a Hann-windowed 64 x 64 window of `texture` on rings of radius
/// `r` cycles per window.
fn ring_amplitude(texture: &Texture, r: f64) -> f64 {
    let n = 64usize;
    let hann = |i: usize| 0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / n as f64).cos();
    let mut total = 0.0;
    let mut count = 0.0;
    for (oy, ox) in [(0.0, 0.0), (300.0, 0.0), (0.0, 500.0), (700.0, 900.0)] {
        let w: Vec<f64> = (0..n * n)
            .map(|i| {
                let (y, x) = (i / n, i % n);
                f64::from(texture.weight(oy + y as f32, ox + x as f32)) * hann(y) * hann(x)
            })
            .collect();
        for k in 0..16 {
            let a = std::f64::consts::TAU * k as f64 / 16.0;
            let (fy, fx) = (r * a.sin(), r * a.cos());
            let (re, im) = w.iter().enumerate().fold((0.0, 0.0), |(re, im), (i, &v)| {
                let ph = std::f64::consts::TAU * (fy * (i / n) as f64 + fx * (i % n) as f64) / n as f64;
                (re + v * ph.cos(), im - v * ph.sin())
            });
            total += (re * re + im * im).sqrt();
            count += 1.0;
        }
    }
    total / count
}

#[test]
fn pink_texture_falls_as_one_over_f() {
    // Slope of log amplitude against log frequency from 2 to 16 cycles per 64 pixels
    // (periods 32 to 4 pixels): -beta for a 1/f^beta field, within 0.35 (value noise is
    // smooth within an octave, and a 64-pixel window holds few of the coarsest).
    let slope = |beta: f32| {
        let t = Texture::Pink { seed: 11, beta };
        let (lo, hi) = (ring_amplitude(&t, 2.0), ring_amplitude(&t, 16.0));
        (hi / lo).ln() / 8f64.ln()
    };
    let (s08, s10, s13) = (slope(0.8), slope(1.0), slope(1.3));
    println!("slopes: beta 0.8 {s08:.2}, 1.0 {s10:.2}, 1.3 {s13:.2}");
    assert!((s10 + 1.0).abs() < 0.35, "beta 1: slope {s10:.2}");
    assert!(s13 < s10 && s10 < s08, "{s08:.2} {s10:.2} {s13:.2}");
}

/// Mean spectral angle (degrees) between horizontally neighbouring pixels of view (u, v).
fn neighbour_angle(lf: &slf_host::io::lightfield::LightField, u: usize, v: usize) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for y in 0..lf.rows {
        for x in 0..lf.cols - 1 {
            let (a, b) = (lf.spectrum(u, v, y, x), lf.spectrum(u, v, y, x + 1));
            let dot: f64 = a.iter().zip(b).map(|(p, q)| f64::from(*p) * f64::from(*q)).sum();
            let na: f64 = a.iter().map(|p| f64::from(*p).powi(2)).sum::<f64>().sqrt();
            let nb: f64 = b.iter().map(|p| f64::from(*p).powi(2)).sum::<f64>().sqrt();
            sum += (dot / (na * nb).max(1e-12)).clamp(-1.0, 1.0).acos().to_degrees();
            n += 1;
        }
    }
    sum / n as f64
}

/// The hard-case set (issue 42): each scene is what its name says it is.
#[test]
fn hard_cases_are_what_they_are_named() {
    use slf_host::sim::{hard, realistic};
    for name in hard::NAMES {
        let a = hard::named(name).unwrap().render(SIZE);
        assert_eq!(a, hard::named(name).unwrap().render(SIZE), "{name}: deterministic");
        assert!(a.data.iter().all(|x| x.is_finite() && *x >= 0.0) && a.max() > 0.0, "{name}");
        assert_eq!(hard::by_name(name, 0).unwrap(), hard::named(name).unwrap());
    }
    assert!(hard::by_name("nope", 0).unwrap_err().to_string().contains("or a hard case"));
    let render = |n: &str| hard::named(n).unwrap().render(SIZE);
    // Materials at the lenslet scale: neighbouring pixels' spectra far apart (a smooth
    // realistic scene's are a few degrees).
    let smooth = neighbour_angle(&realistic::named("outdoor").unwrap().render(SIZE), 2, 2);
    let (one, two, field) = (render("mosaic"), render("mosaic-2"), render("field"));
    assert!(neighbour_angle(&one, 2, 2) > 20.0 && neighbour_angle(&one, 2, 2) > 4.0 * smooth, "{smooth}");
    assert!(neighbour_angle(&two, 2, 2) > 10.0 && neighbour_angle(&field, 2, 2) > 5.0);
    // The mosaic's plane is at 0.3 pixels per view: the centre view's pixel x is the view
    // one step right's, 0.3 pixels on (each pixel is the mean of four samples, so a
    // 0.3-pixel shift of one-pixel cells mixes a pixel with its neighbour: not equal).
    assert_ne!(one.spectrum(2, 2, 10, 10), one.spectrum(2, 3, 10, 10));
    // Dim is the outdoor scene at 3 % of its exposure.
    let (dim, outdoor) = (render("dim"), realistic::named("outdoor").unwrap().render(SIZE));
    for (d, o) in dim.data.iter().zip(&outdoor.data) {
        assert!((d - 0.03 * o).abs() <= 1e-6 + 1e-5 * o, "{d} vs {o}");
    }
    // The dim canopy is the canopy at 10 % of its exposure; half its cells nearly black.
    let (dim, canopy) = (render("canopy-dim"), render("canopy"));
    for (d, c) in dim.data.iter().zip(&canopy.data) {
        assert!((d - 0.1 * c).abs() <= 1e-6 + 1e-5 * c, "{d} vs {c}");
    }
    let dark = canopy.data.chunks(13).filter(|s| s.iter().all(|&x| x < 0.04)).count();
    assert!(dark * 4 > canopy.data.len() / 13 && canopy.max() > 0.5, "{dark} dark pixels");
    // Narrow light: most of the energy in the three lines' bands.
    let narrow = render("narrow");
    let line: f64 = narrow.data.chunks(13).map(|s| f64::from(s[2] + s[5] + s[9])).sum();
    let all: f64 = narrow.data.iter().map(|&x| f64::from(x)).sum();
    assert!(line > 0.8 * all, "{line} of {all}");
    // Speculars exceed white (they saturate the sensor), print does not.
    assert!(render("speculars").max() > 1.5 && render("print").max() < 1.0);
}
