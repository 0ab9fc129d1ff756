//! RGB to spectra: the spectral upsampling of Mallett and Yuksel (2019).
//!
//! A linear sRGB colour `(r, g, b)` is the reflectance `r R(λ) + g G(λ) + b B(λ)`, where
//! `R, G, B` are the three spectra of I. Mallett and C. Yuksel, "Spectral Primary
//! Decomposition for Rendering with sRGB Reflectance" (EGSR 2019), fitted so that the mix
//! renders back to `(r, g, b)` under the sRGB white point D65, stays within 0..=1, and sums
//! to 1 for white. The tables are in [`super::rgb_basis_data`], generated from
//! colour-science by `host-sim/scripts/gen_rgb_basis.py`.
//!
//! slf's light fields hold radiance: the reflectance times an illuminant (D65 here, the
//! default of the rest of slf), integrated over each camera band's filter
//! ([`super::bands`]) and scaled so a white reflector is 1 in the brightest band, as
//! [`crate::sim::spectra::under_d65`] does for the synthetic scenes. Because the lift is linear,
//! it is a 13 x 3 matrix, built once.
//!
//! Lifted spectra are smooth and lie in a 3-dimensional family: every pixel's spectrum is a
//! mix of the same three curves. Real spectra are not, so a decoder (or a dictionary) does
//! better on lifted content than it will on a real scene: claims on lifted light fields
//! are optimistic in the spectral dimension.

use anyhow::Result;

use super::bands::{BandFilter, Resampler};
use super::rgb_basis_data::{D65_5NM, FIRST_NM, MALLETT_2019, STEP_NM};

/// The sRGB transfer function undone: an encoded value in `[0, 1]` to linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Linear sRGB to camera bands: radiance under D65, white = 1 in the brightest band.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbLift {
    /// Row-major `bands x 3`.
    matrix: Vec<f32>,
    bands: usize,
}

impl RgbLift {
    /// The lift to bands centred at `centres_nm`, each seen through `filter`.
    pub fn new(centres_nm: &[f32], filter: BandFilter) -> Result<Self> {
        let nm: Vec<f32> = (0..D65_5NM.len()).map(|i| FIRST_NM + STEP_NM * i as f32).collect();
        let resampler = Resampler::new(&nm, centres_nm, filter)?;
        let bands = centres_nm.len();
        // Radiance of each primary's reflectance under D65, and of white.
        let radiance = |c: usize| -> Vec<f32> {
            let s: Vec<f32> = MALLETT_2019.iter().zip(&D65_5NM).map(|(p, e)| p[c] * e).collect();
            let mut out = vec![0.0; bands];
            resampler.apply(&s, &mut out);
            out
        };
        let mut white = vec![0.0; bands];
        resampler.apply(&D65_5NM, &mut white);
        let peak = white.iter().fold(0.0f32, |m, &x| m.max(x));
        let primaries = [radiance(0), radiance(1), radiance(2)];
        let matrix = (0..bands).flat_map(|b| primaries.iter().map(move |p| p[b] / peak).collect::<Vec<_>>()).collect();
        Ok(Self { matrix, bands })
    }

    /// Bands out.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The radiance in band `b` of primary `c` (0 red, 1 green, 2 blue) at full strength.
    pub fn primary(&self, b: usize, c: usize) -> f32 {
        self.matrix[b * 3 + c]
    }

    /// One linear sRGB colour to `out` (one value a band).
    pub fn lift(&self, rgb: [f32; 3], out: &mut [f32]) {
        for (o, row) in out.iter_mut().zip(self.matrix.chunks_exact(3)) {
            *o = row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2];
        }
    }
}
