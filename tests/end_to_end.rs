//! End to end on the workstation: a named scene -> the camera model (with noise) ->
//! a capture folder on disk -> loaded back -> decoded by the firmware's tile decoder in
//! parallel -> PSNR / SSIM / SA, for each mask family and k in {1, 3}.
//!
//! The DCT on the disjoint grid, with both patches (the paper's 4 x 4-view one in four
//! windows, the full-view one); the floors sit about 1.5 dB below the lower of the two as
//! measured (`cargo test --release -p slf-tests --test end_to_end -- --nocapture`,
//! 2026-11-27), so a regression of that size fails while rounding and thread order (none:
//! tiles merge in order) cannot:
//!
//! | mask | k = 1: 4 / 5 views measured, floor | k = 3: 4 / 5 views measured, floor |
//! | --- | --- | --- |
//! | pixel | 23.25 / 24.14, 21.0 | 30.27 / 32.59, 28.0 |
//! | lenslet | 15.11 / 16.38, 13.0 | 26.25 / 25.01, 23.5 |
//! | kronecker | 10.50 / 10.50, 9.0 | 15.16 / 15.16, 13.5 |
//!
//! The kronecker mask gives every pixel of a patch the same band, so the spectrum of a
//! patch is guessed from k samples (its patches are interpolated: they measure fewer bands
//! than the solve needs): docs/design.md (section 3) predicts the pixel mask is far better
//! at the same 5D cost, and the test holds it to at least 10 dB better at k = 3 with the
//! full-view patch (measured: 17.4 dB).

use slf_host::decode::cs::{Basis, DecodeOptions, PatchDecoder, PatchViews, SolveSchedule, decode_with};
use slf_host::decode::options::Maps;
use slf_host::eval::metrics::evaluate;
use slf_host::firmware::MaskFamily;
use slf_host::io::capture::{Capture, MaskDescription};
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::flags::FromFlags;
use slf_host::sim::scene::{self, SceneSize};

fn mask(family: &str, k: u8) -> MaskDescription {
    let family = match family {
        "pixel" => MaskFamily::Pixel,
        "lenslet" => MaskFamily::Lenslet,
        _ => MaskFamily::Kronecker,
    };
    MaskDescription::seeded(family, 7, k)
}

#[test]
fn scene_to_metrics_for_every_mask_family() {
    let truth = scene::named("depth").unwrap().render(SceneSize { views: (5, 5), rows: 40, cols: 40 });
    let floors = [("pixel", [21.0, 28.0]), ("lenslet", [13.0, 23.5]), ("kronecker", [9.0, 13.5])];
    let mut psnr_k3 = std::collections::HashMap::new();
    for (family, floor) in floors {
        for (i, k) in [1u8, 3].into_iter().enumerate() {
            let cam = CameraConfig::pixel(7, k).with_mask(mask(family, k));
            let dir = tempfile::tempdir().unwrap();
            simulate(&truth, &cam).unwrap().save(dir.path()).unwrap();
            let capture = Capture::load(dir.path()).unwrap();
            // Both patches: the paper's in four angular windows a block, the full-view one in one.
            for (views, windows) in [(PatchViews::Four, 4), (PatchViews::Five, 1)] {
                let opts = DecodeOptions { patch_views: Some(views), ..DecodeOptions::disjoint() };
                let (recon, report) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
                assert_eq!((report.failed_tiles, report.patches.failed, report.uncovered), (0, 0, 0));
                assert_eq!(report.patches.decoded, 8 * 8 * windows, "{views} views: every block, every window");
                let m = evaluate(&truth, &recon).unwrap();
                eprintln!(
                    "{family} k={k}, {views} views: PSNR {:.2} dB, SSIM {:.4}, SA {:.2} deg",
                    m.psnr, m.ssim, m.sa
                );
                assert!(m.psnr >= floor[i], "{family} k={k}, {views} views: PSNR {:.2} below {}", m.psnr, floor[i]);
                assert!(recon.data.iter().all(|x| x.is_finite()));
                if k == 3 && views == PatchViews::Five {
                    psnr_k3.insert(family, m.psnr);
                }
            }
        }
    }
    // The kronecker mask's patches measure k bands each and are interpolated per pixel
    // (measured 10.50 / 15.16 dB): still far below the pixel mask.
    assert!(psnr_k3["pixel"] >= psnr_k3["kronecker"] + 10.0, "{psnr_k3:?}");
    assert!(psnr_k3["pixel"] > psnr_k3["lenslet"], "{psnr_k3:?}");
}

