//! Quality metrics of a reconstruction against the ground truth.
//!
//! - PSNR with data range = the maximum of the ground truth (skimage's
//!   `peak_signal_noise_ratio(truth, recon, data_range=truth.max())`).
//! - SSIM after Wang et al. 2004: Gaussian window sigma 1.5 (radius 5, scipy's truncate 3.5),
//!   K1 0.01, K2 0.03, population covariances, computed per spatial slice (each view and
//!   band) and averaged; each slice's SSIM is the mean over pixels at least 5 from the
//!   border, as skimage's `structural_similarity(gaussian_weights=True, sigma=1.5,
//!   use_sample_covariance=False, data_range=..)` crops it.
//! - Spectral angle in degrees between truth and reconstructed spectra, mean over pixels
//!   (every view) whose true spectrum is not zero; a zero reconstruction there counts 90.
//!
//! All in f64. `tests/metrics_fixtures.rs` proves them against scikit-image to 1e-4.

use anyhow::{Result, bail, ensure};

use crate::decode::cs::estimated_psnr;
use crate::io::lightfield::LightField;

/// PSNR, SSIM and spectral angle of one reconstruction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// dB.
    pub psnr: f64,
    /// The data range PSNR and SSIM used: the maximum of the ground truth.
    pub data_range: f64,
    pub ssim: f64,
    /// Degrees.
    pub sa: f64,
}

/// All three metrics.
///
/// # Errors
/// Shapes that differ, a ground truth with no positive value, or slices smaller than SSIM's
/// 11 x 11 window.
pub fn evaluate(truth: &LightField, recon: &LightField) -> Result<Metrics> {
    ensure!(
        truth.shape() == recon.shape(),
        "shapes differ: truth {:?}, reconstruction {:?}",
        truth.shape(),
        recon.shape()
    );
    let data_range = f64::from(truth.max());
    ensure!(data_range > 0.0, "the ground truth has no positive value (data range 0)");
    ensure!(truth.rows >= WIN && truth.cols >= WIN, "SSIM needs slices of at least {WIN} x {WIN} pixels");
    Ok(Metrics {
        psnr: psnr(&truth.data, &recon.data, data_range),
        data_range,
        ssim: ssim(truth, recon, data_range),
        sa: spectral_angle(truth, recon),
    })
}

/// The blocks of `BLOCK x BLOCK` lenslets (the grid from lenslet (0, 0), whole blocks
/// only) whose reconstructed maximum exceeds twice the truth's maximum there plus 0.05,
/// and how many blocks there are: a decode that lit up a dark region (issue 49's measure of
/// a failure nobody flagged). Shapes must agree (checked by [`evaluate`]).
pub fn blocks_over(truth: &LightField, recon: &LightField) -> (usize, usize) {
    let (rows, cols) = (truth.rows / BLOCK, truth.cols / BLOCK);
    let (mut tmax, mut rmax) = (vec![f32::NEG_INFINITY; rows * cols], vec![f32::NEG_INFINITY; rows * cols]);
    for (i, (&t, &r)) in truth.data.iter().zip(&recon.data).enumerate() {
        let (_, _, y, x, _) = truth.coordinates(i);
        let (by, bx) = (y / BLOCK, x / BLOCK);
        if by < rows && bx < cols {
            let k = by * cols + bx;
            tmax[k] = tmax[k].max(t);
            // A NaN in the reconstruction is above any bound.
            rmax[k] = if r.is_nan() { f32::INFINITY } else { rmax[k].max(r) };
        }
    }
    let over = tmax.iter().zip(&rmax).filter(|(t, r)| **r > 2.0 * **t + 0.05).count();
    (over, rows * cols)
}

/// How well an error map (one estimate a lenslet, row-major, RMS per value, NaN where none)
/// predicts the true error of `recon`, on blocks of [`BLOCK`] x [`BLOCK`] lenslets (a
/// patch's; whole blocks only, and blocks with an estimate at every lenslet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapAccuracy {
    /// Blocks compared.
    pub blocks: usize,
    /// Spearman's rank correlation of the blocks' estimated and true RMS errors.
    pub rank_correlation: f64,
    /// The share of blocks whose estimate lies within a factor of 2 of the true RMS error.
    pub within_2x: f64,
    /// The estimated PSNR at the truth's data range (the map's mean squared estimate).
    pub estimated_psnr: f64,
}

