//! How much of a turned lenslet grid's loss is the decode's model (issue 52)?
//!
//! Behind a turned, non-integer-pitch grid a pixel records the view cells its square covers,
//! each by its share (`sim/footprint.rs`): up to half of a neighbouring view, or of the
//! neighbouring lenslet's. The decoder today reads each view from the pixel under its cell's
//! centre and takes it as that view's value (a selection). This decodes the same patches of
//! a noiseless pixel k = 1 capture (16 bits, so the frames hold the light to 1/65535) three
//! ways, each with the same f64 SL0 (16 disjoint 5 x 5-lenslet full-view patches of a 30 x
//! 30-lenslet scene; the 5D DCT; the hand-set schedule's mu 2, sigma_f 0.7, 3 steps, down to
//! sigma 1e-3; grey-world gains from the light field's band means; the projection
//! `x - M^T (M M^T)^+ (M x - y)` in the signal domain):
//!
//! - **aligned**: the aligned sensor's capture, a selection (the reference);
//! - **nearest**: the grid's capture read as the decoder reads it today, a selection;
//! - **exact**: the grid's capture with each pixel's measurement the shares of the view
//!   cells it covers (pixels reaching outside the patch left out): the projection the
//!   decoder would need.
//!
//! Usage (prints one line per grid with the PSNR over the patches' values together, all 13
//! bands, peak the light field's maximum):
//!
//!     cargo run --release -p slf-host --example grid_model -- office 0.3:5.04 1:5.1 0:5.02

use anyhow::{Context, Result, ensure};
use nalgebra::{DMatrix, DVector};
use slf_host::decode::paper_1d::{Factors, analyze_5d, synthesize_5d};
use slf_host::io::lightfield::LightField;
use slf_host::io::sensor::SensorDescription;
use slf_host::sim::camera::{CameraConfig, GridSettings, simulate};
use slf_host::sim::footprint::footprint;
use slf_host::sim::scene::SceneSize;

const P: usize = 25; // cells along each axis of a patch: 5 lenslets x 5 views
const B: usize = 13;
const N: usize = P * P * B;

/// Patch entry `(s, t, u, v, b)` from the patch's cell `(i, j)` (`i = s * 5 + u`).
fn entry(i: usize, j: usize, b: usize) -> usize {
    let (s, u, t, v) = (i / 5, i % 5, j / 5, j % 5);
    (((s * 5 + t) * 5 + u) * 5 + v) * B + b
}

/// SL0 onto `M x = y` (rows of `(entry, weight)`), the 5D DCT, the hand-set schedule's
/// numbers, white-balanced by `gains` (band `b`'s values divided by `gains[b]` before the
/// solve and multiplied back, as the decoder's grey balance does).
fn sl0(f: &Factors<f64>, rows: &[Vec<(usize, f64)>], y: &[f64], gains: &[f64; B]) -> Vec<f64> {
    let y: Vec<f64> = rows.iter().zip(y).map(|(r, &v)| v / gains[r[0].0 % B]).collect();
    let mut x = sl0_balanced(f, rows, &y);
    for (i, v) in x.iter_mut().enumerate() {
        *v *= gains[i % B];
    }
    x
}

fn sl0_balanced(f: &Factors<f64>, rows: &[Vec<(usize, f64)>], y: &[f64]) -> Vec<f64> {
    let m = rows.len();
    let g = DMatrix::<f64>::from_fn(m, m, |a, b| {
        rows[a]
            .iter()
            .map(|&(i, w)| rows[b].iter().filter(|&&(j, _)| j == i).map(|&(_, v)| w * v).sum::<f64>())
            .sum::<f64>()
    });
    let inv = g.pseudo_inverse(1e-10).expect("pseudo-inverse");
    let apply =
        |x: &[f64]| DVector::from_iterator(m, rows.iter().map(|r| r.iter().map(|&(i, w)| w * x[i]).sum::<f64>()));
    let back = |z: &DVector<f64>, x: &mut [f64]| {
        for (r, &zr) in rows.iter().zip(z.iter()) {
            for &(i, w) in r {
                x[i] -= w * zr;
            }
        }
    };
    let yv = DVector::from_column_slice(y);
    let project = |x: &mut Vec<f64>| {
        let r = apply(x) - &yv;
        back(&(&inv * r), x);
    };
    let mut x = vec![0.0; N];
    project(&mut x);
    let mut s = analyze_5d(f, &x);
    let mut sigma = 2.0 * s.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    let (mu, sigma_f, steps, sigma_min) = (2.0, 0.7, 3, 1e-3);
    while sigma > sigma_min {
        for _ in 0..steps {
            for c in s.iter_mut() {
                *c -= mu * *c * (-*c * *c / (2.0 * sigma * sigma)).exp();
            }
            x = synthesize_5d(f, &s);
            project(&mut x);
            s = analyze_5d(f, &x);
        }
        sigma *= sigma_f;
    }
    x
}

/// The squared error of `x` against `truth`, summed.
fn psnr(truth: &[f64], x: &[f64], _peak: f64) -> f64 {
    truth.iter().zip(x).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
}

