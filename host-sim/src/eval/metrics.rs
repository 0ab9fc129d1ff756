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

use anyhow::{Result, ensure};

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

/// PSNR in dB for the given data range (infinite for identical inputs).
pub fn psnr(truth: &[f32], recon: &[f32], data_range: f64) -> f64 {
    let mse =
        truth.iter().zip(recon).map(|(&a, &b)| (f64::from(a) - f64::from(b)).powi(2)).sum::<f64>() / truth.len() as f64;
    10.0 * (data_range * data_range / mse).log10()
}

const SIGMA: f64 = 1.5;
/// scipy's kernel radius `int(truncate * sigma + 0.5)` with truncate 3.5.
const RADIUS: usize = 5;
const WIN: usize = 2 * RADIUS + 1;

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
