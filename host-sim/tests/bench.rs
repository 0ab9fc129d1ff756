//! The bench's Pareto front: per mask family and k, the points no other point beats in
//! both time and PSNR.

use slf_host::eval::bench::{Point, mark_pareto};

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
