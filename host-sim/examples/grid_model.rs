//! How much of a turned lenslet grid's loss is the light's, the model's and the solver's
//! (issues 52 and 66)?
//!
//! Behind a turned, non-integer-pitch grid a pixel records the view cells its square covers,
//! each by its share (`sim/footprint.rs`): up to half of a neighbouring view, or of the
//! neighbouring lenslet's. The decoder reads each view from the pixel under its cell's
//! centre and takes it as that view's value (a selection). This decodes the same patches of
//! a noiseless capture (16 bits, so the frames hold the light to 1/65535) at `k` snapshots
//! (pixel mask), from three sets of measurements:
//!
//! - **aligned**: the aligned sensor's capture, a selection (the reference);
//! - **nearest**: the grid's capture read as the decoder reads it, a selection;
//! - **exact**: the grid's capture with each pixel's measurement the shares of the view
//!   cells it covers (pixels reaching outside the patch left out): the box-share model.
//!
//! and by two solvers, each in f64 on 5 x 5-lenslet full-view patches (25 x 25 cells x 13
//! bands, 8,125 values; disjoint, 4 x 4 of them spread over the scene away from its edge)
//! of the scene the decode tables decode (`scripts/scene-tables.sh`: a named one at 64 x 64
//! lenslets, an HCI crop whole):
//!
//! - **SL0**: the 5D DCT, the hand-set schedule's numbers (mu 2, sigma_f 0.7, 3 steps, down
//!   to sigma 1e-3), grey-world gains from the light field's band means, the projection
//!   `x - M^T (M M^T)^+ (M x - y)` exact for the patch's own `M`;
//! - **oracle**: least squares on the true signal's largest DCT coefficients (`K` of them,
//!   the best of `K` = m/8 to m for `m` measurements, picked by the truth): what a decoder
//!   that knew the support could do from these measurements. It is the bound in the sense
//!   the field uses (an oracle-support estimator): a decoder may beat it only by a support
//!   other than the largest coefficients, which no sparse prior finds.
//!
//! So `aligned oracle - exact oracle` is what the light loses behind the grid, `exact
//! oracle - exact SL0` the solver's share there, `exact SL0 - nearest SL0` what the exact
//! model gains over the selection.
//!
//! Usage (one markdown row per grid: PSNR over the patches' values together, all 13 bands,
//! peak the light field's maximum):
//!
//!     cargo run --release -p slf-host --example grid_model -- office 3 0.3:5.04 1:5.1 0:5.02
//!
//! (a scene slf names, or a light field's `.npy` of 5 x 5 views and 13 bands; snapshots;
//! then `ROTATION:PITCH` grids). `--size N` renders the scene at N x N lenslets (an `.npy`'s
//! middle N x N) instead: a realistic scene's shapes scale with its size, so a scene at
//! 30 x 30 (this example's size before 2026-12-01's third stop) is not the tables' 64 x 64
//! one. With
//! `--decoder-model` last, a second table: the pixels the decoder reads (the one under
//! each cell's centre) modelled as the decoder models them (`solver/shares.rs`: a separable
//! box, the turn left out, a share outside the patch given to the pixel's own cell), and
//! the same pixels by their exact footprints, each by the row-sum step and exactly. With
//! `--noise`, the captures carry the sensor noise of the decode tables (`scripts/scene-tables.sh`:
//! shot noise of a 20,000-electron well, 2 DN of read noise on a 12-bit range, scaled to the
//! 16-bit frames) and only the oracles are found: what the light loses behind the grid when
//! the measurements are noisy (office 64 x 64, k = 3, 0.3 degrees / 5.04 px: aligned 40.50,
//! exact 38.56 dB, -1.94 against -1.53 noiseless; about 1.6 minutes a grid on 2 cores). `scripts/grid-bound.sh` runs it over
//! scenes and writes `docs/results-grid-bound.md`.

use anyhow::{Context, Result, ensure};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use slf_host::decode::paper_1d::{Factors, analyze_5d, synthesize_5d};
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::LightField;
use slf_host::io::sensor::SensorDescription;
use slf_host::sim::camera::{CameraConfig, GridSettings, simulate};
use slf_host::sim::footprint::footprint;
use slf_host::sim::scene::SceneSize;

