//! White balance: a gain per band, so that the decode sees spectra with the illuminant's
//! tilt taken out.
//!
//! A scene under tungsten light (CIE A) is 30 times brighter in the red bands than in the
//! blue; under a fluorescent tube it has a few bright spikes. The sparsifying bases (the
//! DCT's flat first spectral atom, and members learned from many illuminants) model a grey
//! surface as a flat spectrum, so such a scene's every pixel needs many spectral
//! coefficients. Dividing each band by the scene's mean in that band (the grey-world
//! white balance every colour camera does before demosaicking) makes the average surface
//! grey again. For a one-hot mask this is a change of units per measurement, nothing
//! else: the sensing stays a selection, the orthonormal fast path holds, and the decoded
//! patch is multiplied back. Only the noise changes units too, so the noise ball weighs
//! each band by its gain ([`crate::solver::ball::Ball::weight`]).
//!
//! Measured with the DCT at pixel k = 3 on held-out scenes (noise-free captures, gains
//! from the truth; `docs/results-ensemble-validation.md`): +4.6 dB under A, +0.9 under D65,
//! +8.5 under FL11, +2.0 on a real light field; at k = 1 +0.7 to +1.5 dB.
//!
//! [`gains_from_sums`] turns per-band sums of measurements into gains; the tile decoder
//! collects the sums from a frame ([`crate::TileDecoder::estimate_gains`]) and applies the
//! gains ([`crate::TileDecoder::with_gains`]).

/// The largest ratio of the brightest band's mean to a gain: a band darker than
/// `1 / MAX_RATIO` of the brightest keeps that floor, so a nearly empty band's noise is not
/// blown up without bound.
pub const MAX_RATIO: f32 = 64.0;

use crate::sensor::extent::Array;

/// Gains from each band's sum of measurements and their count: each band's mean (at least
/// the brightest mean over [`MAX_RATIO`]), scaled so the gains average 1 (the decode's
/// values keep their overall size, so the solver's thresholds in normalised units keep
/// their meaning). A band with no measurement gets the measured bands' mean gain; no
/// positive mean at all (a black frame) gives gains of 1.
pub fn gains_from_sums<G: Array<f32>, K: Array<u32>>(sums: &G, counts: &K) -> G {
    let mut means = G::splat(0.0);
    let mut top = 0.0f32;
    for ((m, &s), &c) in means.iter_mut().zip(sums.iter()).zip(counts.iter()) {
        if c > 0 {
            *m = s / c as f32;
            if *m > top {
                top = *m;
            }
        }
    }
    if !(top > 0.0 && top.is_finite()) {
        return G::splat(1.0);
    }
    let floor = top / MAX_RATIO;
    let (mut total, mut measured) = (0.0f32, 0u32);
    for (m, &c) in means.iter_mut().zip(counts.iter()) {
        if c > 0 {
            *m = if *m > floor { *m } else { floor };
            total += *m;
            measured += 1;
        }
    }
    // `measured >= 1`: `top > 0` came from a measured band.
    let fill = total / measured.max(1) as f32;
    for (m, &c) in means.iter_mut().zip(counts.iter()) {
        if c == 0 {
            *m = fill;
        }
    }
    // The gains' mean is `fill` now (every band has a value): divide it out.
    let mean = means.iter().sum::<f32>() / means.len().max(1) as f32;
    for m in means.iter_mut() {
        *m /= mean;
    }
    means
}

/// Whether `gains` can balance a decode: each in `[1 / MAX_RATIO, MAX_RATIO]`. The
/// solver's thresholds are in normalised units, so gains far from 1 would move the whole
/// balanced signal out of their scale; [`gains_from_sums`]' gains average 1 and lie within
/// `[1 / MAX_RATIO, 13]`.
pub fn valid(gains: &[f32]) -> bool {
    gains.iter().all(|&g| valid_gain(g))
}

/// Whether one gain is in `[1 / MAX_RATIO, MAX_RATIO]` (see [`valid`]).
pub fn valid_gain(g: f32) -> bool {
    (1.0 / MAX_RATIO..=MAX_RATIO).contains(&g)
}
