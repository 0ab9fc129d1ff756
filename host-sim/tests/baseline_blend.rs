//! The baseline blend on a kronecker mask ([`slf_host::decode::blend`]): each block's values
//! mixed from the decode and PPID by their held-out errors. Checked against the slow obvious
//! route: each fold's samples made saturated in a copy of the capture (not measurements, to
//! the decoder and to PPID), the copies decoded and PPIDed by the public API, the errors at
//! those samples summed in f64 per block, the rule applied by hand; and for what it must
//! leave alone (the pixel mask's decode).

use slf_host::decode::baselines::{PpidConfig, ppid};
use slf_host::decode::cs::{Balance, Basis, DecodeOptions, decode_with};
use slf_host::decode::held_out::LEVEL;
use slf_host::firmware::Plausibility;
use slf_host::io::capture::{Capture, MaskDescription};
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{SceneSize, named};

mod common;

/// The decode the slow route can make again from a copy: no white balance from the
/// samples and no plausibility check (a saturated sample skips it, a hidden one does not).
fn blending() -> DecodeOptions {
    DecodeOptions {
        balance: Balance::Off,
        plausibility: Plausibility::OFF,
        baseline_blend: true,
        error_estimate: true,
        ..DecodeOptions::default()
    }
}

fn kronecker(lf: &LightField, k: u8) -> Capture {
    let cfg = CameraConfig {
        mask: MaskDescription::Kronecker { snapshots: k, seed: 1, block: [5, 5] },
        ..CameraConfig::pixel(1, k)
    };
    simulate(lf, &cfg).unwrap()
}

/// Whether fold `fold` hides sample `(r, c)` of `snapshot`: a block of 5 x 5 lenslets'
/// every pixel, in the snapshot `(snapshot + block row + 2 block column) % 3` names.
fn hides(fold: usize, snapshot: usize, (r, c): (usize, usize), views: (usize, usize)) -> bool {
    (snapshot + r / (5 * views.0) + 2 * (c / (5 * views.1))) % 3 == fold
}

/// Per lenslet, by hand: (the decode's squared errors, PPID's, their products, held-out
/// samples, noise variance, valid samples) at each fold's hidden samples.
fn slow_tallies(cap: &Capture, opts: &DecodeOptions) -> Vec<[f64; 6]> {
    let d = &cap.description;
    let (rows, cols) = cap.frame_size();
    let (lu, lv) = (d.views[0], d.views[1]);
    let lc = d.lenslets[1];
    let mask = cap.mask().unwrap();
    let (noise, shot) = cap.noise_model().map_or((0.0, 0.0), |(n, s)| (f64::from(n), f64::from(s)));
    let (black, white) = (f64::from(d.black_level), f64::from(d.white_level));
    let top = (f64::from(d.saturation_level) - 0.5 - black) / (white - black);
    let plain = DecodeOptions { baseline_blend: false, error_estimate: false, ..*opts };
    let mut t = vec![[0.0f64; 6]; d.lenslets[0] * lc];
    for fold in 0..3 {
        let mut frames = cap.held_frames().unwrap().into_owned();
        for (j, f) in frames.iter_mut().enumerate() {
            for r in 0..rows {
                for c in 0..cols {
                    if hides(fold, j, (r, c), (lu, lv)) {
                        f[r * cols + c] = u16::MAX;
                    }
                }
            }
        }
        let hidden = Capture::new(d.clone(), frames).unwrap();
        let decoded = decode_with(&hidden, &Basis::Dct, &plain).unwrap().0;
        let baseline = ppid(&hidden, &PpidConfig::default()).unwrap().0;
        for r in 0..rows {
            for c in 0..cols {
                let (y, x, u, v) = (r / lu, c / lv, r % lu, c % lv);
                let slot = &mut t[y * lc + x];
                for (j, &band) in mask.bands_at(r, c).iter().enumerate() {
                    let raw = f64::from(cap.held_frames().unwrap()[j][r * cols + c]);
                    let over = raw > f64::from(d.saturation_level) - 0.5;
                    if fold == 0 && !over {
                        slot[5] += 1.0;
                    }
                    if !hides(fold, j, (r, c), (lu, lv)) {
                        continue;
                    }
                    let at = decoded.index(u, v, y, x, usize::from(band));
                    let (a, b) = (f64::from(decoded.data[at]), f64::from(baseline.data[at]));
                    let seen = (raw - black) / (white - black);
                    let (ea, eb) = if over { ((top - a).max(0.0), (top - b).max(0.0)) } else { (a - seen, b - seen) };
                    if !over {
                        slot[4] += noise * noise + shot * seen.max(0.0);
                    }
                    slot[0] += ea * ea;
                    slot[1] += eb * eb;
                    slot[2] += ea * eb;
                    slot[3] += 1.0;
                }
            }
        }
    }
    t
}

