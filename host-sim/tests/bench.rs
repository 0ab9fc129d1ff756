//! The bench's Pareto front: per mask family and k, the points no other point beats in
//! both time and PSNR.

use slf_host::eval::bench::{Point, frame_patches, label, mark_pareto};

fn p(mask: &str, k: u8, ms: f64, psnr: f64) -> Point {
    Point {
        mask: mask.into(),
        k,
        setting: format!("{ms}/{psnr}"),
        psnr,
        ssim: 0.0,
        sa: 0.0,
        ms_one: ms,
        ms_all: ms / 2.0,
        solves: 1.0,
        frame_s: 0.0,
        pareto: false,
    }
}

#[test]
fn the_pareto_front_is_per_family_and_strict() {
    let mut pts = vec![
        p("pixel", 3, 1.0, 20.0),   // fastest: front
        p("pixel", 3, 2.0, 25.0),   // front
        p("pixel", 3, 3.0, 24.0),   // slower and worse than (2, 25): dominated
        p("pixel", 3, 4.0, 27.0),   // best: front
        p("pixel", 3, 4.0, 27.0),   // a tie dominates neither
        p("lenslet", 3, 3.0, 24.0), // another family: its own front
        p("pixel", 1, 3.0, 24.0),   // another k: its own front
    ];
    mark_pareto(&mut pts);
    let front: Vec<bool> = pts.iter().map(|p| p.pareto).collect();
    assert_eq!(front, [true, true, false, true, true, true, true]);
}

/// The plot names the presets and the baselines, and nothing else.
#[test]
fn presets_and_baselines_are_labelled_and_the_sweep_is_not() {
    assert_eq!(label("preset preview"), Some("preview"));
    assert_eq!(label("preset best"), Some("best"));
    for b in slf_host::decode::baselines::Baseline::ALL {
        assert_eq!(label(b.name()), Some(b.name()));
    }
    assert_eq!(label("DCT sigma_f 0.5"), None);
    assert_eq!(label("ensemble screened, noise model"), None);
}

/// A 512 x 512-lenslet frame holds 102 x 102 whole 5 x 5-lenslet blocks per angular window
/// (the last two lenslets of each axis are in no disjoint patch), counted the way the
/// decoder counts a capture's.
#[test]
fn the_frame_figure_counts_the_frames_disjoint_patches() {
    assert_eq!(frame_patches(1), 102 * 102);
    assert_eq!(frame_patches(4), 4 * 102 * 102);
    // The decoder's own count on a small capture: 20 x 20 lenslets, 5 x 5 views, four
    // angular windows, 4 x 4 blocks.
    let truth = slf_host::sim::scene::named("smooth").unwrap().render(slf_host::sim::scene::SceneSize {
        views: (5, 5),
        rows: 20,
        cols: 20,
    });
    let cap = slf_host::sim::camera::simulate(&truth, &slf_host::sim::camera::CameraConfig::pixel(7, 1)).unwrap();
    let n = slf_host::decode::cs::patch_count(&cap, slf_host::decode::cs::PatchViews::Four).unwrap();
    assert_eq!(n, 4 * 4 * 4);
    assert_eq!(frame_patches(n / 16), 4 * 102 * 102);
}