const P: usize = 25; // cells along each axis of a patch: 5 lenslets x 5 views
const B: usize = 13;
const N: usize = P * P * B;
/// The lenslets of a named scene by default: the decode tables' (`scripts/scene-tables.sh`'s
/// `grid_table_setup`), so the bound is measured on the picture they decode.
const TABLES_SIZE: usize = 64;

/// A patch's measurements: rows of `(entry, weight)` and the values they measured.
struct Measured {
    rows: Vec<Vec<(usize, f64)>>,
    y: Vec<f64>,
}

/// Patch entry `(s, t, u, v, b)` from the patch's cell `(i, j)` (`i = s * 5 + u`).
fn entry(i: usize, j: usize, b: usize) -> usize {
    let (s, u, t, v) = (i / 5, i % 5, j / 5, j % 5);
    (((s * 5 + t) * 5 + u) * 5 + v) * B + b
}

/// `M x`.
fn apply(rows: &[Vec<(usize, f64)>], x: &[f64]) -> DVector<f64> {
    DVector::from_iterator(rows.len(), rows.iter().map(|r| r.iter().map(|&(i, w)| w * x[i]).sum::<f64>()))
}

/// How SL0's projection onto `M x = y` solves `(M M^T) z = M x - y` for the correction
/// `M^T z`.
#[derive(Clone, Copy, Debug)]
enum Projection {
    /// Exactly: Cholesky of `M M^T` (the pseudo-inverse where it is singular).
    Exact,
    /// One step scaled by each row of `M M^T` summed: the firmware's behind a grid
    /// (`solver/shares.rs`), exact for a measurement alone.
    RowSum,
    /// This many conjugate-gradient steps from zero, preconditioned by the row sums.
    Cg(usize),
}

