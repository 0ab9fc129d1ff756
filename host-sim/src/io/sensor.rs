//! A simulated sensor's imperfections as a capture records them (`capture.json`'s
//! `simulated_sensor`, format version 2): the parameters `slf simulate` drew its sensor from,
//! so a capture says what made it. `slf decode` never reads them (a real camera's capture has
//! no such truth; its calibration file is what a decode may use); tests and the results
//! scripts compare a calibration with them. The model itself is [`crate::sim::sensor`].

use anyhow::{Result, ensure};
use serde::{Deserialize, Serialize};

use crate::io::message::number;

/// How the filters leak: each filter type's transmission over the bands, in the shape of a
/// thin-film (Fabry-Perot) filter (a main peak, secondary peaks of the neighbouring
/// interference orders, a floor), scaled so that `leakage` of its response to an
/// equal-energy spectrum comes from the other bands.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterDescription {
    /// Fraction of a filter's response to an equal-energy spectrum from bands other than
    /// its own, in [0, 0.9]; 0 is the ideal one-hot filter.
    pub leakage: f32,
    /// The main peak's full width at half maximum, nm, in [1, 200].
    pub width_nm: f32,
    /// The secondary peaks' height, relative to the main peak, in [0, 1].
    pub secondary: f32,
    /// How far the secondary peaks lie from the main one (both sides), nm, in [0, 1000].
    pub secondary_nm: f32,
    /// Transmission away from every peak, relative to the main peak, in [0, 1].
    pub floor: f32,
}

/// The sensor behind a simulated capture.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorDescription {
    pub filters: FilterDescription,
    /// Standard deviation of each pixel's dark level about the black level (fixed-pattern
    /// offset), DN, in [0, 1000].
    pub dark_sd_dn: f32,
    /// Fraction of hot pixels (a dark level far above black), in [0, 0.5].
    pub hot_fraction: f64,
    /// Standard deviation of each pixel's gain about 1 (photo-response non-uniformity), in
    /// [0, 0.5].
    pub prnu: f32,
    /// Fraction of the light lost by the corner view under the centre lenslet, in [0, 0.95].
    pub vignetting: f32,
    /// Seed of the sensor's own pattern (dark levels, gains, hot pixels): one sensor for
    /// every capture made with it, whatever the noise seed.
    pub seed: u64,
}

impl FilterDescription {
    /// Filters that see their own band only.
    pub const IDEAL: Self = Self { leakage: 0.0, width_nm: 15.0, secondary: 0.15, secondary_nm: 125.0, floor: 0.02 };
}

impl SensorDescription {
    /// The sensor the decoder assumes: one-hot filters, one dark level and gain, no
    /// vignetting.
    pub const IDEAL: Self = Self {
        filters: FilterDescription::IDEAL,
        dark_sd_dn: 0.0,
        hot_fraction: 0.0,
        prnu: 0.0,
        vignetting: 0.0,
        seed: 1,
    };

    /// Whether it is the ideal sensor's (leaky filters, dark or gain patterns, hot pixels or
    /// vignetting make it real; the leakage shape does not count without leakage).
    pub fn is_ideal(&self) -> bool {
        self.filters.leakage == 0.0
            && self.dark_sd_dn == 0.0
            && self.hot_fraction == 0.0
            && self.prnu == 0.0
            && self.vignetting == 0.0
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// The first field out of its range, named with it.
    pub fn check(&self) -> Result<()> {
        let f = &self.filters;
        let within = |v: f32, lo: f32, hi: f32| v.is_finite() && (lo..=hi).contains(&v);
        for (name, v, lo, hi) in [
            ("filters.leakage", f.leakage, 0.0, 0.9),
            ("filters.width_nm", f.width_nm, 1.0, 200.0),
            ("filters.secondary", f.secondary, 0.0, 1.0),
            ("filters.secondary_nm", f.secondary_nm, 0.0, 1000.0),
            ("filters.floor", f.floor, 0.0, 1.0),
            ("dark_sd_dn", self.dark_sd_dn, 0.0, 1000.0),
            ("prnu", self.prnu, 0.0, 0.5),
            ("vignetting", self.vignetting, 0.0, 0.95),
        ] {
            ensure!(within(v, lo, hi), "simulated_sensor.{name} is {}: must be in [{lo}, {hi}]", number(v));
        }
        ensure!(
            self.hot_fraction.is_finite() && (0.0..=0.5).contains(&self.hot_fraction),
            "simulated_sensor.hot_fraction is {}: must be in [0, 0.5]",
            self.hot_fraction
        );
        // With leakage, some band other than the filter's own must transmit for certain
        // (a main peak's tails may round to nothing), or the leaked share has nowhere to
        // come from.
        ensure!(
            f.leakage == 0.0 || f.floor > 0.0 || f.secondary > 0.0,
            "simulated_sensor.filters: leakage {} needs a floor or a secondary peak above 0 to leak through",
            number(f.leakage)
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_out_of_range_is_named() {
        let ok = SensorDescription::IDEAL;
        ok.check().unwrap();
        type Spoil = fn(&mut SensorDescription);
        let cases: [(&str, Spoil); 10] = [
            ("filters.leakage", |s| s.filters.leakage = 0.95),
            ("filters.width_nm", |s| s.filters.width_nm = 0.0),
            ("filters.secondary", |s| s.filters.secondary = f32::NAN),
            ("filters.secondary_nm", |s| s.filters.secondary_nm = -1.0),
            ("filters.floor", |s| s.filters.floor = 2.0),
            ("dark_sd_dn", |s| s.dark_sd_dn = f32::INFINITY),
            ("prnu", |s| s.prnu = 0.6),
            ("vignetting", |s| s.vignetting = 1.0),
            ("hot_fraction", |s| s.hot_fraction = -0.1),
            ("to leak through", |s| (s.filters.leakage, s.filters.floor, s.filters.secondary) = (0.1, 0.0, 0.0)),
        ];
        for (name, spoil) in cases {
            let mut s = ok;
            spoil(&mut s);
            let e = s.check().unwrap_err().to_string();
            assert!(e.contains(name) && !e.contains('\n'), "{name}: {e}");
        }
    }

    #[test]
    fn ideal_means_nothing_the_decoder_does_not_assume() {
        assert!(SensorDescription::IDEAL.is_ideal());
        let mut s = SensorDescription::IDEAL;
        s.filters.width_nm = 40.0;
        assert!(s.is_ideal(), "the leakage's shape alone leaks nothing");
        s.vignetting = 0.1;
        assert!(!s.is_ideal());
    }
}