/// Refuses an error map (row-major, `cols` lenslets a row) with a negative or infinite
/// value: an RMS error is neither (NaN: a lenslet not estimated), and a negative one's
/// square would score as an error.
///
/// # Errors
/// The first such value, by lenslet.
pub fn check_error_map(map: &[f32], cols: usize) -> Result<()> {
    if let Some(i) = map.iter().position(|e| *e < 0.0 || e.is_infinite()) {
        bail!(
            "the error map's value at lenslet ({}, {}) is {}: an RMS error is finite and not negative (NaN where \
             none was estimated)",
            i / cols.max(1),
            i % cols.max(1),
            map[i]
        );
    }
    Ok(())
}

/// [`MapAccuracy`] of `map` (`truth.rows x truth.cols`).
///
/// # Errors
/// A map of another size, a negative or infinite value ([`check_error_map`]), or no block to
/// compare.
pub fn map_accuracy(truth: &LightField, recon: &LightField, map: &[f32]) -> Result<MapAccuracy> {
    ensure!(
        truth.shape() == recon.shape(),
        "shapes differ: truth {:?}, reconstruction {:?}",
        truth.shape(),
        recon.shape()
    );
    ensure!(
        map.len() == truth.rows * truth.cols,
        "the error map has {} values, the light field {} x {} lenslets",
        map.len(),
        truth.rows,
        truth.cols
    );
    check_error_map(map, truth.cols)?;
    let (rows, cols) = (truth.rows / BLOCK, truth.cols / BLOCK);
    let mut err2 = vec![0.0f64; rows * cols];
    let mut n = vec![0usize; rows * cols];
    for (i, (&t, &r)) in truth.data.iter().zip(&recon.data).enumerate() {
        let (_, _, y, x, _) = truth.coordinates(i);
        if y / BLOCK < rows && x / BLOCK < cols {
            let k = (y / BLOCK) * cols + x / BLOCK;
            err2[k] += (f64::from(r) - f64::from(t)).powi(2);
            n[k] += 1;
        }
    }
    let (mut est, mut truth_rms) = (Vec::new(), Vec::new());
    for by in 0..rows {
        for bx in 0..cols {
            let mut e2 = 0.0f64;
            let mut whole = true;
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    let e = f64::from(map[y * truth.cols + x]);
                    whole &= e.is_finite();
                    e2 += e * e;
                }
            }
            if whole {
                let k = by * cols + bx;
                est.push((e2 / (BLOCK * BLOCK) as f64).sqrt());
                truth_rms.push((err2[k] / n[k].max(1) as f64).sqrt());
            }
        }
    }
    ensure!(!est.is_empty(), "no block of {BLOCK} x {BLOCK} lenslets has an estimate at every lenslet");
    let within = est.iter().zip(&truth_rms).filter(|(e, t)| **e <= 2.0 * **t && **t <= 2.0 * **e).count();
    // A block with an estimate at every lenslet: the map has a finite value.
    let estimated_psnr = estimated_psnr(map, f64::from(truth.max())).unwrap_or(f64::NAN);
    Ok(MapAccuracy {
        blocks: est.len(),
        rank_correlation: spearman(&est, &truth_rms),
        within_2x: within as f64 / est.len() as f64,
        estimated_psnr,
    })
}

/// Spearman's rank correlation of `a` and `b` (ties take their mean rank): the Pearson
/// correlation of the ranks; 0 when either is constant.
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 { 0.0 } else { sab / (saa * sbb).sqrt() }
}

/// The rank of each value of `x` (1-based; ties their mean rank).
fn ranks(x: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&i, &j| x[i].total_cmp(&x[j]));
    let mut r = vec![0.0; x.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && x[order[j + 1]] == x[order[i]] {
            j += 1;
        }
        let mean = (i + j) as f64 / 2.0 + 1.0;
        for &k in &order[i..=j] {
            r[k] = mean;
        }
        i = j + 1;
    }
    r
}

/// The block side of [`blocks_over`], in lenslets: the disparity choice's block.
pub const BLOCK: usize = 5;

