//! Fractional disparities on a slow reference (issue 19): is a half-pixel shear worth an
//! operator that is no longer a selection?
//!
//! For blocks whose true disparity is near a half-integer `n + 0.5` (and nearly constant over
//! the block), one angular window of a noiseless pixel k = 1 capture is decoded four ways,
//! each by the same dense f64 SL0 (the paper's Algorithm 1 with an explicit pseudo-inverse)
//! with the 5D DCT:
//!
//! - sheared to the integers `n` and `n + 1` (a selection: what the decoder does);
//! - sheared to `n + 0.5` with each view's shift rounded to the nearest pixel (a selection);
//! - sheared to `n + 0.5` exactly: a sensor pixel is the bilinear interpolation of the sheared
//!   patch at its fractional position (two to four patch values per measurement).
//!
//! Each is scored at the sensor pixels every variant reaches (all 13 bands, against the
//! truth). Usage, with the HCI crops of `scripts/real-eval.sh` and their disparity maps
//! (the 128 x 128 crops sit at (64, 64) of the 256 x 256 maps):
//!
//!     cargo run --release -p slf-host --example fractional_shear -- \
//!         /tmp/hci/real/cotton_128.npy /tmp/hci/real/cotton.disparity.npy 64 64

use anyhow::{Context, Result, ensure};
use nalgebra::{DMatrix, DVector};
use slf_host::decode::cs::{DecodeOptions, tile_decoder};
use slf_host::firmware::{FrameSource, Sl0Config, TileSource};
use slf_host::io::lightfield::read_npy;
use slf_host::sim::camera::{CameraConfig, simulate};

/// Blocks decoded at most per light field.
const MAX_BLOCKS: usize = 12;

/// The orthonormal DCT-II matrix `C[k][n]` of size `d` (rows are atoms).
fn dct(d: usize) -> Vec<Vec<f64>> {
    (0..d)
        .map(|k| {
            let a = if k == 0 { (1.0 / d as f64).sqrt() } else { (2.0 / d as f64).sqrt() };
            (0..d).map(|n| a * (std::f64::consts::PI * (n as f64 + 0.5) * k as f64 / d as f64).cos()).collect()
        })
        .collect()
}

/// `K s`, the 5D synthesis, one mode at a time: mode `m` of size `d` maps index `k` to
/// `sum_k C[k][n] x[.., k, ..]`.
fn synthesize(s: &DVector<f64>, c: [&Vec<Vec<f64>>; 5]) -> Vec<f64> {
    let dims = [5usize, 5, 4, 4, 13];
    let mut x: Vec<f64> = s.iter().copied().collect();
    for m in 0..5 {
        let inner: usize = dims[m + 1..].iter().product();
        let outer: usize = dims[..m].iter().product();
        let d = dims[m];
        let mut y = vec![0.0; x.len()];
        for o in 0..outer {
            for n in 0..d {
                for k in 0..d {
                    let w = c[m][k][n];
                    for i in 0..inner {
                        y[(o * d + n) * inner + i] += w * x[(o * d + k) * inner + i];
                    }
                }
            }
        }
        x = y;
    }
    x
}

/// The paper's SL0 with an explicit pseudo-inverse, in f64: the slow reference.
fn sl0(a: &DMatrix<f64>, y: &DVector<f64>, cfg: &Sl0Config) -> DVector<f64> {
    let aat = a * a.transpose();
    let chol = aat.cholesky().expect("A A^T positive definite: distinct measurements");
    let pinv = |r: &DVector<f64>| a.transpose() * chol.solve(r);
    let mut s = pinv(y);
    let mut sigma = 2.0 * s.amax();
    let sigma_min = f64::from(cfg.sigma_min) * sigma.max(1e-12) / 2.0;
    while sigma > sigma_min {
        for _ in 0..cfg.steps {
            let delta = s.map(|x| x * (-x * x / (2.0 * sigma * sigma)).exp());
            s -= f64::from(cfg.mu) * delta;
            let r = a * &s - y;
            s -= pinv(&r);
        }
        sigma *= f64::from(cfg.sigma_f);
    }
    s
}

