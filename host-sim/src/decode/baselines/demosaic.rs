//! The neighbourhood demosaic: each band estimated from the pixels that measured it nearby
//! ([`super::neighbourhood`]), then matched to each pixel's own measurements (scaled by the
//! ratio of its measured values to the estimate at those bands, the colour-ratio rule of
//! classic demosaicking, limited to [`DemosaicConfig::max_ratio`]); the measured bands keep
//! their measured values.

use anyhow::{Result, ensure};
use rayon::prelude::*;

use super::lagged::Lagged;
use super::measurements::Reader;
use super::neighbourhood::{Measured, estimate};
use super::{BaselineReport, Emit};
use crate::io::rows::Rows;

/// The neighbourhood demosaic's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemosaicConfig {
    /// Lenslets either side that contribute to a band's estimate.
    pub radius: usize,
    /// Standard deviation of the Gaussian weight, in lenslets.
    pub sigma: f32,
    /// Largest factor (and smallest, as its inverse) by which the match to a pixel's own
    /// measurements scales the neighbourhood's spectrum.
    pub max_ratio: f32,
}

impl Default for DemosaicConfig {
    /// Radius 2 (5 x 5 lenslets, 625 samples at 5 x 5 views: about 48 a band at one
    /// snapshot), sigma 1 lenslet, ratios within 1/4..4.
    fn default() -> Self {
        Self { radius: 2, sigma: 1.0, max_ratio: 4.0 }
    }
}

impl DemosaicConfig {
    /// # Errors
    /// A sigma or ratio out of range.
    pub(super) fn check(&self) -> Result<()> {
        ensure!(self.sigma.is_finite() && self.sigma > 0.0, "demosaic sigma {} must be above 0", self.sigma);
        ensure!(
            self.max_ratio.is_finite() && self.max_ratio >= 1.0,
            "demosaic max_ratio {} must be >= 1",
            self.max_ratio
        );
        Ok(())
    }
}

/// Demosaics every lenslet row of `reader`'s capture into `sink`, in order. Held: the
/// measurements and sums of `radius + 1` lenslet rows.
pub(super) fn stream(reader: &Reader<'_>, cfg: &DemosaicConfig, sink: &mut Rows<'_>) -> Result<BaselineReport> {
    cfg.check()?;
    let (rows, lt) = reader.lenslets;
    let (uv, nb, r) = (reader.views.0 * reader.views.1, reader.bands, cfg.radius);
    let mut emit = Emit::new(reader);
    let mut report = BaselineReport::default();
    let mut read: Lagged<Measured> = Lagged::new();
    let mut out = vec![0.0f32; lt * uv * nb];
    for s in 0..rows {
        read.fill_to(s + r, rows, |s| Measured::read(reader, s))?;
        let e = estimate(&read, s, reader, r, cfg.sigma);
        let mine = &read.get(s).row;
        out.par_chunks_mut(nb).enumerate().for_each(|(p, o)| {
            let (t, k) = (p / uv, p % uv);
            let e = &e[t * nb..(t + 1) * nb];
            let samples = mine.at(t, k);
            if samples.is_empty() {
                // No measurement here: the neighbourhood's spectrum as it is.
                o.copy_from_slice(e);
                return;
            }
            let (mine, theirs): (f32, f32) =
                samples.iter().fold((0.0, 0.0), |(a, b), &(band, x)| (a + x, b + e[usize::from(band)]));
            let ratio = if theirs > 1e-6 && mine > 0.0 {
                (mine / theirs).clamp(1.0 / cfg.max_ratio, cfg.max_ratio)
            } else {
                1.0
            };
            for (o, &x) in o.iter_mut().zip(e) {
                *o = x * ratio;
            }
            for &(band, x) in samples {
                o[usize::from(band)] = x;
            }
        });
        report.tally(mine);
        emit.row(s, &out, sink)?;
        // Row s + 1 reads the sums from row s + 1 - radius.
        read.keep_from((s + 1).saturating_sub(r));
    }
    report.ensure_measured(reader)?;
    Ok(report)
}
