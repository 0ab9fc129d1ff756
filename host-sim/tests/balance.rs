//! White balance on the host: the default decode balances by the frame's grey world, the
//! gains are reported and can be given, and under a steep illuminant the balanced decode
//! is measurably nearer the truth.

use slf_host::decode::cs::{Balance, Basis, DecodeOptions, PatchViews, SolveSchedule, decode_with, tile_decoder};
use slf_host::eval::metrics::evaluate;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::SceneSize;

/// Tungsten light (CIE A: blue bands at a tenth of the red) at pixel k = 3, with the
/// default sensor's noise: the balanced DCT decode beats the plain one by at least 0.5 dB
/// with the paper's patch (measured at 64 x 64 lenslets: 41.52 against 40.55 dB; here 40 x
/// 40; at 24 x 24 the gain is 0.35 dB, within a small scene's spread), and by half its
/// measured gain with the full-view patch (here 39.76 against 39.45 dB).
#[test]
fn balance_helps_under_tungsten_light() {
    let truth =
        slf_host::sim::realistic::lookup("tungsten").unwrap().render(SceneSize { views: (5, 5), rows: 40, cols: 40 });
    let cap = simulate(&truth, &CameraConfig::pixel(3, 3)).unwrap();
    let psnr = |balance, views| {
        let opts = DecodeOptions { balance, patch_views: Some(views), ..DecodeOptions::disjoint() };
        let (lf, r) = decode_with(&cap, &Basis::Dct, &opts).unwrap();
        (evaluate(&truth, &lf).unwrap().psnr, r.gains)
    };
    for (views, margin) in [(PatchViews::Four, 0.5), (PatchViews::Five, 0.15)] {
        let (off, ones) = psnr(Balance::Off, views);
        let (grey, _) = psnr(Balance::GreyWorld, views);
        assert_eq!(ones, [1.0; 13]);
        assert!(grey > off + margin, "{views} views: balanced {grey:.2} dB, plain {off:.2} dB");
    }
    let (_, gains) = psnr(Balance::GreyWorld, PatchViews::Five);
    // The estimate follows the illuminant: red over blue as the truth's band means.
    let mean = |b: usize| truth.data.iter().skip(b).step_by(13).map(|&x| f64::from(x)).sum::<f64>();
    let (want, got) = (mean(12) / mean(0), f64::from(gains[12] / gains[0]));
    assert!((got / want - 1.0).abs() < 0.1, "gain ratio {got:.2}, truth's {want:.2}");

    // Given gains equal to the estimate decode bit for bit as the grey world does.
    let given = DecodeOptions { balance: Balance::Gains(gains), ..DecodeOptions::disjoint() };
    let grey_world = DecodeOptions { balance: Balance::GreyWorld, ..DecodeOptions::disjoint() };
    assert_eq!(
        decode_with(&cap, &Basis::Dct, &given).unwrap().0,
        decode_with(&cap, &Basis::Dct, &grey_world).unwrap().0
    );
    assert_eq!(tile_decoder::<4, 4, 5200>(&cap, &grey_world).unwrap().gains(), &gains);
}

#[test]
fn bad_gains_are_refused_with_a_message() {
    let truth =
        slf_host::sim::realistic::lookup("outdoor").unwrap().render(SceneSize { views: (5, 5), rows: 10, cols: 10 });
    let cap = simulate(&truth, &CameraConfig::pixel(3, 1)).unwrap();
    // Zero, below 1/64, above 64, not a number: each refused by the firmware's decoder.
    for bad in [0.0, 1e-3, 1e30, f32::NAN] {
        let mut g = [1.0f32; 13];
        g[3] = bad;
        let opts = DecodeOptions { balance: Balance::Gains(g), ..DecodeOptions::disjoint() };
        let e = decode_with(&cap, &Basis::Dct, &opts).unwrap_err().to_string();
        assert!(e.contains("gains") && e.contains("[1/64, 64]"), "{bad}: {e}");
    }
}

/// The shipped ensemble's screened choice keeps the DCT's solution in the mean unless a
/// member's scores `DCT_MARGIN` times sparser: on the smooth test scene at pixel k = 3 (the
/// DCT's best case) the ensemble then stays within 0.3 dB of the DCT (issue 18's bound;
/// measured at 40 x 40: +0.10 dB, and -0.78 dB with a margin of 1).
#[test]
fn ensemble_does_not_lose_to_the_dct_on_a_smooth_scene() {
    let truth = slf_host::sim::scene::named("smooth").unwrap().render(SceneSize { views: (5, 5), rows: 40, cols: 40 });
    let cap = simulate(&truth, &CameraConfig::pixel(3, 3)).unwrap();
    // Both with the hand-set schedule: the claim is the basis's. With the trained ones the
    // DCT decodes alone with its own schedule (from the band-gain fill) and measured 0.79
    // dB above the screened ensemble here (docs/results-schedule.md: issue 42's open point).
    let psnr = |basis: &Basis| {
        let opts = DecodeOptions { schedule: SolveSchedule::Annealed, ..DecodeOptions::disjoint() };
        let (lf, _) = decode_with(&cap, basis, &opts).unwrap();
        evaluate(&truth, &lf).unwrap().psnr
    };
    let (dct, ensemble) = (psnr(&Basis::Dct), psnr(&Basis::default_ensemble()));
    assert!(ensemble > dct - 0.3, "ensemble {ensemble:.2} dB, DCT {dct:.2} dB");
}
