//! Spectra at slf's 13 bands: measured data, synthetic families, and illumination.
//!
//! Measured tables (ColorChecker reflectances, CIE 1931 observer, D65, every measured
//! reflectance set colour-science ships, and illuminants A, FL2, FL11 and two LEDs) are in
//! [`crate::sim::spectra_data`], generated from colour-science by `scripts/gen_spectra.py`.

use rand::Rng;

pub use crate::sim::spectra_data::{BAND_NM, CMF_1931, COLORCHECKER, D65, ILLUMINANTS, MEASURED};

/// Number of bands.
pub const BANDS: usize = 13;

/// A reflectance or radiance spectrum at the band centres.
pub type Spectrum = [f32; BANDS];

/// An illuminant of [`ILLUMINANTS`] by name ("D65", "A", "FL2", "FL11", "LED-B3", "LED-V1").
pub fn illuminant(name: &str) -> Option<Spectrum> {
    ILLUMINANTS.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// A ColorChecker patch's reflectance by its chart name ("dark skin", "blue sky", ..).
pub fn colorchecker(name: &str) -> Option<Spectrum> {
    COLORCHECKER.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// A smooth random reflectance: a floor plus two or three broad Gaussian bumps, in
/// `[0.03, 0.95]`.
pub fn smooth_random(rng: &mut impl Rng) -> Spectrum {
    let floor = rng.random_range(0.03..0.3f32);
    let bumps: Vec<(f32, f32, f32)> = (0..rng.random_range(2..=3))
        .map(|_| (rng.random_range(380.0..720.0f32), rng.random_range(40.0..120.0f32), rng.random_range(0.1..0.7f32)))
        .collect();
    BAND_NM.map(|nm| {
        let v = floor + bumps.iter().map(|&(c, w, a)| a * (-0.5 * ((nm - c) / w).powi(2)).exp()).sum::<f32>();
        v.clamp(0.03, 0.95)
    })
}

/// A narrow-band reflectance: a Gaussian line of standard deviation `width_nm` at
/// `centre_nm` over a dark floor (a fluorescent dye, a coloured LED seen through a filter).
pub fn narrow_band(centre_nm: f32, width_nm: f32) -> Spectrum {
    BAND_NM.map(|nm| 0.03 + 0.9 * (-0.5 * ((nm - centre_nm) / width_nm).powi(2)).exp())
}

/// Radiance of a Lambertian reflectance under D65, scaled so a perfect white reflector is 1
/// in D65's brightest band.
pub fn under_d65(reflectance: &Spectrum) -> Spectrum {
    let peak = D65.iter().fold(0.0f32, |m, &x| m.max(x));
    core::array::from_fn(|b| reflectance[b] * D65[b] / peak)
}