#[test]
fn the_blend_mixes_each_block_by_the_errors_at_the_samples_each_fold_hid() {
    // A foliage scene (where PPID predicts better in places) and a smooth one, 3 x 3 blocks.
    for name in ["canopy", "smooth"] {
        let scene = slf_host::sim::hard::named(name).or_else(|| named(name)).unwrap();
        let lf = scene.render(SceneSize { views: (5, 5), rows: 15, cols: 15 });
        let cap = kronecker(&lf, 3);
        let opts = blending();
        let (out, report) = decode_with(&cap, &Basis::Dct, &opts).unwrap();
        let blend = report.blend.clone().expect("a kronecker mask is blended");
        let plain = DecodeOptions { baseline_blend: false, error_estimate: false, ..opts };
        let (decoded, _) = decode_with(&cap, &Basis::Dct, &plain).unwrap();
        let (baseline, _) = ppid(&cap, &PpidConfig::default()).unwrap();

        // The weights by hand: per block of 5 x 5 lenslets, over the 3 x 3 blocks around.
        let t = slow_tallies(&cap, &opts);
        let (n, lc) = (15, 15);
        let mut weights = vec![0.0f64; n * lc];
        for y in 0..n {
            for x in 0..lc {
                let (mut c, mut p) = (0.0, 0.0);
                for yy in 0..n {
                    for xx in 0..lc {
                        if (yy / 5).abs_diff(y / 5) <= 1 && (xx / 5).abs_diff(x / 5) <= 1 {
                            c += t[yy * lc + xx][0];
                            p += t[yy * lc + xx][1];
                        }
                    }
                }
                weights[y * lc + x] = c * c / (c * c + p * p);
            }
        }
        assert_eq!(blend.weights.len(), weights.len());
        for (i, (&fast, &slow)) in blend.weights.iter().zip(&weights).enumerate() {
            assert!((f64::from(fast) - slow).abs() < 1e-4, "{name}, lenslet {i}: weight {fast} against {slow}");
        }
        assert!(weights.iter().any(|&w| w > 0.05), "{name}: PPID never weighed");

        // The output: each value (1 - w) x decode + w x PPID.
        for (i, ((&o, &a), &b)) in out.data.iter().zip(&decoded.data).zip(&baseline.data).enumerate() {
            let (y, x) = ((i / (lc * 13)) % n, (i / 13) % lc);
            let w = f64::from(blend.weights[y * lc + x]);
            let want = (1.0 - w) * f64::from(a) + w * f64::from(b);
            assert!((f64::from(o) - want).abs() < 1e-5, "{name}, value {i}: {o} against {want}");
        }

        // The error map: the blended output's errors at the hidden samples, per lenslet over
        // the 5 x 5 lenslets around it, less the noise (measured values at the lower of that
        // and the noise), scaled by LEVEL.
        for y in 0..n {
            for x in 0..lc {
                let mut s = [0.0f64; 6];
                let mut lenslets = 0.0;
                for yy in y.saturating_sub(2)..(y + 3).min(n) {
                    for xx in x.saturating_sub(2)..(x + 3).min(lc) {
                        let w = f64::from(blend.weights[yy * lc + xx]);
                        let o = t[yy * lc + xx];
                        s[0] += (1.0 - w) * (1.0 - w) * o[0] + w * w * o[1] + 2.0 * w * (1.0 - w) * o[2];
                        for k in 3..6 {
                            s[k] += o[k];
                        }
                        lenslets += 1.0;
                    }
                }
                let measured = (s[5] / lenslets / (25.0 * 13.0)).min(1.0);
                let (r2, var) = (s[0] / s[3], s[4] / s[3]);
                let unmeasured = (r2 - var).max(0.0);
                let slow = LEVEL * (unmeasured * (1.0 - measured) + unmeasured.min(var) * measured).sqrt();
                let fast = f64::from(report.error_lenslets[y * lc + x]);
                assert!(
                    (fast - slow).abs() <= 1e-4 * slow + 1e-7,
                    "{name}, lenslet ({y}, {x}): map {fast} against {slow}"
                );
            }
        }
    }
}

#[test]
fn other_masks_and_the_blend_turned_off_decode_as_before() {
    let lf = common::small_smooth(5);
    let pixel = simulate(&lf, &CameraConfig::pixel(2, 3)).unwrap();
    let on = decode_with(&pixel, &Basis::Dct, &blending()).unwrap();
    let off = decode_with(&pixel, &Basis::Dct, &DecodeOptions { baseline_blend: false, ..blending() }).unwrap();
    assert_eq!(on.0.data, off.0.data, "the pixel mask's decode changed");
    assert!(on.1.blend.is_none());
    let cap = kronecker(&lf, 3);
    let off = decode_with(&cap, &Basis::Dct, &DecodeOptions { baseline_blend: false, ..blending() }).unwrap();
    assert!(off.1.blend.is_none());
}
