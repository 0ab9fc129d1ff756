//! PPID: multispectral demosaicking by the pseudo-panchromatic image, after S. Mihoubi,
//! O. Losson, B. Mathon and L. Macaire, "Multispectral Demosaicing Using
//! Pseudo-Panchromatic Image", IEEE Transactions on Computational Imaging 3(4), 2017.
//!
//! The method, as published for periodic filter arrays: (1) a pseudo-panchromatic image
//! (PPI, the mean over bands) is estimated by a low-pass of the raw mosaic, then sharpened
//! at each pixel by its own raw value plus the local difference between the PPI and the
//! raw values of the same band; (2) each band is the PPI plus the band's difference to the
//! PPI, interpolated from the pixels that measured it with edge-sensing weights (large
//! where the PPI is alike). Demosaicking in the difference domain keeps the edges the PPI
//! carries, which plain per-band interpolation blurs.
//!
//! slf's filter array is random per pixel and spread over views, so two steps are adapted:
//! the low-pass is the band-balanced mean of the neighbourhood's per-band estimates (a
//! periodic array's averaging kernel balances the bands by construction; a random one does
//! not), and neighbours are all views of the lenslets within [`PpidConfig::radius`],
//! weighted by a Gaussian of the lenslet distance times the edge-sensing weight
//! `1 / (epsilon + |P(p) - P(q)|)`. Measured bands keep their measured values.
//!
//! Streamed down the frame: output row `s` reads the PPI of rows `s ± radius`, which read
//! the coarse PPI of rows `s ± 2 radius`, which read the measurements of rows `s ± 3
//! radius`; each stage is held for the rows still ahead of it ([`super::lagged`]).

use anyhow::{Result, ensure};
use rayon::prelude::*;

use super::lagged::{Lagged, around};
use super::measurements::Reader;
use super::neighbourhood::{Measured, estimate, gauss};
use super::{BaselineReport, Emit};
use crate::io::rows::Rows;

/// The pseudo-panchromatic demosaic's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PpidConfig {
    /// Lenslets either side that contribute.
    pub radius: usize,
    /// Standard deviation of the Gaussian weight, in lenslets.
    pub sigma: f32,
    /// The edge-sensing weight is `1 / (epsilon + |P(p) - P(q)|)` (white = 1 units).
    pub epsilon: f32,
}

impl Default for PpidConfig {
    /// As the neighbourhood demosaic (radius 2, sigma 1 lenslet); epsilon 0.02.
    fn default() -> Self {
        Self { radius: 2, sigma: 1.0, epsilon: 0.02 }
    }
}

impl PpidConfig {
    /// # Errors
    /// A sigma or epsilon out of range.
    pub(super) fn check(&self) -> Result<()> {
        ensure!(self.sigma.is_finite() && self.sigma > 0.0, "ppid sigma {} must be above 0", self.sigma);
        ensure!(self.epsilon.is_finite() && self.epsilon > 0.0, "ppid epsilon {} must be above 0", self.epsilon);
        Ok(())
    }
}

/// A lenslet row's neighbourhood estimates (`T x B`) and their band means, the coarse PPI
/// (`T`).
struct Coarse {
    estimate: Vec<f32>,
    coarse: Vec<f32>,
}

/// Step 1 for lenslet row `s`: the PPI at each position (`T x UV`), its own values plus
/// the local difference between the coarse PPI and the raw values of the same band. That
/// difference's sums depend on the lenslet and the band alone (the neighbourhood is the
/// lenslets around), so they are summed once a lenslet for every band.
fn ppi_row(
    read: &Lagged<Measured>,
    coarse: &Lagged<Coarse>,
    s: usize,
    reader: &Reader<'_>,
    cfg: &PpidConfig,
) -> Vec<f32> {
    let ((rows, lt), nb) = (reader.lenslets, reader.bands);
    let uv = reader.views.0 * reader.views.1;
    let here = coarse.get(s);
    let mine = &read.get(s).row;
    let mut ppi = vec![0.0f32; lt * uv];
    ppi.par_chunks_mut(uv).enumerate().for_each(|(t, ppi)| {
        let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
        for ss in around(s, cfg.radius, rows) {
            let (theirs, c) = (&read.get(ss).row, &coarse.get(ss).coarse);
            for tt in around(t, cfg.radius, lt) {
                let g = gauss(ss as isize - s as isize, tt as isize - t as isize, cfg.sigma);
                for own in theirs.lenslet(tt) {
                    for &(b, x) in own {
                        num[usize::from(b)] += g * (c[tt] - x);
                        den[usize::from(b)] += g;
                    }
                }
            }
        }
        let (c, e) = (here.coarse[t], &here.estimate[t * nb..(t + 1) * nb]);
        for (k, p) in ppi.iter_mut().enumerate() {
            let own = mine.at(t, k);
            *p = if own.is_empty() {
                c
            } else {
                let sum: f32 = own
                    .iter()
                    .map(|&(b, x)| {
                        let b = usize::from(b);
                        x + if den[b] > 0.0 { num[b] / den[b] } else { c - e[b] }
                    })
                    .sum();
                sum / own.len() as f32
            };
        }
    });
    ppi
}