#[test]
fn defects_and_noise_are_survived() {
    // 1 % defective pixels and heavy read noise: every patch still decodes, flagged where a
    // defect fell, and the result stays useful.
    let truth = scene::named("smooth").unwrap().render(SceneSize { views: (5, 5), rows: 20, cols: 20 });
    let mut cam = CameraConfig::pixel(3, 3);
    cam.defect_fraction = 0.01;
    cam.read_noise = 20.0;
    let capture = simulate(&truth, &cam).unwrap();
    let (recon, report) = decode_with(&capture, &Basis::Dct, &DecodeOptions::default()).unwrap();
    assert_eq!(report.patches.failed, 0);
    assert!(report.patches.flagged > 0 && report.patches.flagged <= report.patches.decoded);
    let m = evaluate(&truth, &recon).unwrap();
    assert!(m.psnr > 25.0, "PSNR {:.2}", m.psnr);
}

#[test]
fn the_shipped_ensemble_beats_the_dct() {
    // Pixel mask, k = 3, depth scene at 40 x 40, both with the hand-set schedule: measured
    // (2026-11-27) DCT 38.26 dB, shipped ensemble with screened choice 39.25 dB (+0.99). The
    // margin asserted is half the measured gain: a regression that loses most of the
    // ensemble's advantage fails.
    let truth = scene::named("depth").unwrap().render(SceneSize { views: (5, 5), rows: 40, cols: 40 });
    let capture = simulate(&truth, &CameraConfig::pixel(7, 3)).unwrap();
    // Both with the hand-set schedule: the claim is the basis's (with the trained ones the
    // DCT decodes alone with its own schedule from the band-gain fill and measured 39.67 dB
    // against the ensemble's 39.50 here: issue 42's open point).
    let opts = DecodeOptions { schedule: SolveSchedule::Annealed, maps: Maps::ALL, ..DecodeOptions::default() };
    let (dct, _) = decode_with(&capture, &Basis::Dct, &opts).unwrap();
    let (ens, report) = decode_with(&capture, &Basis::default_ensemble(), &opts).unwrap();
    let (d, e) = (evaluate(&truth, &dct).unwrap().psnr, evaluate(&truth, &ens).unwrap().psnr);
    eprintln!("DCT {d:.2} dB, ensemble {e:.2} dB");
    const MARGIN: f64 = 0.5;
    assert!(e >= d + MARGIN, "ensemble {e:.2} dB vs DCT {d:.2} dB");
    // Screened choice: 2 solves a patch of the disjoint grid (3 where the DCT's own
    // solution wins and is solved again), 1 a shifted patch seeded from the grid's decode.
    let grid = decode_with(&capture, &Basis::Dct, &DecodeOptions { stride: (5, 5), ..opts }).unwrap().1;
    let (n, d) = (u64::from(report.patches.decoded), u64::from(grid.patches.decoded));
    assert!(
        d < n && (2 * d + (n - d)..=3 * d + (n - d)).contains(&report.solves),
        "{} solves, {n} patches, {d} on the grid",
        report.solves
    );
    let cold = decode_with(&capture, &Basis::default_ensemble(), &DecodeOptions { seeded: false, ..opts }).unwrap().1;
    let per_patch = cold.solves as f64 / f64::from(cold.patches.decoded);
    assert!((2.0..=3.0).contains(&per_patch), "unseeded: {per_patch} solves per patch");
    assert_eq!(report.member_map.len(), report.patches.decoded as usize);
    assert!(report.member_map.iter().all(|(_, m)| matches!(m, PatchDecoder::Member(0..8) | PatchDecoder::Flat)));
    assert_eq!(report.patches.interpolated, 0);
}

/// What the shipped default does against the DCT (issue 51: with the trained schedules the
/// ensemble's lead above is the hand-set schedule's; this states the default's). The
/// default decode (the shipped ensemble and the DCT, chosen for the frame by the model
/// trial's held-out errors, trained schedules) against `--dictionary dct` (the DCT alone,
/// its trained schedule), on the depth scene at pixel k = 1 and 3: issue 49's target is the
/// default within 0.1 dB of the better of the two; asserted: never more than 0.5 dB below
/// the DCT. Measured (2026-11-27): k = 1 default 32.14 dB, DCT 29.88 (the trial takes the
/// ensemble); k = 3 both 39.67 (it takes the DCT).
#[test]
fn the_shipped_default_keeps_up_with_the_dct() {
    use slf_host::decode::settings::DecodeSettings;
    let truth = scene::named("depth").unwrap().render(SceneSize { views: (5, 5), rows: 40, cols: 40 });
    for k in [1u8, 3] {
        let capture = simulate(&truth, &CameraConfig::pixel(7, k)).unwrap();
        let psnr = |flags: &[&str]| {
            let d = DecodeSettings::from_flags(flags).unwrap().run(&capture, false, &|_, _| {}).unwrap();
            evaluate(&truth, &d.light_field).unwrap().psnr
        };
        let (default, dct) = (psnr(&[]), psnr(&["--dictionary", "dct"]));
        eprintln!("k = {k}: default {default:.2} dB, DCT {dct:.2} dB");
        assert!(default >= dct - 0.5, "k = {k}: default {default:.2} dB, DCT alone {dct:.2} dB");
    }
}