/// An orthonormal `n x n` operator that shifts a signal by `g` samples (`x[s] = z(s + g)`):
/// the polar factor (`U V^T` of the SVD) of `z`'s DCT-II interpolant evaluated at `s + g`
/// (`polar`), or the band-limited periodic (DFT) interpolant, which is orthogonal for odd
/// `n` (`!polar`).
fn orthonormal_shift(n: usize, g: f64, polar: bool) -> Vec<Vec<f64>> {
    use std::f64::consts::PI;
    let m = if polar {
        let c = dct(n);
        let a = |k: usize| if k == 0 { (1.0 / n as f64).sqrt() } else { (2.0 / n as f64).sqrt() };
        let e = DMatrix::from_fn(n, n, |s, j| {
            (0..n).map(|k| a(k) * (PI * (s as f64 + g + 0.5) * k as f64 / n as f64).cos() * c[k][j]).sum::<f64>()
        });
        let svd = e.svd(true, true);
        svd.u.expect("u") * svd.v_t.expect("v_t")
    } else {
        let h = (n as i64 - 1) / 2;
        DMatrix::from_fn(n, n, |s, j| {
            let q = s as f64 + g - j as f64;
            (-h..=h).map(|k| (2.0 * PI * k as f64 * q / n as f64).cos()).sum::<f64>() / n as f64
        })
    };
    (0..n).map(|r| (0..n).map(|c| m[(r, c)]).collect()).collect()
}

