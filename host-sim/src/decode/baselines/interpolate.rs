//! Per-pixel spectral interpolation: each pixel's spectrum linear in band index between the
//! bands it measured, constant beyond; a pixel without a measurement takes the mean
//! spectrum of the measured pixels of its lenslet and the lenslets around it.

use anyhow::Result;
use rayon::prelude::*;

use super::lagged::{Lagged, around};
use super::measurements::{LensletRow, Reader};
use super::{BaselineReport, Emit};
use crate::io::rows::Rows;

/// The spectrum through `(band, value)` points (distinct bands, any order): linear in band
/// index between them, constant beyond. `None` without a point.
pub(super) fn through(points: &mut [(u8, f32)], out: &mut [f32]) -> Option<()> {
    points.sort_by_key(|p| p.0);
    let (&first, &last) = (points.first()?, points.last()?);
    for (b, o) in out.iter_mut().enumerate() {
        let b8 = b as u8;
        *o = if b8 <= first.0 {
            first.1
        } else if b8 >= last.0 {
            last.1
        } else {
            let i = points.partition_point(|p| p.0 <= b8);
            let (lo, hi) = (points[i - 1], points[i]);
            let t = f32::from(b8 - lo.0) / f32::from(hi.0 - lo.0);
            lo.1 + t * (hi.1 - lo.1)
        };
    }
    Some(())
}

/// A lenslet row's interpolated spectra (`T x UV x B`, lenslet-major) and which positions
/// had no measurement to interpolate.
struct Interpolated {
    values: Vec<f32>,
    missing: Vec<bool>,
}

fn interpolated(row: &LensletRow, lenslets: usize, views: usize, bands: usize) -> Interpolated {
    let mut values = vec![0.0f32; lenslets * views * bands];
    let missing = values
        .par_chunks_mut(bands)
        .enumerate()
        .map(|(p, out)| {
            let mut points = row.at(p / views, p % views).to_vec();
            through(&mut points, out).is_none()
        })
        .collect();
    Interpolated { values, missing }
}

/// Interpolates every lenslet row of `reader`'s capture into `sink`, in order.
pub(super) fn stream(reader: &Reader<'_>, sink: &mut Rows<'_>) -> Result<BaselineReport> {
    let (rows, lt) = reader.lenslets;
    let (uv, nb) = (reader.views.0 * reader.views.1, reader.bands);
    let mut emit = Emit::new(reader);
    let mut report = BaselineReport::default();
    let mut done: Lagged<Interpolated> = Lagged::new();
    let mut out = vec![0.0f32; lt * uv * nb];
    for s in 0..rows {
        done.fill_to(s + 1, rows, |s| Ok(interpolated(&reader.row(s)?, lt, uv, nb)))?;
        let here = done.get(s);
        out.copy_from_slice(&here.values);
        report.filled += here.missing.iter().filter(|&&m| m).count();
        report.measured += here.missing.iter().filter(|&&m| !m).count();
        // A position without a measurement: the mean spectrum of the measured ones in the
        // 3 x 3 lenslets around (all views), or zeros when none is.
        out.par_chunks_mut(nb).enumerate().filter(|(p, _)| here.missing[*p]).for_each(|(p, o)| {
            let t = p / uv;
            let mut sum = vec![0.0f32; nb];
            let mut n = 0u32;
            for ss in around(s, 1, rows) {
                let near = done.get(ss);
                for tt in around(t, 1, lt) {
                    for k in 0..uv {
                        let q = tt * uv + k;
                        if !near.missing[q] {
                            n += 1;
                            for (a, &x) in sum.iter_mut().zip(&near.values[q * nb..(q + 1) * nb]) {
                                *a += x;
                            }
                        }
                    }
                }
            }
            for (o, a) in o.iter_mut().zip(&sum) {
                *o = if n > 0 { a / n as f32 } else { 0.0 };
            }
        });
        emit.row(s, &out, sink)?;
        // Row s + 1 reads rows s..=s + 2.
        done.keep_from(s);
    }
    report.ensure_measured(reader)?;
    Ok(report)
}
