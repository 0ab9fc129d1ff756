//! Band resampling: a spectrum sampled at any wavelengths, integrated over each of the
//! camera's band filters.
//!
//! Each camera band `b` sees `∫ f_b(λ) s(λ) dλ / ∫ f_b(λ) dλ`, where `f_b` is the band's
//! filter and `s` the input spectrum, linearly interpolated between its samples and held
//! constant beyond the first and last. The filter is a Gaussian ([`BandFilter`]); its
//! FWHM defaults to the band spacing, 25 nm ([`CAMERA_FILTER`]), so neighbouring filters
//! cross at half height and every wavelength in 400..=700 nm reaches some band. Sampling at
//! the centre wavelength (nearest neighbour, or interpolation) would instead alias a
//! finely sampled spectrum's detail between the band centres.
//!
//! The integral is a sum over a 0.1 nm grid across `centre ± 2 FWHM` (the Gaussian's mass
//! outside is below 1e-5), folded once into a weight matrix: [`Resampler::apply`] is then a
//! small matrix-vector product per pixel. Each row of weights sums to 1, so a flat spectrum
//! stays flat to rounding.

use anyhow::{Result, bail, ensure};

/// A camera band's spectral filter: a Gaussian of the given full width at half maximum,
/// centred on the band's centre wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandFilter {
    /// Full width at half maximum, nm.
    pub fwhm_nm: f32,
}

/// The camera's filters: FWHM 25 nm, the spacing of its 13 band centres.
pub const CAMERA_FILTER: BandFilter = BandFilter { fwhm_nm: 25.0 };

/// Step of the integration grid, nm.
const GRID_NM: f64 = 0.1;

impl BandFilter {
    /// Standard deviation of the Gaussian, nm.
    pub fn sigma_nm(self) -> f64 {
        f64::from(self.fwhm_nm) / (2.0 * (2.0 * core::f64::consts::LN_2).sqrt())
    }

    /// The filter's (unnormalised) response at `offset_nm` from its centre.
    pub fn response(self, offset_nm: f64) -> f64 {
        let s = self.sigma_nm();
        (-0.5 * (offset_nm / s).powi(2)).exp()
    }
}

/// Weights from input samples to camera bands, built once for a set of input wavelengths.
#[derive(Clone, Debug, PartialEq)]
pub struct Resampler {
    inputs: usize,
    outputs: usize,
    /// Row-major `outputs x inputs`.
    weights: Vec<f32>,
}

impl Resampler {
    /// Weights from spectra sampled at `input_nm` (strictly increasing, finite, at least 2)
    /// to bands centred at `centres_nm`, each seen through `filter`.
    ///
    /// Refused when a band centre lies more than half a FWHM outside the input's range:
    /// that band would be mostly extrapolation.
    pub fn new(input_nm: &[f32], centres_nm: &[f32], filter: BandFilter) -> Result<Self> {
        ensure!(
            filter.fwhm_nm.is_finite() && filter.fwhm_nm > 0.0 && filter.fwhm_nm <= 1000.0,
            "band filter FWHM {} nm is not in (0, 1000]",
            filter.fwhm_nm
        );
        ensure!(input_nm.len() >= 2, "{} input wavelength(s): need at least 2 to resample", input_nm.len());
        for (i, w) in input_nm.iter().enumerate() {
            ensure!(w.is_finite() && *w > 0.0, "input wavelength {i} is {w}: need finite nm above 0");
        }
        if let Some(i) = input_nm.windows(2).position(|w| w[1] <= w[0]) {
            bail!(
                "input wavelengths must increase: {} nm (index {}) is followed by {} nm",
                input_nm[i],
                i,
                input_nm[i + 1]
            );
        }
        let (first, last) = (f64::from(input_nm[0]), f64::from(input_nm[input_nm.len() - 1]));
        let half = f64::from(filter.fwhm_nm) / 2.0;
        for &c in centres_nm {
            let c = f64::from(c);
            ensure!(
                c >= first - half && c <= last + half,
                "band at {c} nm is outside the input's {first}..={last} nm by more than half the filter's \
                 {} nm FWHM",
                filter.fwhm_nm
            );
        }
        let inputs = input_nm.len();
        let outputs = centres_nm.len();
        let mut weights = vec![0.0f32; outputs * inputs];
        let reach = 2.0 * f64::from(filter.fwhm_nm);
        let steps = (2.0 * reach / GRID_NM).round() as usize;
        let nm: Vec<f64> = input_nm.iter().map(|&w| f64::from(w)).collect();
        for (b, &c) in centres_nm.iter().enumerate() {
            let c = f64::from(c);
            let mut row = vec![0.0f64; inputs];
            let mut j = 0usize; // last input sample at or below the grid point
            for k in 0..=steps {
                let lambda = c - reach + k as f64 * GRID_NM;
                // Trapezoid rule: half weight at both ends.
                let edge = if k == 0 || k == steps { 0.5 } else { 1.0 };
                let g = edge * filter.response(lambda - c);
                if lambda <= nm[0] {
                    row[0] += g;
                } else if lambda >= nm[inputs - 1] {
                    row[inputs - 1] += g;
                } else {
                    while nm[j + 1] < lambda {
                        j += 1;
                    }
                    let t = (lambda - nm[j]) / (nm[j + 1] - nm[j]);
                    row[j] += g * (1.0 - t);
                    row[j + 1] += g * t;
                }
            }
            let total: f64 = row.iter().sum();
            for (w, r) in weights[b * inputs..(b + 1) * inputs].iter_mut().zip(&row) {
                *w = (r / total) as f32;
            }
        }
        Ok(Self { inputs, outputs, weights })
    }

