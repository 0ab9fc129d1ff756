//! Time per patch solve and per transform, on one core (criterion).
//!
//! `cargo bench -p slf-firmware --bench solve` prints criterion's times and, first, the
//! multiply-adds of each benchmarked solve, so time per solve converts to a fraction of
//! the core's f32 FMA peak: `macs / time / peak`.

use criterion::{Criterion, criterion_group, criterion_main};
use slf_firmware::Shape;
use slf_firmware::ascent::ascend;
use slf_firmware::ball::Ball;
use slf_firmware::projection::{project_coefficients, projection_macs};
use slf_firmware::transform::{analyze, analyze_preserving, synthesize};
use slf_firmware::{
    ChoiceRule, DEFAULT_ENSEMBLE, Dictionary, Ensemble, EnsembleModel, LensletSize, Mask, MemberChoice, PaperShape,
    PaperWorkspace, PatchModel, Sl0Config, solve,
};
use std::hint::black_box;

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };

/// A smooth, textured patch in [0, 1].
fn patch() -> Vec<f32> {
    (0..5200)
        .map(|i| {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            let (s, t, b) = (s as f32, t as f32, b as f32);
            0.45 + 0.2 * (0.6 * s + 0.3 * t).sin() + 0.15 * (0.4 * b).cos() + 0.01 * (u * v) as f32
        })
        .collect()
}

fn measured_workspace(mask: &Mask) -> Box<PaperWorkspace> {
    let x = patch();
    let mut ws = Box::new(PaperWorkspace::new());
    for (i, &y) in x.iter().enumerate() {
        let [s, t, u, v, b] = PaperShape::coordinates(i);
        if mask.bands_at(s * 5 + u, t * 5 + v).contains(&(b as u8)) {
            ws.measurements_mut().set(i, y).unwrap();
        }
    }
    ws
}

fn benches(c: &mut Criterion) {
    let dict = Dictionary::<PaperShape>::dct();
    let cfg = Sl0Config::DEFAULT;
    let macs = PaperShape::TRANSFORM_MACS as f64;

    let mut a = Box::new([0.5f32; 5200]);
    let mut b = Box::new([0.0f32; 5200]);
    c.bench_function("synthesize 5x5x4x4x13", |bench| bench.iter(|| synthesize(&dict, black_box(&mut a), &mut b)));
    c.bench_function("analyze 5x5x4x4x13", |bench| bench.iter(|| analyze(&dict, black_box(&mut b), &mut a)));
    eprintln!("transform: {macs} multiply-adds");

    for k in [1u8, 3] {
        let mask = Mask::pixel(1, k, 13, L5).unwrap();
        let mut ws = measured_workspace(&mask);
        let out = solve(&dict, &cfg, &mut ws).unwrap();
        // Per step: one projection; plus the start's analysis and the final synthesis.
        let count = ws.measurements().count();
        let step_macs = projection_macs::<PaperShape>(count);
        let solve_macs = (out.iterations as usize * step_macs) as f64 + 2.0 * macs;
        eprintln!("projection pixel k={k}: {step_macs} multiply-adds ({count} measurements)");
        let mut coeffs = Box::new([0.0f32; 5200]);
        let mut scratch = Box::new([0.0f32; 5200]);
        let exact = Ball::new(0.0, 0.0, count as u32, 0);
        analyze_preserving(&dict, ws.patch(), &mut coeffs);
        c.bench_function(&format!("project pixel k={k}"), |bench| {
            bench.iter(|| {
                project_coefficients(&dict, black_box(&mut coeffs), &mut scratch, ws.measurements(), &exact, None)
            })
        });
        let ensemble = Ensemble::<PaperShape>::new(DEFAULT_ENSEMBLE).unwrap();
        let member = ensemble.member(1).unwrap(); // 0 is the DCT
        c.bench_function(&format!("project pixel k={k} learned member"), |bench| {
            bench.iter(|| {
                project_coefficients(&member, black_box(&mut coeffs), &mut scratch, ws.measurements(), &exact, None)
            })
        });
        if k == 1 {
            // The step is branch-free on the host: its time does not depend on sigma.
            c.bench_function("ascend 5200", |bench| {
                bench.iter(|| ascend(black_box(&mut coeffs[..]), cfg.mu, black_box(1.0 / (2.0 * 0.05 * 0.05))))
            });
        }
        eprintln!(
            "solve pixel k={k}: {} steps, {} levels, {solve_macs:.3e} multiply-adds in transforms",
            out.iterations, out.levels
        );
        c.bench_function(&format!("solve DCT default pixel k={k}"), |bench| {
            bench.iter(|| solve(&dict, &cfg, black_box(&mut ws)).unwrap())
        });
        let model =
            EnsembleModel::new(Ensemble::new(DEFAULT_ENSEMBLE).unwrap(), MemberChoice::Screened(ChoiceRule::DEFAULT));
        let out = model.decode(&cfg, &mut ws).unwrap();
        eprintln!("screened pixel k={k}: {} solves, member {:?}", out.solves, out.member);
        c.bench_function(&format!("decode ensemble screened pixel k={k}"), |bench| {
            bench.iter(|| model.decode(&cfg, black_box(&mut ws)).unwrap())
        });
    }
}

criterion_group!(solve_benches, benches);
criterion_main!(solve_benches);
