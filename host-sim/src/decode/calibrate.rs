//! A sensor's calibration from its calibration captures (issue 43, `slf calibrate`): dark
//! frames give each pixel's dark level, flat frames its flat (gain times vignetting), a band
//! sweep the filters' response matrix, and pixels whose dark level or flat no working pixel
//! has are listed as hot.
//!
//! Every capture is checked against the first (geometry, bands, levels, mask): a calibration
//! belongs to one camera. Exposures of a kind are averaged, and so are a capture's
//! snapshots (a pixel's dark level and flat do not depend on its filter: the flat's light
//! has equal energy in every band and a filter's response to it is its row's sum, 1 by the
//! response matrix's definition). The response matrix's entry `(f, b)` is the mean over the
//! working pixels behind filter `f` of what they record under band `b`'s light, dark level
//! removed and divided by their flat and the light's level.

use std::collections::BTreeMap;

use anyhow::{Result, bail, ensure};

use crate::io::calibration::{Calibration, CalibrationDescription, FORMAT, Sources, VERSION};
use crate::io::capture::{Capture, Light};

/// A pixel whose dark level lies more than this fraction of the range (white - black) above
/// black is hot; so is one whose flat is below [`DEAD_FLAT`] or at saturation.
pub const HOT_DARK: f32 = 0.05;
/// The flat below which a pixel is dead (listed with the hot ones).
pub const DEAD_FLAT: f32 = 0.1;

/// What a calibration was made of, one line each, for the user.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub lines: Vec<String>,
}