/// PPID over every lenslet row of `reader`'s capture into `sink`, in order. Held: the
/// measurements of `4 radius + 1` lenslet rows, the estimates of `2 radius + 1`, the PPI
/// of `2 radius + 1`.
pub(super) fn stream(reader: &Reader<'_>, cfg: &PpidConfig, sink: &mut Rows<'_>) -> Result<BaselineReport> {
    cfg.check()?;
    let (rows, lt) = reader.lenslets;
    let (uv, nb, r) = (reader.views.0 * reader.views.1, reader.bands, cfg.radius);
    let mut emit = Emit::new(reader);
    let mut report = BaselineReport::default();
    let mut read: Lagged<Measured> = Lagged::new();
    let mut coarse: Lagged<Coarse> = Lagged::new();
    let mut ppi: Lagged<Vec<f32>> = Lagged::new();
    let mut out = vec![0.0f32; lt * uv * nb];
    for s in 0..rows {
        read.fill_to(s + 3 * r, rows, |s| Measured::read(reader, s))?;
        coarse.fill_to(s + 2 * r, rows, |s| {
            let estimate = estimate(&read, s, reader, r, cfg.sigma);
            let coarse = estimate.chunks_exact(nb).map(|e| e.iter().sum::<f32>() / nb as f32).collect();
            Ok(Coarse { estimate, coarse })
        })?;
        ppi.fill_to(s + r, rows, |s| Ok(ppi_row(&read, &coarse, s, reader, cfg)))?;
        // Step 2: each band is the PPI plus the band's difference to it, interpolated with
        // edge-sensing weights.
        let (here, mine, ppi_here) = (coarse.get(s), &read.get(s).row, ppi.get(s));
        out.par_chunks_mut(nb).enumerate().for_each(|(p, o)| {
            let (t, k) = (p / uv, p % uv);
            let pp = ppi_here[p];
            let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
            for ss in around(s, r, rows) {
                let (theirs, pq_row) = (&read.get(ss).row, ppi.get(ss));
                for tt in around(t, r, lt) {
                    let g = gauss(ss as isize - s as isize, tt as isize - t as isize, cfg.sigma);
                    for (j, own) in theirs.lenslet(tt).enumerate() {
                        let pq = pq_row[tt * uv + j];
                        let w = g / (cfg.epsilon + (pp - pq).abs());
                        for &(b, x) in own {
                            num[usize::from(b)] += w * (x - pq);
                            den[usize::from(b)] += w;
                        }
                    }
                }
            }
            let (e, c) = (&here.estimate[t * nb..(t + 1) * nb], here.coarse[t]);
            for (b, o) in o.iter_mut().enumerate() {
                *o = pp + if den[b] > 0.0 { num[b] / den[b] } else { e[b] - c };
            }
            for &(b, x) in mine.at(t, k) {
                o[usize::from(b)] = x;
            }
        });
        report.tally(mine);
        emit.row(s, &out, sink)?;
        // Row s + 1 reads the PPI and measurements from row s + 1 - radius, and its PPI
        // row (s + 1 + radius) the coarse PPI from row s + 1.
        read.keep_from((s + 1).saturating_sub(r));
        coarse.keep_from(s + 1);
        ppi.keep_from((s + 1).saturating_sub(r));
    }
    report.ensure_measured(reader)?;
    Ok(report)
}
