//! The band-gain fill: a cheap start for SL0's cold solve that already holds the patch's
//! brightness and colour.
//!
//! SL0's first levels, from the minimum-norm start (measurements, zeros elsewhere) at
//! `sigma0 = max |S0|`, find the patch's large coefficients: above all its DC, which the
//! zero-filled start holds at a thirteenth of its value at one measurement per pixel. A
//! start that holds them lets the solve begin lower. The fill is the simplest such start
//! that sees both the spectrum and the shading: each band's mean over the patch's
//! measurements, times each pixel's gain, the ratio of its own measurements to those of
//! its bands' means. A patch of one spectrum at one brightness is filled exactly; under
//! varying light each pixel follows its own measurements; the solve corrects the rest.
//!
//! Measured (`docs/bench/README.md`, "The schedule and the start"): a cold solve from the
//! fill at 0.03 of its largest coefficient (about 3 levels below the minimum-norm start)
//! decodes as well as the minimum-norm start, within -0.04 to +0.17 dB, and is the
//! preview preset's start; at 0.01 (6 levels lower) it loses 5 dB and more on scenes of
//! edges, occlusions or narrow spectra (the `depth` and `led` scenes), where SL0 at small
//! sigma only refines what the fill got wrong.

use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands};
use crate::solver::workspace::Measurements;

/// What a pixel's gain adds to its own measurements and to its bands' means, per measured
/// band (normalised units, white = 1: 20 times a 12-bit sensor's 2 DN read noise), so a
/// dark pixel's gain is about 1 and a bright one's its ratio.
pub const FLOOR: f32 = 0.01;

/// Writes the band-gain fill of `m` into `signal` (`B` bands per pixel, the last axis):
/// measured values as they are, every other value its pixel's gain times its band's mean.
/// A band no pixel measures takes the mean of all measurements; a pixel with no
/// measurement (or whose bands' means are not positive) has gain 1.
pub fn fill_bands<S: Shape>(m: &Measurements<S::Values>, signal: &mut PerValue<S, f32>) {
    let (mut sum, mut count) = (<PerBand<S, f32>>::splat(0.0), <PerBand<S, u32>>::splat(0));
    let pixels = || S::Bands::chunks(m.values.as_ref()).iter().zip(S::Bands::chunks(m.measured.as_ref()));
    for (values, measured) in pixels() {
        for b in 0..S::B {
            if measured[b] {
                sum[b] += values[b];
                count[b] += 1;
            }
        }
    }
    let all = sum.iter().sum::<f32>() / count.iter().sum::<u32>().max(1) as f32;
    let mut mean = <PerBand<S, f32>>::splat(0.0);
    for (b, m) in mean.iter_mut().enumerate() {
        *m = if count[b] > 0 { sum[b] / count[b] as f32 } else { all };
    }
    for (x, (values, measured)) in S::Bands::chunks_mut(signal.as_mut()).iter_mut().zip(pixels()) {
        let (mut own, mut expected) = (0.0f32, 0.0f32);
        for b in 0..S::B {
            if measured[b] {
                own += values[b];
                expected += mean[b];
            }
        }
        // The ratio pulled towards 1 by `FLOOR` a measured band: where the pixel's bands'
        // means are near nothing (a dark patch: noise about the black level, some of it
        // below), `own / expected` alone is noise over noise, and one such pixel filled at
        // 200 times the patch's brighter bands started the dark canopy's solves at the
        // output's clamp (issue 49).
        let floor = FLOOR * measured.iter().filter(|&&k| k).count() as f32;
        let ratio = (own + floor) / (expected + floor);
        let gain = if expected + floor > f32::MIN_POSITIVE && ratio.is_finite() && ratio > 0.0 { ratio } else { 1.0 };
        for b in 0..S::B {
            x[b] = if measured[b] { values[b] } else { gain * mean[b] };
        }
    }
}