/// PSNR in dB for the given data range (infinite for identical inputs).
pub fn psnr(truth: &[f32], recon: &[f32], data_range: f64) -> f64 {
    let mse =
        truth.iter().zip(recon).map(|(&a, &b)| (f64::from(a) - f64::from(b)).powi(2)).sum::<f64>() / truth.len() as f64;
    10.0 * (data_range * data_range / mse).log10()
}

const SIGMA: f64 = 1.5;
/// scipy's kernel radius `int(truncate * sigma + 0.5)` with truncate 3.5.
const RADIUS: usize = 5;
/// SSIM's window: a slice (lenslets) must be at least this on each side.
pub const WIN: usize = 2 * RADIUS + 1;

fn kernel() -> [f64; WIN] {
    let mut k: [f64; WIN] = core::array::from_fn(|i| {
        let x = i as f64 - RADIUS as f64;
        (-0.5 * x * x / (SIGMA * SIGMA)).exp()
    });
    let s: f64 = k.iter().sum();
    k.iter_mut().for_each(|x| *x /= s);
    k
}

/// Gaussian filter at the positions at least RADIUS from every border ("valid" output,
/// `(h - 2R) x (w - 2R)`); the only positions SSIM's crop keeps, so the boundary mode does
/// not matter.
fn filter_valid(img: &[f64], h: usize, w: usize, k: &[f64; WIN]) -> Vec<f64> {
    let (oh, ow) = (h - 2 * RADIUS, w - 2 * RADIUS);
    let mut rows = vec![0.0; h * ow];
    for y in 0..h {
        for x in 0..ow {
            rows[y * ow + x] = (0..WIN).map(|i| k[i] * img[y * w + x + i]).sum();
        }
    }
    let mut out = vec![0.0; oh * ow];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = (0..WIN).map(|i| k[i] * rows[(y + i) * ow + x]).sum();
        }
    }
    out
}