/// PSNR of summed squared errors over `patches` patches.
fn db(sum: f64, patches: usize, peak: f64) -> f64 {
    10.0 * (peak * peak / (sum / (patches * N) as f64)).log10()
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    ensure!(args.len() >= 2, "usage: grid_model SCENE ROTATION:PITCH...");
    let size = 30;
    let lf: LightField = slf_host::sim::realistic::named(&args[0])
        .or_else(|| slf_host::sim::scene::named(&args[0]))
        .context("a scene slf names")?
        .render(SceneSize { views: (5, 5), rows: size, cols: size });
    let peak = f64::from(lf.max());
    let camera = |grid: Option<GridSettings>| {
        let mut cam = CameraConfig::pixel(5, 1).noiseless();
        (cam.bits, cam.black_level, cam.white_fraction) = (16, 0, 1.0);
        cam.sensor = SensorDescription::IDEAL;
        cam.grid = grid;
        cam
    };
    let f = Factors::dct_f64_of([5, 5, 5, 5, 13]);
    // Grey-world gains from the light field's band means (the decoder takes them from the
    // frame's).
    let mut means = [0.0f64; B];
    for (i, &v) in lf.data.iter().enumerate() {
        means[i % B] += f64::from(v);
    }
    let all = means.iter().sum::<f64>() / B as f64;
    let gains: [f64; B] = means.map(|m| (m / all).max(1e-3));
    let origins: Vec<(usize, usize)> = [5, 10, 15, 20].iter().flat_map(|&a| [5, 10, 15, 20].map(|b| (a, b))).collect();
    let truth = |(s0, t0): (usize, usize)| {
        let mut x = vec![0.0; N];
        for i in 0..P {
            for j in 0..P {
                for b in 0..B {
                    x[entry(i, j, b)] = f64::from(lf.get(i % 5, j % 5, s0 + i / 5, t0 + j / 5, b));
                }
            }
        }
        x
    };
    // The aligned sensor, a selection.
    let aligned = simulate(&lf, &camera(None))?;
    let mask = aligned.mask()?;
    let cols = size * 5;
    let mut sum = 0.0;
    for &(s0, t0) in &origins {
        let (mut rows, mut y) = (Vec::new(), Vec::new());
        for i in 0..P {
            for j in 0..P {
                let (r, c) = (s0 * 5 + i, t0 * 5 + j);
                let b = mask.bands_at(r, c)[0] as usize;
                rows.push(vec![(entry(i, j, b), 1.0)]);
                y.push(f64::from(aligned.held_frames().unwrap()[0][r * cols + c]) / 65535.0);
            }
        }
        sum += psnr(&truth((s0, t0)), &sl0(&f, &rows, &y, &gains), peak);
    }
    println!("{}: aligned sensor {:.2} dB over {} patches", args[0], db(sum, origins.len(), peak), origins.len());
    for g in &args[1..] {
        let (rot, pitch) = g.split_once(':').context("ROTATION:PITCH")?;
        let settings = GridSettings { rotation_deg: rot.parse()?, pitch: Some([pitch.parse()?; 2]), offset: None };
        let cap = simulate(&lf, &camera(Some(settings)))?;
        let desc = cap.description.lenslet_grid.context("a grid")?;
        let fw = desc.firmware([5, 5])?;
        let (rows_n, cols_n) = cap.frame_size();
        let mask = cap.mask()?;
        let (mut nearest, mut exact) = (0.0, 0.0);
        let mut cells = Vec::new();
        for &(s0, t0) in &origins {
            let want = truth((s0, t0));
            // Nearest: each cell from the pixel under its centre.
            let (mut rows, mut y) = (Vec::new(), Vec::new());
            for i in 0..P {
                for j in 0..P {
                    let l = ((s0 + i / 5) as isize, (t0 + j / 5) as isize);
                    let Some((r, c)) = fw.pixel(l, (i % 5, j % 5)) else { continue };
                    let b = mask.bands_at(r, c)[0] as usize;
                    rows.push(vec![(entry(i, j, b), 1.0)]);
                    y.push(f64::from(cap.held_frames().unwrap()[0][r * cols_n + c]) / 65535.0);
                }
            }
            nearest += psnr(&want, &sl0(&f, &rows, &y, &gains), peak);
            // Exact: every pixel whose square lies in the patch's cells, by its shares.
            let (mut rows, mut y) = (Vec::new(), Vec::new());
            let (lo_r, lo_c) = ((s0 * 5) as i64, (t0 * 5) as i64);
            for r in 0..rows_n {
                for c in 0..cols_n {
                    footprint(&desc, [5, 5], r, c, &mut cells);
                    let inside = cells.iter().all(|&([i, j], _)| {
                        (lo_r..lo_r + P as i64).contains(&i) && (lo_c..lo_c + P as i64).contains(&j)
                    });
                    if cells.is_empty() || !inside {
                        continue;
                    }
                    let b = mask.bands_at(r, c)[0] as usize;
                    rows.push(
                        cells
                            .iter()
                            .map(|&([i, j], w)| (entry((i - lo_r) as usize, (j - lo_c) as usize, b), w))
                            .collect(),
                    );
                    y.push(f64::from(cap.held_frames().unwrap()[0][r * cols_n + c]) / 65535.0);
                }
            }
            exact += psnr(&want, &sl0(&f, &rows, &y, &gains), peak);
        }
        let n = origins.len();
        println!(
            "  rotation {rot}, pitch {pitch}: nearest {:.2} dB, exact {:.2} dB",
            db(nearest, n, peak),
            db(exact, n, peak)
        );
    }
    Ok(())
}