/// SL0 onto `M x = y` by `projection`, the 5D DCT, the hand-set schedule's numbers,
/// white-balanced by `gains` (band `b`'s values divided by `gains[b]` before the solve and
/// multiplied back, as the decoder's grey balance does: a measurement's weights scale with
/// its band's gain).
fn sl0(f: &Factors<f64>, m: &Measured, gains: &[f64; B], projection: Projection) -> Vec<f64> {
    let rows: Vec<Vec<(usize, f64)>> =
        m.rows.iter().map(|r| r.iter().map(|&(i, w)| (i, w * gains[i % B])).collect()).collect();
    let back = |z: &DVector<f64>| {
        let mut x = vec![0.0; N];
        for (r, &zr) in rows.iter().zip(z.iter()) {
            for &(i, w) in r {
                x[i] += w * zr;
            }
        }
        x
    };
    // `M M^T z`, applied through `M^T`.
    let gram = |z: &DVector<f64>| apply(&rows, &back(z));
    let sums = gram(&DVector::from_element(rows.len(), 1.0));
    let n = rows.len();
    let (chol, inv) = match projection {
        Projection::Exact => {
            let g = DMatrix::<f64>::from_fn(n, n, |a, b| {
                rows[a]
                    .iter()
                    .map(|&(i, w)| rows[b].iter().filter(|&&(j, _)| j == i).map(|&(_, v)| w * v).sum::<f64>())
                    .sum::<f64>()
            });
            // Full row rank (each pixel's own measurement): Cholesky; else the pseudo-inverse.
            match g.clone().cholesky() {
                Some(c) => (Some(c), None),
                None => (None, Some(g.pseudo_inverse(1e-10).expect("pseudo-inverse"))),
            }
        }
        _ => (None, None),
    };
    let solve = |r: DVector<f64>| -> DVector<f64> {
        match projection {
            Projection::Exact => match (&chol, &inv) {
                (Some(c), _) => c.solve(&r),
                (None, Some(inv)) => inv * r,
                (None, None) => unreachable!(),
            },
            Projection::RowSum => r.component_div(&sums),
            Projection::Cg(steps) => {
                let mut z = DVector::zeros(n);
                let mut res = r;
                let mut p = res.component_div(&sums);
                let mut rz = res.dot(&p);
                for _ in 0..steps {
                    let gp = gram(&p);
                    let pgp = p.dot(&gp);
                    if pgp <= 0.0 || rz == 0.0 {
                        break;
                    }
                    let alpha = rz / pgp;
                    z.axpy(alpha, &p, 1.0);
                    res.axpy(-alpha, &gp, 1.0);
                    let q = res.component_div(&sums);
                    let rz_next = res.dot(&q);
                    p = &q + (rz_next / rz) * &p;
                    rz = rz_next;
                }
                z
            }
        }
    };
    let yv = DVector::from_column_slice(&m.y);
    let project = |x: &mut Vec<f64>| {
        let z = solve(apply(&rows, x) - &yv);
        for (xi, c) in x.iter_mut().zip(back(&z)) {
            *xi -= c;
        }
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
    for (i, v) in x.iter_mut().enumerate() {
        *v *= gains[i % B];
    }
    x
}

/// The oracle: least squares on `truth`'s `K` largest DCT coefficients, the best `K` of
/// m/8, m/4, m/2, 3m/4, 7m/8 and m for `m` measurements by the squared error against
/// `truth` (returned). Solved by the normal equations (Cholesky of the leading `K x K`
/// block of `A^T A`, made once for the largest `K`; a `K` whose block is singular is
/// skipped).
fn oracle(f: &Factors<f64>, m: &Measured, truth: &[f64]) -> f64 {
    let c = analyze_5d(f, truth);
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|&a, &b| c[b].abs().total_cmp(&c[a].abs()));
    let rows = m.rows.len();
    let top = rows.min(N);
    // The measurements of each of the `top` largest atoms, once.
    let mut atoms = DMatrix::<f64>::zeros(rows, top);
    let mut unit = vec![0.0; N];
    for (col, &k) in order[..top].iter().enumerate() {
        unit[k] = 1.0;
        let atom = synthesize_5d(f, &unit);
        unit[k] = 0.0;
        atoms.set_column(col, &apply(&m.rows, &atom));
    }
    let gram = atoms.tr_mul(&atoms);
    let aty = atoms.tr_mul(&DVector::from_column_slice(&m.y));
    [rows / 8, rows / 4, rows / 2, rows * 3 / 4, rows * 7 / 8, top]
        .iter()
        .filter(|&&k| k > 0 && k <= top)
        .filter_map(|&k| {
            let coef = gram.view((0, 0), (k, k)).into_owned().cholesky()?.solve(&aty.rows(0, k).into_owned());
            let mut full = vec![0.0; N];
            for (j, &atom) in order[..k].iter().enumerate() {
                full[atom] = coef[j];
            }
            Some(sq_err(truth, &synthesize_5d(f, &full)))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The squared error of `x` against `truth`, summed.
fn sq_err(truth: &[f64], x: &[f64]) -> f64 {
    truth.iter().zip(x).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
}

/// PSNR of summed squared errors over `patches` patches.
fn db(sum: f64, patches: usize, peak: f64) -> f64 {
    10.0 * (peak * peak / (sum / (patches * N) as f64)).log10()
}

/// Pixel `(r, c)`'s measurement in snapshot `j` by its exact footprint (`cells`, filled by
/// [`footprint`]) on the patch whose first cell is `lo`: its row and value; `None` for a
/// pixel that reaches outside the patch.
fn exact_row(cells: &[([i64; 2], f64)], lo: (i64, i64), band: usize, value: f64) -> Option<(Vec<(usize, f64)>, f64)> {
    let inside =
        |&([i, j], _): &([i64; 2], f64)| (lo.0..lo.0 + P as i64).contains(&i) && (lo.1..lo.1 + P as i64).contains(&j);
    if cells.is_empty() || !cells.iter().all(inside) {
        return None;
    }
    Some((cells.iter().map(|&([i, j], w)| (entry((i - lo.0) as usize, (j - lo.1) as usize, band), w)).collect(), value))
}

/// Snapshot `j`'s normalised value at pixel `(r, c)`.
fn value(cap: &Capture, j: usize, r: usize, c: usize) -> f64 {
    let cols = cap.frame_size().1;
    f64::from(cap.held_frames().unwrap()[j][r * cols + c]) / 65535.0
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    ensure!(args.len() >= 3, "usage: grid_model SCENE|LIGHT_FIELD.npy SNAPSHOTS ROTATION:PITCH...");
    let k: u8 = args[1].parse().context("SNAPSHOTS: 1 to 13")?;
    // `--decoder-model` after the grids: a second table, the decoder's own model of the
    // grid against the exact footprints on the same pixels.
    let decoder_model = args.iter().any(|a| a == "--decoder-model");
    // `--noise`: the decoder tables' sensor noise (shot noise of a 20,000-electron well,
    // read noise of 2 DN of a 12-bit range 90 % full), the oracle alone.
    let noise = args.iter().any(|a| a == "--noise");
    // `--size N` (30 or more): the scene's lenslets (an .npy's middle N x N), the 16 patches
    // spread over it. By default the decode tables' own: a named scene at 64 x 64
    // (`scripts/scene-tables.sh`), an .npy whole (its smaller side).
    let size: Option<usize> = match args.iter().position(|a| a == "--size") {
        Some(i) => Some(args.get(i + 1).context("--size N")?.parse().context("--size N: lenslets")?),
        None => None,
    };
    ensure!(size.is_none_or(|n| (30..=4096).contains(&n)), "--size: 30 to 4096 lenslets");
    let grids: Vec<&String> = args[2..]
        .iter()
        .enumerate()
        .filter(|&(i, a)| !a.starts_with("--") && args[1 + i] != "--size")
        .map(|(_, a)| a)
        .collect();
    let (lf, name): (LightField, String) = if args[0].ends_with(".npy") {
        // A light field's file (an HCI crop): its middle size x size lenslets.
        let whole = slf_host::io::lightfield::read_npy(std::path::Path::new(&args[0]))?;
        ensure!(whole.views == (5, 5) && whole.bands == B, "{}: 5 x 5 views and 13 bands", args[0]);
        let size = size.unwrap_or(whole.rows.min(whole.cols));
        ensure!(
            whole.rows >= size && whole.cols >= size && size >= 30,
            "{}: at least {size} x {size} lenslets, and 30",
            args[0]
        );
        let name = std::path::Path::new(&args[0]).file_stem().map_or(String::new(), |s| s.to_string_lossy().into());
        (whole.window((whole.rows - size) / 2, (whole.cols - size) / 2, size, size), name)
    } else {
        let scene = slf_host::sim::realistic::named(&args[0])
            .or_else(|| slf_host::sim::scene::named(&args[0]))
            .context("a scene slf names, or a light field's .npy")?;
        let size = size.unwrap_or(TABLES_SIZE);
        (scene.render(SceneSize { views: (5, 5), rows: size, cols: size }), args[0].clone())
    };
    let size = lf.rows.min(lf.cols);
    let peak = f64::from(lf.max());
    let camera = |grid: Option<GridSettings>| {
        let mut cam = CameraConfig::pixel(5, k);
        if noise {
            // The same noise relative to white on the 16-bit range below.
            let range = ((1u32 << cam.bits) - 1) as f32 - f32::from(cam.black_level);
            cam.read_noise *= 65535.0 / (range * cam.white_fraction);
        } else {
            cam = cam.noiseless();
        }
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
    // 4 x 4 patches 5 lenslets from the edges, a whole number of patches apart (at 30
    // lenslets: 5, 10, 15, 20).
    let step = (size - 10) / 3 / 5 * 5;
    let at = [5, 5 + step, 5 + 2 * step, 5 + 3 * step];
    let origins: Vec<(usize, usize)> = at.iter().flat_map(|&a| at.map(|b| (a, b))).collect();
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
    // Summed squared errors over the patches of one set of measurements: the oracle's (with
    // `with_oracle`, else 0), then SL0's by each of `projections`.
    let score = |measure: &(dyn Fn((usize, usize)) -> Measured + Sync),
                 with_oracle: bool,
                 projections: &[Projection]|
     -> Vec<f64> {
        origins
            .par_iter()
            .map(|&o| {
                let (m, want) = (measure(o), truth(o));
                let mut e = vec![if with_oracle { oracle(&f, &m, &want) } else { 0.0 }];
                e.extend(projections.iter().map(|&p| sq_err(&want, &sl0(&f, &m, &gains, p))));
                e
            })
            .reduce(|| vec![0.0; projections.len() + 1], |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect())
    };
    let n = origins.len();
    let aligned = simulate(&lf, &camera(None))?;
    let mask = aligned.mask()?;
    let a = score(
        &|(s0, t0)| {
            let (mut rows, mut y) = (Vec::new(), Vec::new());
            for j in 0..usize::from(k) {
                for i in 0..P {
                    for jj in 0..P {
                        let (r, c) = (s0 * 5 + i, t0 * 5 + jj);
                        rows.push(vec![(entry(i, jj, mask.bands_at(r, c)[j] as usize), 1.0)]);
                        y.push(value(&aligned, j, r, c));
                    }
                }
            }
            Measured { rows, y }
        },
        true,
        if noise { &[] } else { &[Projection::Exact] },
    );
    if noise {
        println!(
            "| scene | k | grid (deg:px) | aligned oracle | exact model, oracle | exact - aligned, oracle (the light) |"
        );
        println!("| --- | --- | --- | --- | --- | --- |");
    }
    if !noise {
        println!(
            "| scene | k | grid (deg:px) | aligned SL0 | aligned oracle | nearest SL0 | exact model, SL0 by: \
         row-sum step | CG 4 | exact projection | exact model, oracle | nearest - aligned, SL0 | \
         row-sum - aligned | CG 4 - aligned | exact - aligned, SL0 | exact - aligned, oracle (the light) |"
        );
        println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    }
    let mut model_rows = Vec::new();
    for g in &grids {
        let (rot, pitch) = g.split_once(':').context("ROTATION:PITCH")?;
        let settings = GridSettings { rotation_deg: rot.parse()?, pitch: Some([pitch.parse()?; 2]), offset: None };
        let cap = simulate(&lf, &camera(Some(settings)))?;
        let desc = cap.description.lenslet_grid.context("a grid")?;
        let fw = desc.firmware([5, 5])?;
        let (rows_n, cols_n) = cap.frame_size();
        let mask = cap.mask()?;
        // Nearest: each cell from the pixel under its centre.
        let near = score(
            &|(s0, t0)| {
                let (mut rows, mut y) = (Vec::new(), Vec::new());
                for j in 0..usize::from(k) {
                    for i in 0..P {
                        for jj in 0..P {
                            let l = ((s0 + i / 5) as isize, (t0 + jj / 5) as isize);
                            let Some((r, c)) = fw.pixel(l, (i % 5, jj % 5)) else { continue };
                            rows.push(vec![(entry(i, jj, mask.bands_at(r, c)[j] as usize), 1.0)]);
                            y.push(value(&cap, j, r, c));
                        }
                    }
                }
                Measured { rows, y }
            },
            false,
            if noise { &[] } else { &[Projection::Exact] },
        );
        // Exact: every pixel whose square lies in the patch's cells, by its shares.
        let exact = score(
            &|(s0, t0)| {
                let (mut rows, mut y, mut cells) = (Vec::new(), Vec::new(), Vec::new());
                let (lo_r, lo_c) = ((s0 * 5) as i64, (t0 * 5) as i64);
                for r in 0..rows_n {
                    for c in 0..cols_n {
                        footprint(&desc, [5, 5], r, c, &mut cells);
                        for j in 0..usize::from(k) {
                            let band = mask.bands_at(r, c)[j] as usize;
                            let Some((row, v)) = exact_row(&cells, (lo_r, lo_c), band, value(&cap, j, r, c)) else {
                                break;
                            };
                            rows.push(row);
                            y.push(v);
                        }
                    }
                }
                Measured { rows, y }
            },
            true,
            if noise { &[] } else { &[Projection::RowSum, Projection::Cg(4), Projection::Exact] },
        );
        if noise {
            let (a_or, e_or) = (db(a[0], n, peak), db(exact[0], n, peak));
            println!("| {name} | {k} | {rot}:{pitch} | {a_or:.2} | {e_or:.2} | {:+.2} |", e_or - a_or);
            continue;
        }
        if decoder_model {
            // The pixels the decoder reads: the one under each view cell's centre.
            let nearest = |(s0, t0): (usize, usize), row: &mut dyn FnMut(usize, usize, (usize, usize), usize)| {
                for j in 0..usize::from(k) {
                    for i in 0..P {
                        for jj in 0..P {
                            let l = ((s0 + i / 5) as isize, (t0 + jj / 5) as isize);
                            if let Some(rc) = fw.pixel(l, (i % 5, jj % 5)) {
                                row(i, jj, rc, j);
                            }
                        }
                    }
                }
            };
            // The decoder's model (`solver/shares.rs`): a separable box `views / pitch`
            // cells wide about the pixel's centre, the turn left out, a share outside the
            // patch given to the pixel's own cell.
            let width = [5.0 / desc.pitch[0], 5.0 / desc.pitch[1]];
            let boxed = score(
                &|(s0, t0)| {
                    let (mut rows, mut y) = (Vec::new(), Vec::new());
                    nearest((s0, t0), &mut |i, jj, (r, c), j| {
                        let centre = desc.cell([5, 5], [r as f64 + 0.5, c as f64 + 0.5]);
                        let own = [(s0 * 5 + i) as f64 + 0.5, (t0 * 5 + jj) as f64 + 0.5];
                        let axis = |a: usize, at: usize| -> [(usize, f64); 3] {
                            let (delta, w) = (centre[a] - own[a], width[a]);
                            let before = ((-0.5 - (delta - w / 2.0)) / w).max(0.0);
                            let after = ((delta + w / 2.0 - 0.5) / w).max(0.0);
                            let mut shares =
                                [(at.wrapping_sub(1), before), (at, 1.0 - before - after), (at + 1, after)];
                            for side in [0, 2] {
                                if shares[side].0 >= P {
                                    shares[1].1 += shares[side].1;
                                    shares[side].1 = 0.0;
                                }
                            }
                            shares
                        };
                        let b = mask.bands_at(r, c)[j] as usize;
                        let mut taps = Vec::new();
                        for (ri, wr) in axis(0, i) {
                            for (ci, wc) in axis(1, jj) {
                                if wr * wc > 0.0 {
                                    taps.push((entry(ri, ci, b), wr * wc));
                                }
                            }
                        }
                        rows.push(taps);
                        y.push(value(&cap, j, r, c));
                    });
                    Measured { rows, y }
                },
                false,
                &[Projection::RowSum, Projection::Exact],
            );
            // The same pixels by their exact footprints (a pixel reaching outside the
            // patch left out).
            let exact_nearest = score(
                &|(s0, t0)| {
                    let (mut rows, mut y, mut cells) = (Vec::new(), Vec::new(), Vec::new());
                    let (lo_r, lo_c) = ((s0 * 5) as i64, (t0 * 5) as i64);
                    nearest((s0, t0), &mut |_, _, (r, c), j| {
                        footprint(&desc, [5, 5], r, c, &mut cells);
                        let band = mask.bands_at(r, c)[j] as usize;
                        if let Some((row, v)) = exact_row(&cells, (lo_r, lo_c), band, value(&cap, j, r, c)) {
                            rows.push(row);
                            y.push(v);
                        }
                    });
                    Measured { rows, y }
                },
                false,
                &[Projection::RowSum, Projection::Exact],
            );
            let d = |e: f64| db(e, n, peak);
            model_rows.push(format!(
                "| {name} | {k} | {rot}:{pitch} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                d(a[1]),
                d(boxed[1]),
                d(boxed[2]),
                d(exact_nearest[1]),
                d(exact_nearest[2])
            ));
        }
        let db = |e: f64| db(e, n, peak);
        let (a_or, a_sl0, n_sl0) = (db(a[0]), db(a[1]), db(near[1]));
        let (e_or, e_row, e_cg, e_sl0) = (db(exact[0]), db(exact[1]), db(exact[2]), db(exact[3]));
        println!(
            "| {name} | {k} | {rot}:{pitch} | {a_sl0:.2} | {a_or:.2} | {n_sl0:.2} | {e_row:.2} | {e_cg:.2} | {e_sl0:.2} | \
             {e_or:.2} | {:+.2} | {:+.2} | {:+.2} | {:+.2} | {:+.2} |",
            n_sl0 - a_sl0,
            e_row - a_sl0,
            e_cg - a_sl0,
            e_sl0 - a_sl0,
            e_or - a_or
        );
    }
    if decoder_model {
        println!();
        println!(
            "| scene | k | grid (deg:px) | aligned SL0 | decoder's model (separable box), row-sum step | \
             decoder's model, exact projection | exact footprints of the same pixels, row-sum step | \
             exact footprints of the same pixels, exact projection |"
        );
        println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
        for r in &model_rows {
            println!("{r}");
        }
    }
    Ok(())
}
