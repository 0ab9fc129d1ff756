//! Scenes and spectra: deterministic, correct parallax and occlusion, spectra as published.

use slf_host::preview::{linear_srgb, xyz};
use slf_host::scene::{self, Layer, Scene, SceneSize, Shape, Texture};
use slf_host::spectra::{BAND_NM, CMF_1931, COLORCHECKER, D65, colorchecker, narrow_band, under_d65};

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
            Layer { disparity: -1.0, shape: Shape::Everywhere, texture: Texture::Flat, reflectance: [white, white] },
            Layer {
                disparity: 1.0,
                shape: Shape::Rect { y0: 0.4, x0: 0.4, y1: 0.6, x1: 0.6 },
                texture: Texture::Flat,
                reflectance: [red, red],
            },
        ],
        gain: 1.0,
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