    /// Input samples per spectrum.
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// Bands out.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// The weight of input sample `j` in band `b`.
    pub fn weight(&self, b: usize, j: usize) -> f32 {
        self.weights[b * self.inputs + j]
    }

    /// One spectrum: `input` has [`Self::inputs`] values, `output` [`Self::outputs`].
    pub fn apply(&self, input: &[f32], output: &mut [f32]) {
        debug_assert_eq!(input.len(), self.inputs);
        for (o, row) in output.iter_mut().zip(self.weights.chunks_exact(self.inputs)) {
            *o = row.iter().zip(input).map(|(w, x)| w * x).sum();
        }
    }

    /// Every spectrum of an interleaved array (`inputs` values a pixel), into a new array
    /// of `outputs` values a pixel.
    pub fn apply_all(&self, input: &[f32]) -> Vec<f32> {
        let pixels = input.len() / self.inputs;
        let mut out = vec![0.0f32; pixels * self.outputs];
        for (i, o) in input.chunks_exact(self.inputs).zip(out.chunks_exact_mut(self.outputs)) {
            self.apply(i, o);
        }
        out
    }
}

/// The most wavelengths a list or range may give.
pub const MAX_SAMPLES: usize = 100_000;

/// Wavelengths from a flag: `START:STOP:STEP` (inclusive, e.g. `400:700:10`) or a comma
/// list (`450,550,650`), at most [`MAX_SAMPLES`] of them.
pub fn parse_wavelengths(s: &str) -> Result<Vec<f32>> {
    let s = s.trim();
    if let Some((start, rest)) = s.split_once(':') {
        let Some((stop, step)) = rest.split_once(':') else {
            bail!("wavelengths {s:?}: a range is START:STOP:STEP, e.g. 400:700:10");
        };
        let num = |t: &str| -> Result<f64> {
            t.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| anyhow::anyhow!("wavelengths {s:?}: {t:?} is not a number"))
        };
        let (a, b, d) = (num(start)?, num(stop)?, num(step)?);
        ensure!(d > 0.0 && b >= a, "wavelengths {s:?}: need STEP > 0 and STOP >= START");
        // The count in f64 first: a tiny STEP would overflow a usize.
        let n = ((b - a) / d + 1e-6).floor() + 1.0;
        ensure!(n <= MAX_SAMPLES as f64, "wavelengths {s:?}: {n:.3e} samples is more than {MAX_SAMPLES}");
        let n = n as usize;
        let out: Vec<f32> = (0..n).map(|i| (a + i as f64 * d) as f32).collect();
        // A step below f32's resolution at these wavelengths would repeat samples.
        ensure!(
            out.windows(2).all(|w| w[1] > w[0]),
            "wavelengths {s:?}: STEP {d} is below the resolution of the wavelengths (f32)"
        );
        return Ok(out);
    }
    ensure!(s.split(',').count() <= MAX_SAMPLES, "wavelengths: more than {MAX_SAMPLES} in the list");
    s.split(',')
        .map(|t| {
            t.trim().parse::<f32>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                anyhow::anyhow!("wavelengths {s:?}: {t:?} is not a number (give START:STOP:STEP or a comma list)")
            })
        })
        .collect()
}