/// SSIM of two `h x w` images (f64), skimage's definition (see the module docs).
pub fn ssim_2d(a: &[f64], b: &[f64], h: usize, w: usize, data_range: f64) -> f64 {
    let k = kernel();
    let prod = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(x, y)| x * y).collect::<Vec<f64>>();
    let ux = filter_valid(a, h, w, &k);
    let uy = filter_valid(b, h, w, &k);
    let uxx = filter_valid(&prod(a, a), h, w, &k);
    let uyy = filter_valid(&prod(b, b), h, w, &k);
    let uxy = filter_valid(&prod(a, b), h, w, &k);
    let c1 = (0.01 * data_range).powi(2);
    let c2 = (0.03 * data_range).powi(2);
    let n = ux.len();
    (0..n)
        .map(|i| {
            let (mx, my) = (ux[i], uy[i]);
            let (vx, vy, vxy) = (uxx[i] - mx * mx, uyy[i] - my * my, uxy[i] - mx * my);
            ((2.0 * mx * my + c1) * (2.0 * vxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
        })
        .sum::<f64>()
        / n as f64
}

/// Mean SSIM over every spatial slice (each view and band).
pub fn ssim(truth: &LightField, recon: &LightField, data_range: f64) -> f64 {
    let (h, w) = (truth.rows, truth.cols);
    let slice = |lf: &LightField, u, v, b| -> Vec<f64> {
        (0..h * w).map(|p| f64::from(lf.get(u, v, p / w, p % w, b))).collect()
    };
    let mut total = 0.0;
    let mut n = 0;
    for u in 0..truth.views.0 {
        for v in 0..truth.views.1 {
            for b in 0..truth.bands {
                total += ssim_2d(&slice(truth, u, v, b), &slice(recon, u, v, b), h, w, data_range);
                n += 1;
            }
        }
    }
    total / n as f64
}

/// Mean spectral angle in degrees (see the module docs).
pub fn spectral_angle(truth: &LightField, recon: &LightField) -> f64 {
    let bands = truth.bands;
    let mut total = 0.0;
    let mut n = 0usize;
    for (t, r) in truth.data.chunks_exact(bands).zip(recon.data.chunks_exact(bands)) {
        let tt: f64 = t.iter().map(|&x| f64::from(x).powi(2)).sum();
        if tt == 0.0 {
            continue;
        }
        let rr: f64 = r.iter().map(|&x| f64::from(x).powi(2)).sum();
        let angle = if rr == 0.0 {
            90.0
        } else {
            let tr: f64 = t.iter().zip(r).map(|(&a, &b)| f64::from(a) * f64::from(b)).sum();
            (tr / (tt.sqrt() * rr.sqrt())).clamp(-1.0, 1.0).acos().to_degrees()
        };
        total += angle;
        n += 1;
    }
    if n == 0 { 0.0 } else { total / n as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spearman_is_the_rank_correlation() {
        let a = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert!((spearman(&a, &[10.0, 20.0, 25.0, 100.0, 1e3]) - 1.0).abs() < 1e-12);
        assert!((spearman(&a, &[5.0, 4.0, 3.0, 2.0, 1.0]) + 1.0).abs() < 1e-12);
        // By the formula for distinct ranks, 1 - 6 sum d^2 / (n (n^2 - 1)): d = (1, -1, 0, 0, 0).
        let rho = spearman(&a, &[2.0, 1.0, 3.0, 4.0, 5.0]);
        assert!((rho - (1.0 - 6.0 * 2.0 / 120.0)).abs() < 1e-12, "{rho}");
        // Ties take their mean rank; a constant has no correlation.
        assert_eq!(ranks(&[3.0, 1.0, 3.0, 2.0]), [3.5, 1.0, 3.5, 2.0]);
        assert_eq!(spearman(&a, &[1.0; 5]), 0.0);
    }

    /// A 10 x 10-lenslet light field of 2 x 2 views and 3 bands, `f(y, x)` everywhere.
    fn field(f: impl Fn(usize, usize) -> f32) -> LightField {
        LightField::from_fn((2, 2), 10, 10, 3, |_, _, y, x, _| f(y, x))
    }

    #[test]
    fn blocks_decoded_far_above_their_truth_are_counted() {
        let truth = field(|y, _| if y < 5 { 0.01 } else { 0.5 });
        // A dark block lit to 0.08 (above 2 x 0.01 + 0.05) and a bright one to 1.0 (not
        // above 2 x 0.5 + 0.05): one block over of four.
        let recon = field(|y, x| match (y, x) {
            (1, 1) => 0.08,
            (7, 7) => 1.0,
            _ if y < 5 => 0.01,
            _ => 0.5,
        });
        assert_eq!(blocks_over(&truth, &recon), (1, 4));
        assert_eq!(blocks_over(&truth, &truth), (0, 4));
        let nan = field(|y, x| if (y, x) == (6, 1) { f32::NAN } else { 0.0 });
        assert_eq!(blocks_over(&truth, &nan), (1, 4));
    }

    #[test]
    fn a_map_of_the_true_error_is_exact() {
        let truth = field(|y, x| 0.2 + 0.01 * (y * 10 + x) as f32);
        // Each block's error a different constant: the map of it ranks perfectly.
        let err = |y: usize, x: usize| 0.001 * (1 + (y / 5) * 2 + x / 5) as f32;
        let recon = field(|y, x| 0.2 + 0.01 * (y * 10 + x) as f32 + err(y, x));
        let map: Vec<f32> = (0..100).map(|i| err(i / 10, i % 10)).collect();
        let a = map_accuracy(&truth, &recon, &map).unwrap();
        assert_eq!((a.blocks, a.within_2x), (4, 1.0));
        assert!((a.rank_correlation - 1.0).abs() < 1e-12);
        let true_psnr = psnr(&truth.data, &recon.data, f64::from(truth.max()));
        assert!((a.estimated_psnr - true_psnr).abs() < 1e-3, "{} against {true_psnr}", a.estimated_psnr);
        // Four times the error: none within 2 x, the same ranks.
        let far: Vec<f32> = map.iter().map(|e| 4.0 * e).collect();
        assert_eq!(map_accuracy(&truth, &recon, &far).unwrap().within_2x, 0.0);
        // A block with a NaN lenslet is left out; a map of another size is refused.
        let mut holed = map.clone();
        holed[0] = f32::NAN;
        assert_eq!(map_accuracy(&truth, &recon, &holed).unwrap().blocks, 3);
        assert!(map_accuracy(&truth, &recon, &map[..99]).unwrap_err().to_string().contains("99 values"));
    }
}
