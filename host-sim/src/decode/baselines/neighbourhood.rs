//! Each lenslet's spectrum estimated from its neighbourhood: per band, the Gaussian-weighted
//! mean of the measurements of every view of the lenslets within a radius. The demosaic's
//! and PPID's first step.

use rayon::prelude::*;

use super::lagged::{Lagged, around};
use super::measurements::{LensletRow, Reader};

/// A lenslet row's measurements and their sums per lenslet and band.
pub(super) struct Measured {
    pub row: LensletRow,
    pub sums: Sums,
}

impl Measured {
    /// Lenslet row `s` of `reader`'s capture.
    ///
    /// # Errors
    /// A frame's row that cannot be read.
    pub(super) fn read(reader: &Reader<'_>, s: usize) -> anyhow::Result<Self> {
        let row = reader.row(s)?;
        let sums = Sums::of(&row, reader.lenslets.1, reader.bands);
        Ok(Self { row, sums })
    }
}

/// Per lenslet of a row and band: the sum and the count of its views' measurements.
pub(super) struct Sums {
    sum: Vec<f32>,
    count: Vec<f32>,
}

impl Sums {
    /// The sums of a lenslet row of `bands` bands.
    pub(super) fn of(row: &LensletRow, lenslets: usize, bands: usize) -> Self {
        let (mut sum, mut count) = (vec![0.0f32; lenslets * bands], vec![0.0f32; lenslets * bands]);
        for t in 0..lenslets {
            for own in row.lenslet(t) {
                for &(b, x) in own {
                    let i = t * bands + usize::from(b);
                    sum[i] += x;
                    count[i] += 1.0;
                }
            }
        }
        Self { sum, count }
    }
}

/// The Gaussian weight of lenslets `(ds, dt)` apart, `sigma` in lenslets.
#[inline]
pub(super) fn gauss(ds: isize, dt: isize, sigma: f32) -> f32 {
    (-((ds * ds + dt * dt) as f32) / (2.0 * sigma * sigma)).exp()
}

/// Lenslet row `s`'s estimates, `T x B`: per lenslet, each band's Gaussian-weighted mean
/// over the measurements of the lenslets within `radius` (rows `s - radius ..= s + radius`
/// of `read` held); a band no neighbour measured takes the interpolation of the lenslet's
/// other band estimates.
pub(super) fn estimate(read: &Lagged<Measured>, s: usize, reader: &Reader<'_>, radius: usize, sigma: f32) -> Vec<f32> {
    let ((rows, lenslets), nb) = (reader.lenslets, reader.bands);
    let mut out = vec![0.0f32; lenslets * nb];
    out.par_chunks_mut(nb).enumerate().for_each(|(t, out)| {
        let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
        for ss in around(s, radius, rows) {
            let row = &read.get(ss).sums;
            for tt in around(t, radius, lenslets) {
                let w = gauss(ss as isize - s as isize, tt as isize - t as isize, sigma);
                let i = tt * nb;
                for b in 0..nb {
                    num[b] += w * row.sum[i + b];
                    den[b] += w * row.count[i + b];
                }
            }
        }
        let mut points: Vec<(u8, f32)> =
            (0..nb).filter(|&b| den[b] > 0.0).map(|b| (b as u8, num[b] / den[b])).collect();
        // Within the known bands, interpolation equals the estimates themselves.
        let _ = super::interpolate::through(&mut points, out);
        for b in 0..nb {
            if den[b] > 0.0 {
                out[b] = num[b] / den[b];
            }
        }
    });
    out
}