/// Calibrates the sensor behind `captures` (dark, flat and, unless `response` is given as
/// measured filter curves `[filter][band]`, one band capture per band at least).
///
/// # Errors
/// No capture, a scene among them, captures of different cameras (named), a kind missing,
/// a filter type no working pixel has.
pub fn calibrate(captures: &[(String, Capture)], response: Option<Vec<Vec<f32>>>) -> Result<(Calibration, Report)> {
    let Some((first_name, first)) = captures.first() else { bail!("no calibration capture given") };
    let d0 = &first.description;
    for (name, c) in captures {
        let d = &c.description;
        ensure!(!d.light.is_scene(), "{name}: a scene's capture (its light is not dark, flat or a band)");
        ensure!(
            d.lenslets == d0.lenslets
                && d.views == d0.views
                && d.bands_nm == d0.bands_nm
                && d.mask == d0.mask
                && d.black_level == d0.black_level
                && d.white_level == d0.white_level,
            "{name}: another camera than {first_name}'s (lenslets, views, bands, mask or levels differ)"
        );
    }
    let (rows, cols) = first.frame_size();
    let bands = d0.bands_nm.len();
    let (black, range) = (d0.black_level, d0.white_level - d0.black_level);
    let of = |want: fn(&Light) -> bool| captures.iter().filter(move |(_, c)| want(&c.description.light));
    let darks: Vec<_> = of(|l| *l == Light::Dark).collect();
    let flats: Vec<_> = of(|l| matches!(l, Light::Flat { .. })).collect();
    ensure!(!darks.is_empty(), "no dark capture (light \"dark\") among the {} given", captures.len());
    ensure!(!flats.is_empty(), "no flat capture (light {{\"flat\": ...}}) among the {} given", captures.len());

    // Dark levels: the mean of every dark frame.
    let mut dark = vec![0.0f64; rows * cols];
    let mut n = 0usize;
    for (_, c) in &darks {
        for f in &c.frames {
            for (d, &x) in dark.iter_mut().zip(f) {
                *d += f64::from(x);
            }
            n += 1;
        }
    }
    let dark: Vec<f32> = dark.iter().map(|&d| (d / n as f64) as f32).collect();

    // Flats: light above the dark level over the light's, in units of white.
    let saturation = d0.saturation_level;
    let mut flat = vec![0.0f64; rows * cols];
    let mut saturated = vec![false; rows * cols];
    let mut n = 0usize;
    for (_, c) in &flats {
        let Light::Flat { level } = c.description.light else { continue };
        for f in &c.frames {
            for (p, &x) in f.iter().enumerate() {
                saturated[p] |= f32::from(x) >= saturation;
                flat[p] += f64::from((f32::from(x) - dark[p]) / (range * level));
            }
            n += 1;
        }
    }
    let flat: Vec<f32> = flat.iter().map(|&v| (v / n as f64).max(0.0) as f32).collect();

    // Hot and dead pixels, and the ones the captures list as defective.
    let mut bad: Vec<bool> = (0..rows * cols)
        .map(|p| dark[p] - black > HOT_DARK * range || flat[p] < DEAD_FLAT || saturated[p])
        .collect();
    for (_, c) in captures {
        for &[r, col] in &c.description.defective_pixels {
            bad[r as usize * cols + col as usize] = true;
        }
    }
    let hot_pixels: Vec<[u32; 2]> =
        (0..rows * cols).filter(|&p| bad[p]).map(|p| [(p / cols) as u32, (p % cols) as u32]).collect();

    // Vignetting per view: the mean flat of the working pixels at each view.
    let [u_n, v_n] = d0.views;
    let mut sums = vec![(0.0f64, 0usize); u_n * v_n];
    for p in (0..rows * cols).filter(|&p| !bad[p]) {
        let (u, v) = ((p / cols) % u_n, (p % cols) % v_n);
        let s = &mut sums[u * v_n + v];
        *s = (s.0 + f64::from(flat[p]), s.1 + 1);
    }
    ensure!(sums.iter().all(|s| s.1 > 0), "a view with no working pixel: the flats are dark or saturated");
    let means: Vec<f64> = sums.iter().map(|s| s.0 / s.1 as f64).collect();
    let top = means.iter().fold(0.0f64, |m, &x| m.max(x));
    ensure!(top > 0.0, "the flats record no light");
    let vignetting: Vec<Vec<f32>> =
        (0..u_n).map(|u| (0..v_n).map(|v| (means[u * v_n + v] / top) as f32).collect()).collect();

    // The response matrix: measured curves as given, or the band sweep.
    let band_count = of(|l| matches!(l, Light::Band { .. })).count();
    let response = match response {
        Some(r) => r,
        None => {
            let mut seen = BTreeMap::new();
            let mut sum = vec![0.0f64; bands * bands];
            let mut count = vec![0usize; bands * bands];
            for (_, c) in of(|l| matches!(l, Light::Band { .. })) {
                let Light::Band { band, level } = c.description.light else { continue };
                let b = usize::from(band);
                *seen.entry(b).or_insert(0usize) += 1;
                let mask = c.mask()?;
                for (j, f) in c.frames.iter().enumerate() {
                    for (p, &x) in f.iter().enumerate() {
                        if bad[p] {
                            continue;
                        }
                        let filter = usize::from(mask.bands_at(p / cols, p % cols)[j]);
                        sum[filter * bands + b] += f64::from((f32::from(x) - dark[p]) / (flat[p] * range * level));
                        count[filter * bands + b] += 1;
                    }
                }
            }
            if let Some(b) = (0..bands).find(|b| !seen.contains_key(b)) {
                bail!(
                    "no capture under band {b}'s light ({} nm): a sweep needs one per band, or --response \
                     FILE with measured filter curves",
                    d0.bands_nm[b]
                );
            }
            if let Some(f) = (0..bands).find(|&f| count[f * bands] == 0) {
                bail!("filter type {f} ({} nm) has no working pixel in the sweep", d0.bands_nm[f]);
            }
            (0..bands)
                .map(|f| (0..bands).map(|b| (sum[f * bands + b] / count[f * bands + b] as f64) as f32).collect())
                .collect()
        }
    };

    let description = CalibrationDescription {
        format: FORMAT.into(),
        version: VERSION,
        lenslets: d0.lenslets,
        views: d0.views,
        bands_nm: d0.bands_nm.clone(),
        black_level: d0.black_level,
        white_level: d0.white_level,
        response,
        vignetting,
        hot_pixels,
        sources: Sources { dark: darks.len(), flat: flats.len(), band: band_count },
    };
    let report = Report {
        lines: vec![
            format!(
                "calibration: {} dark, {} flat and {} band captures of {} x {} lenslets, {} x {} views",
                darks.len(),
                flats.len(),
                band_count,
                d0.lenslets[0],
                d0.lenslets[1],
                u_n,
                v_n
            ),
            format!(
                "{} hot, dead or defective pixels of {}; vignetting: the darkest view gets {:.3} of the brightest's",
                description.hot_pixels.len(),
                rows * cols,
                description.vignetting.iter().flatten().fold(1.0f32, |m, &x| m.min(x))
            ),
        ],
    };
    Ok((Calibration::new(description, dark, flat)?, report))
}
