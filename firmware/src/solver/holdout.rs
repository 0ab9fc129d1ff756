//! Held-out measurements: a patch's own estimate of its decode's error.
//!
//! Every decoded value that was not measured comes from the prior, and a solve meets the
//! measurements it was given whatever its error, so its residual says nothing. A
//! measurement the solve was *not* given does: hold out one measurement in
//! [`HoldOut::fold`], solve from the rest, and the prediction error on the held-out ones
//! estimates the error at the values nobody measured (cross-validation for compressed
//! sensing: Boufounos, Duarte and Baraniuk, "Sparse signal reconstruction from noisy
//! compressive measurements using cross validation", 2007; Ward, "Compressed sensing with
//! cross validation", IEEE Trans. Inf. Theory 2009). A held-out measurement carries its
//! own noise, whose variance (the capture's noise model) is taken off the squared error.
//!
//! The tile decoder ([`crate::decode::tile`]) runs the estimating solve before the decode
//! and reads the patch again after it, so the held-out values need no buffer and the
//! decode sees every measurement: its output is the same with or without the estimate.
//!
//! The estimate of the patch's error is in the output's units (sensor units, white = 1,
//! as an RMS per value over the whole patch): the unmeasured values at the held-out
//! prediction error, the measured ones at the noise's level.

use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands};
use crate::solver::workspace::Measurements;

/// Which measurements are held out (config).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HoldOut {
    /// One measurement (or (lenslet, band) group, [`Unit`]) in `fold` is held out, >= 2.
    pub fold: u16,
}

impl HoldOut {
    /// One in eight: at one snapshot, about 78 of a full-view patch's 625 measurements.
    pub const DEFAULT: Self = Self { fold: 8 };

    /// Whether `key` is held out: a hash of it, so the held-out keys spread over the
    /// patch's lenslets, views and bands (or a frame's samples, for a held-out decode of the
    /// whole frame).
    #[inline(always)]
    pub fn holds(&self, key: usize) -> bool {
        let mut z = (key as u32).wrapping_mul(0x9E37_79B9) ^ 0x5bd1_e995;
        z ^= z >> 15;
        z = z.wrapping_mul(0x2c1b_3c6d);
        z ^= z >> 12;
        z.checked_rem(u32::from(self.fold)) == Some(0)
    }

    /// Whether entry `index` of a patch of `PU x PV` views and `B` bands is held out when
    /// the patch's measurements are held out by `unit`.
    #[inline(always)]
    pub fn held<S: Shape>(&self, unit: Unit, index: usize) -> bool {
        match unit {
            Unit::Measurement => self.holds(index),
            // The lenslet and the band: every view of it.
            Unit::LensletBand => match (index.checked_div(S::PU * S::PV * S::B), index.checked_rem(S::B)) {
                (Some(lenslet), Some(band)) => self.holds(lenslet * S::B + band),
                _ => false,
            },
        }
    }
}

/// What is held out together.
///
/// The held-out measurements must be like the values nobody measured, or their error says
/// little of those values'. A pixel mask measures a band of a lenslet in some of its views
/// and not in others: a value nobody measured has its band measured in the lenslet's other
/// views, as a single held-out measurement does. A lenslet (or kronecker) mask measures a
/// lenslet's few bands in every view: a value nobody measured is of a band no view of its
/// lenslet saw, and a single held-out measurement is predicted by the other views of its band
/// (measured: the estimate read 10 dB high at lenslet k = 3), so whole (lenslet, band) groups
/// are held out there. Which of the two a patch is, its measurements say
/// ([`Unit::of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Unit {
    /// Single measurements.
    Measurement,
    /// Every view of a band of a lenslet.
    LensletBand,
}

