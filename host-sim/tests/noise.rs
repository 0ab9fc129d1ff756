//! The sensor's noise in the decoder's model, and the physical range of its output: the
//! noise ball comes from the capture's description unless told otherwise, a capture
//! without one decodes exactly, and every decoded value lies in `[0, top]`.

use slf_host::decode::cs::{Basis, DecodeOptions, NoiseSource, decode_with};
use slf_host::firmware::Sl0Config;
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};

mod common;

fn decode(cap: &Capture, opts: &DecodeOptions) -> LightField {
    decode_with(cap, &Basis::Dct, opts).unwrap().0
}

fn exact() -> DecodeOptions {
    DecodeOptions { noise: NoiseSource::Config, ..DecodeOptions::default() }
}

#[test]
fn the_noise_model_is_the_sensors_in_normalised_units() {
    let lf = common::small_smooth(4);
    let cap = simulate(&lf, &CameraConfig::pixel(1, 1)).unwrap();
    let d = &cap.description;
    // The default sensor by hand: 12 bits, black 64, white at 90 % of the range above it,
    // 2 DN read noise, 20,000 electrons at white.
    assert_eq!((d.bits, d.black_level), (12, 64.0));
    let range = 0.9 * (4095.0 - 64.0);
    assert!((f64::from(d.white_level - d.black_level) - range).abs() < 1e-3);
    let (noise, shot) = cap.noise_model().unwrap();
    let floor = (4.0f64 + 1.0 / 12.0).sqrt() / range; // read^2 + quantisation, DN
    assert!((f64::from(noise) - floor).abs() <= 1e-6 * floor, "noise {noise} vs {floor}");
    assert!((f64::from(shot) - 5e-5).abs() <= 1e-6 * 5e-5, "shot {shot}");
    assert_eq!(simulate(&lf, &CameraConfig::pixel(1, 1).noiseless()).unwrap().noise_model(), None);
}

#[test]
fn a_capture_without_a_noise_description_decodes_exactly_by_default() {
    let lf = common::small_smooth(4);
    for k in [1u8, 3] {
        let cap = simulate(&lf, &CameraConfig::pixel(2, k).noiseless()).unwrap();
        assert!(cap.description.noise.is_none());
        let by_default = decode(&cap, &DecodeOptions::default());
        assert_eq!(by_default.data, decode(&cap, &exact()).data, "k {k}: default is not the exact projection");
    }
}

#[test]
fn a_described_capture_decodes_with_its_noise_ball_by_default() {
    let lf = common::small_smooth(4);
    for k in [1u8, 3] {
        let cap = simulate(&lf, &CameraConfig::pixel(2, k)).unwrap();
        let (noise, shot) = cap.noise_model().unwrap();
        let by_default = decode(&cap, &DecodeOptions::default());
        let given = DecodeOptions { sl0: Sl0Config { noise, shot, ..Sl0Config::DEFAULT }, ..exact() };
        assert_eq!(by_default.data, decode(&cap, &given).data, "k {k}: not the capture's ball");
        assert_ne!(by_default.data, decode(&cap, &exact()).data, "k {k}: the ball changed nothing");
    }
}

/// A dark scene under heavy read noise (samples below the black level) and white noise up
/// to just under the sensor's top (no sparse model fits it, so the solve swings past both
/// ends of the range where nothing is measured): every decoded value
/// lies in `[0, top]`, with `top = (saturation - 0.5 - black) / (white - black)` in
/// normalised units, and the clamp bites (values at 0 and at `top` exactly).
#[test]
fn decoded_values_stay_in_the_physical_range() {
    let lf = common::small_smooth(4);
    let dim = LightField { data: lf.data.iter().map(|x| x * 0.01).collect(), ..lf.clone() };
    // A fixed hash of the coordinates, uniform in [0, 1.1).
    let hash = |u: usize, v: usize, y: usize, x: usize, b: usize| {
        let h = (((u * 7 + v) * 131 + y) * 137 + x) * 17 + b;
        let h = (h as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
        (h as f32 / (1u64 << 24) as f32) * 1.1
    };
    let white = LightField::from_fn((4, 4), 12, 12, 13, hash);
    let mut dark = CameraConfig::pixel(4, 3);
    dark.read_noise = 30.0;
    for (name, scene, cam, bites_at) in
        [("dark", dim, dark, 0.0f32), ("white noise", white, CameraConfig::pixel(4, 3).noiseless(), 1.0)]
    {
        let cap = simulate(&scene, &cam).unwrap();
        let d = &cap.description;
        let top = (d.saturation_level - 0.5 - d.black_level) / (d.white_level - d.black_level);
        for opts in [DecodeOptions::default(), exact()] {
            let out = decode(&cap, &opts);
            let (lo, hi) = out.data.iter().fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            assert!(lo >= 0.0 && hi <= top, "{name}: output in [{lo}, {hi}], outside [0, {top}]");
            let at = if bites_at == 0.0 { 0.0 } else { top };
            assert!(out.data.contains(&at), "{name}: no value at {at} (range [{lo}, {hi}]): the clamp never bit");
        }
    }
}