/// Bilinear weights of a patch position `(qs, qt)` in `[0, 4]^2` over the 5 x 5 grid.
fn bilinear(qs: f64, qt: f64) -> Vec<((usize, usize), f64)> {
    let (s0, t0) = ((qs.floor() as usize).min(3), (qt.floor() as usize).min(3));
    let (fs, ft) = (qs - s0 as f64, qt - t0 as f64);
    let mut w = Vec::with_capacity(4);
    for (ds, ws) in [(0, 1.0 - fs), (1, fs)] {
        for (dt, wt) in [(0, 1.0 - ft), (1, ft)] {
            if ws * wt > 1e-12 {
                w.push(((s0 + ds, t0 + dt), ws * wt));
            }
        }
    }
    w
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    ensure!(args.len() == 4, "usage: fractional_shear LF.npy DISPARITY.npy MAP_ROW0 MAP_COL0");
    let truth = read_npy(std::path::Path::new(&args[0]))?;
    let map_file = npyz::NpyFile::new(std::fs::File::open(&args[1]).context("disparity map")?)?;
    let map_shape: Vec<usize> = map_file.shape().iter().map(|&x| x as usize).collect();
    let map: Vec<f32> = map_file.into_vec()?;
    let (r0, c0): (usize, usize) = (args[2].parse()?, args[3].parse()?);
    let disparity = |y: usize, x: usize| f64::from(map[(r0 + y) * map_shape[1] + c0 + x]);
    let capture = simulate(&truth, &CameraConfig::pixel(3, 1).noiseless())?;
    let opts = DecodeOptions::default();
    let decoder = tile_decoder::<4, 4, 5200>(&capture, &opts)?;
    let (gains, raw_format) = (*decoder.gains(), decoder.config().raw);
    let mask = decoder.config().mask;
    let raw = capture.raw_frames()?;
    let mut source = FrameSource::new(&raw);
    let (rows, cols) = (truth.rows, truth.cols);
    let c5 = dct(5);
    let c4 = dct(4);
    let c13 = dct(13);
    let cfg = Sl0Config::DEFAULT;
    // The window of views 0..4 x 0..4 of the 5 x 5 lenslet: view offsets from the centre.
    let du = |u: usize| u as f64 - 2.0;
    let names = [
        "integer n",
        "integer n + 1",
        "n + 0.5 rounded",
        "n + 0.5 exact",
        "n + 0.5 orthonormal shift (polar of the DCT interpolant)",
        "n + 0.5 orthonormal shift (periodic DFT interpolant)",
    ];
    // The orthonormal variants read each view at the integer part `floor(shift)` of its
    // shift (a selection) and model the rest, 0 or 0.5, in the dictionary: `A = P H K`,
    // `H` per view the orthonormal shift by `-(shift - floor(shift))`.
    let half = [orthonormal_shift(5, -0.5, true), orthonormal_shift(5, -0.5, false)];
    let identity: Vec<Vec<f64>> = (0..5).map(|r| (0..5).map(|c| f64::from(u8::from(r == c))).collect()).collect();
    let mut err = [0.0f64; 6];
    let (mut count, mut blocks) = (0usize, 0usize);
    // Blocks in an order that spreads the first ones over the frame (every 3rd position).
    let positions: Vec<(usize, usize)> =
        (4..rows - 9).step_by(5).flat_map(|by| (4..cols - 9).step_by(5).map(move |bx| (by, bx))).collect();
    let order = (0..3).flat_map(|phase| positions.iter().skip(phase).step_by(3).copied());
    for (by, bx) in order {
        {
            let ds: Vec<f64> =
                (0..5).flat_map(|s| (0..5).map(move |t| (s, t))).map(|(s, t)| disparity(by + s, bx + t)).collect();
            let mean = ds.iter().sum::<f64>() / 25.0;
            let spread = ds.iter().map(|d| (d - mean).abs()).fold(0.0, f64::max);
            let n = (mean - 0.5).round();
            if (mean - n - 0.5).abs() > 0.12 || spread > 0.25 {
                continue;
            }
            // At most `MAX_BLOCKS` (a block costs seconds), spread over the frame.
            if blocks >= MAX_BLOCKS {
                continue;
            }
            blocks += 1;
            // Each variant: the shift of view u (lenslets), and whether to interpolate.
            let shifts: [Box<dyn Fn(usize) -> f64>; 6] = [
                Box::new(move |u| -n * du(u)),
                Box::new(move |u| -(n + 1.0) * du(u)),
                Box::new(move |u| {
                    let x = -(n + 0.5) * du(u);
                    x.signum() * (x.abs() + 0.5).floor()
                }),
                Box::new(move |u| -(n + 0.5) * du(u)),
                Box::new(move |u| (-(n + 0.5) * du(u)).floor()),
                Box::new(move |u| (-(n + 0.5) * du(u)).floor()),
            ];
            let fractional = |u: usize| -(n + 0.5) * du(u) - (-(n + 0.5) * du(u)).floor() > 0.25;
            // The sensor pixels near the block, and where each variant puts them in its patch.
            // Row `y` in view row `u` (or column `x` in view column `w`, from `bx`).
            let pos = |v: usize, y: usize, u: usize| y as f64 - by as f64 - shifts[v](u);
            let pos_c = |v: usize, x: usize, w: usize| x as f64 - bx as f64 - shifts[v](w);
            let inside = |q: f64| (-1e-9..=4.0 + 1e-9).contains(&q);
            let mut estimates: Vec<Vec<f64>> = Vec::new();
            let mut pixels: Vec<(usize, usize, usize, usize)> = Vec::new();
            for y in by.saturating_sub(6)..(by + 11).min(rows) {
                for x in bx.saturating_sub(6)..(bx + 11).min(cols) {
                    for u in 0..4 {
                        for w in 0..4 {
                            if (0..6).all(|v| inside(pos(v, y, u)) && inside(pos_c(v, x, w))) {
                                pixels.push((y, x, u, w));
                            }
                        }
                    }
                }
            }
            for v in 0..6 {
                // The view's orthonormal shift along s and t (orthonormal variants only).
                let h = |u: usize| if v >= 4 && fractional(u) { &half[v - 4] } else { &identity };
                let weights_of = |qs: f64, qt: f64, u: usize, w: usize| -> Vec<((usize, usize), f64)> {
                    if v < 4 {
                        return bilinear(qs, qt);
                    }
                    let (q, r) = (qs.round() as usize, qt.round() as usize);
                    let (hs, ht) = (h(u), h(w));
                    (0..5).flat_map(|a| (0..5).map(move |b| ((a, b), hs[q][a] * ht[r][b]))).collect()
                };
                // Measurement rows: a sensor pixel's one band, as weights over patch entries.
                let mut rows_a: Vec<Vec<(usize, f64)>> = Vec::new();
                let mut ys = Vec::new();
                for y in by.saturating_sub(6)..(by + 11).min(rows) {
                    for x in bx.saturating_sub(6)..(bx + 11).min(cols) {
                        for u in 0..4 {
                            for w in 0..4 {
                                let (qs, qt) = (pos(v, y, u), pos_c(v, x, w));
                                if !(inside(qs) && inside(qt)) {
                                    continue;
                                }
                                let (row, col) = (y * 5 + u, x * 5 + w);
                                let mut sample = [0.0f32];
                                source.read(0, row, col, &mut sample).map_err(|e| anyhow::anyhow!("{e:?}"))?;
                                let b = usize::from(mask.band(0, row, col).context("band")?);
                                let Ok(value) = raw_format.classify(sample[0]) else { continue };
                                let weights = weights_of(qs, qt, u, w)
                                    .into_iter()
                                    .map(|((s, t), wt)| ((((s * 5 + t) * 4 + u) * 4 + w) * 13 + b, wt))
                                    .collect();
                                rows_a.push(weights);
                                ys.push(f64::from(value / gains[b]));
                            }
                        }
                    }
                }
                // A = M K, K the dense 5D DCT synthesis: K[i][j] = prod of the 1D atoms.
                let idx = |i: usize| [i / 1040, (i / 208) % 5, (i / 52) % 4, (i / 13) % 4, i % 13];
                let k_entry = |i: usize, j: usize| {
                    let (a, b) = (idx(i), idx(j));
                    c5[b[0]][a[0]] * c5[b[1]][a[1]] * c4[b[2]][a[2]] * c4[b[3]][a[3]] * c13[b[4]][a[4]]
                };
                let a = DMatrix::from_fn(rows_a.len(), 5200, |r, j| {
                    rows_a[r].iter().map(|&(i, wt)| wt * k_entry(i, j)).sum()
                });
                let s = sl0(&a, &DVector::from_vec(ys), &cfg);
                let patch = synthesize(&s, [&c5, &c5, &c4, &c4, &c13]);
                // The estimate at each common pixel, all bands: the patch interpolated there.
                let mut est = Vec::with_capacity(pixels.len() * 13);
                for &(y, x, u, w) in &pixels {
                    for b in 0..13 {
                        let value: f64 = weights_of(pos(v, y, u), pos_c(v, x, w), u, w)
                            .iter()
                            .map(|&((ps, pt), wt)| wt * patch[(((ps * 5 + pt) * 4 + u) * 4 + w) * 13 + b])
                            .sum();
                        est.push(value * f64::from(gains[b]));
                    }
                }
                estimates.push(est);
            }
            for (v, est) in estimates.iter().enumerate() {
                let mut i = 0;
                for &(y, x, u, w) in &pixels {
                    for b in 0..13 {
                        err[v] += (est[i] - f64::from(truth.get(u, w, y, x, b))).powi(2);
                        i += 1;
                    }
                }
            }
            count += pixels.len() * 13;
            eprintln!("block ({by}, {bx}) disparity {mean:.2}: {} common pixels", pixels.len());
        }
    }
    ensure!(count > 0, "no block with a disparity near a half-integer");
    let peak = truth.data.iter().fold(0.0f32, |m, &x| m.max(x));
    println!("{blocks} blocks, {count} values");
    for (name, e) in names.iter().zip(err) {
        println!("{name}: PSNR {:.2} dB", 10.0 * (f64::from(peak).powi(2) / (e / count as f64)).log10());
    }
    Ok(())
}