impl Unit {
    /// [`Unit::LensletBand`] if most (lenslet, band) groups the patch measures at all are
    /// measured in at least three quarters of the patch's views, else [`Unit::Measurement`].
    pub fn of<S: Shape>(m: &Measurements<S::Values>) -> Self {
        let (mut groups, mut whole) = (0u32, 0u32);
        for lenslet in m.measured.chunks_exact(S::PU * S::PV * S::B) {
            let mut views = <PerBand<S, _>>::splat(0u32);
            for pixel in S::Bands::chunks(lenslet) {
                for (n, &k) in views.iter_mut().zip(pixel.iter()) {
                    *n += u32::from(k);
                }
            }
            for &n in views.iter() {
                groups += u32::from(n > 0);
                whole += u32::from(4 * n as usize >= 3 * S::PU * S::PV);
            }
        }
        if 2 * whole > groups { Self::LensletBand } else { Self::Measurement }
    }
}

impl Default for HoldOut {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Leaves the held-out entries of `m` out (not measured, value 0); returns how many.
/// Nothing is left out if that would leave no measurement.
pub fn hold_out<S: Shape>(hold: &HoldOut, m: &mut Measurements<S::Values>) -> u32 {
    let unit = Unit::of::<S>(m);
    let held = (0..S::N).filter(|&i| m.measured.get(i) == Some(&true) && hold.held::<S>(unit, i)).count() as u32;
    if held == 0 || held >= m.count {
        return 0;
    }
    for (i, (v, k)) in m.values.iter_mut().zip(m.measured.iter_mut()).enumerate() {
        if *k && hold.held::<S>(unit, i) {
            *k = false;
            *v = 0.0;
        }
    }
    m.count -= held;
    held
}

/// The noise variance of a measurement that reads `seen` in the light field's units, its
/// view's flat field `flat` divided out: the sensor's noise (`noise` sd and `shot` per unit,
/// normalised raw units, as [`crate::Sl0Config`]'s) on the raw value `seen * flat`, divided
/// by `flat` as the value was. A vignetted view's measurement is noisier than its raw
/// pixel's by `1 / flat`; taken as raw, its noise was under-subtracted and the estimate
/// read the noise as error.
#[inline]
pub fn noise_variance(noise: f32, shot: f32, seen: f32, flat: f32) -> f32 {
    let raw = seen * flat;
    (noise * noise + shot * if raw > 0.0 { raw } else { 0.0 }) / (flat * flat)
}

/// The error estimate of a patch (RMS per value, sensor units) from `predicted`, the
/// estimating solve's patch at the measurements' positions (a half-pixel patch moved to
/// its pixels, [`crate::solver::fractional::to_sensor`]), against the held-out entries of
/// `m` (all its measurements, read again). `noise` and `shot` are the capture's noise model
/// (normalised units, as [`crate::Sl0Config`]'s), `flat(i)` the flat field of entry `i`'s
/// view (1 without one, [`noise_variance`]); each band's values are divided by its
/// gain in `m` and multiplied back here. `None` if `m` holds no held-out measurement.
pub fn estimate<S: Shape>(
    hold: &HoldOut,
    m: &Measurements<S::Values>,
    predicted: &PerValue<S, f32>,
    (noise, shot): (f32, f32),
    flat: impl Fn(usize) -> f32,
) -> Option<f32> {
    let unit = Unit::of::<S>(m);
    let (mut r2, mut var, mut held) = (0.0f32, 0.0f32, 0u32);
    for (i, ((&y, &k), &x)) in m.values.iter().zip(m.measured.iter()).zip(predicted.iter()).enumerate() {
        if !(k && hold.held::<S>(unit, i)) {
            continue;
        }
        let g = m.gains.get(i % S::B).copied().unwrap_or(1.0);
        let (seen, d) = (y * g, (x - y) * g);
        r2 += d * d;
        var += noise_variance(noise, shot, seen, flat(i));
        held += 1;
    }
    if held == 0 || !r2.is_finite() {
        return None;
    }
    let (r2, var) = (r2 / held as f32, var / held as f32);
    // The unmeasured values' error, the noise taken off (not below nothing).
    let unmeasured = if r2 > var { r2 - var } else { 0.0 };
    let measured = m.count as f32 / S::N as f32;
    Some(libm::sqrtf(unmeasured * (1.0 - measured) + var * measured))
}
