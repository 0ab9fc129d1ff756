//! The sensor as it is, not as the decoder assumes it (issue 43): filters that leak, a dark
//! level and a gain per pixel, hot pixels, and views that get less light the farther they
//! lie from their lenslet's centre.
//!
//! - **Filters.** A thin-film (Fabry-Perot) filter on a pixel passes a main peak, the
//!   neighbouring interference orders as secondary peaks, and a floor of leakage. Snapshot
//!   mosaic sensors built that way show 10-20 nm wide main peaks in the visible, secondary
//!   peaks, and a floor of a few per cent, and their makers ship a correction matrix per
//!   sensor for them (Geelen, Tack and Lambrechts, "A compact snapshot multispectral imager
//!   with a monolithically integrated per-pixel filter mosaic", Proc. SPIE 8974, 2014;
//!   Goossens et al., "Pixel-integrated thin-film filter simulation and scaling trade-offs",
//!   arXiv 2106.01147, 2021, on how the peaks widen and sink on small pixels; Lapray et al.,
//!   "Multispectral filter arrays: recent advances and practical implementation", Sensors
//!   14, 2014, for the survey). The defaults take that shape: a 15 nm main peak, secondary
//!   peaks at 0.15 of it 125 nm to either side, a floor of 0.02. The response matrix
//!   (filter x band, [`response`]) averages the transmission over each band's interval
//!   and is scaled so that exactly `leakage` of a filter's response to an equal-energy
//!   spectrum comes from other bands: the shape says where the leaked light comes from,
//!   `leakage` how much.
//! - **Dark level and gain.** Each pixel's dark level lies a fixed-pattern offset from the
//!   black level (normal, `dark_sd_dn`); hot pixels lie 10-50 % of the range above it.
//!   Each pixel turns light into signal with its own gain (normal about 1, `prnu`, the
//!   photo-response non-uniformity of EMVA 1288).
//! - **Vignetting.** A view gets `1 / (1 + a r^2)^2` of the centre view's light (the
//!   cos^4 law, `tan^2` of the ray's angle growing as `r^2`), `r` its distance from the
//!   centre of its lenslet's micro-image over the corner view's, `a` such that the corner
//!   view under the centre lenslet gets `1 - vignetting`. The micro-image's centre moves
//!   with the lenslet's place on the sensor (the main lens's chief ray): by half a view at
//!   the sensor's edges, so every lenslet vignettes its views differently.
//!
//! A [`Sensor`] is one such sensor drawn from its description's seed: every capture made
//! with it (scene, dark, flat, band sweep) sees the same dark levels, gains and hot pixels.

use anyhow::{Result, ensure};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::io::grid::GridDescription;
use crate::io::sensor::{FilterDescription, SensorDescription};

/// How far the micro-image's centre moves at the sensor's edges, in views.
pub const IMAGE_SHIFT: f64 = 0.5;

/// Samples of the transmission averaged over each band's interval.
const SAMPLES: usize = 32;

/// The filters' response matrix, row-major `[filter][band]` over `bands_nm` (the band
/// centres, increasing): each row's own band holds `1 - leakage`, the others share
/// `leakage` in proportion to the filter's mean transmission over their intervals (each
/// band's interval reaches halfway to its neighbours' centres; the end bands' as far out
/// as in). Each row sums to 1: a filter's response to an equal-energy spectrum is the
/// ideal filter's.
///
/// # Errors
/// Filters out of their ranges ([`SensorDescription::check`]'s), or fewer than 2 bands.
pub fn response(filters: &FilterDescription, bands_nm: &[f32]) -> Result<Vec<f64>> {
    let b = bands_nm.len();
    ensure!(b >= 2, "a response matrix needs 2 or more bands, not {b}");
    SensorDescription { filters: *filters, ..SensorDescription::IDEAL }.check()?;
    let c: Vec<f64> = bands_nm.iter().map(|&w| f64::from(w)).collect();
    // Each band's interval [lo, hi].
    let edges: Vec<(f64, f64)> = (0..b)
        .map(|i| {
            let below = if i > 0 { (c[i] - c[i - 1]) / 2.0 } else { (c[1] - c[0]) / 2.0 };
            let above = if i + 1 < b { (c[i + 1] - c[i]) / 2.0 } else { (c[b - 1] - c[b - 2]) / 2.0 };
            (c[i] - below, c[i] + above)
        })
        .collect();
    let w = f64::from(filters.width_nm);
    let peak = |x: f64| (-4.0 * std::f64::consts::LN_2 * x * x / (w * w)).exp();
    let (h, d, floor) = (f64::from(filters.secondary), f64::from(filters.secondary_nm), f64::from(filters.floor));
    let transmission =
        |centre: f64, l: f64| peak(l - centre) + h * (peak(l - centre - d) + peak(l - centre + d)) + floor;
    let leakage = f64::from(filters.leakage);
    let mut r = vec![0.0f64; b * b];
    for f in 0..b {
        let mean = |(lo, hi): (f64, f64)| {
            (0..SAMPLES).map(|k| transmission(c[f], lo + (hi - lo) * (k as f64 + 0.5) / SAMPLES as f64)).sum::<f64>()
                / SAMPLES as f64
        };
        let off: Vec<f64> = (0..b).map(|band| if band == f { 0.0 } else { mean(edges[band]) }).collect();
        let total: f64 = off.iter().sum();
        let row = &mut r[f * b..(f + 1) * b];
        for (band, x) in row.iter_mut().enumerate() {
            *x = if band == f {
                1.0 - leakage
            } else if total > 0.0 {
                leakage * off[band] / total
            } else {
                0.0
            };
        }
    }
    Ok(r)
}

/// The share of the centre view's light that view `(u, v)` of lenslet `(s, t)` gets, for
/// a sensor of `lenslets` lenslets of `views` views that loses `vignetting` at the corner
/// view under its centre lenslet.
pub fn vignette(
    vignetting: f32,
    lenslets: [usize; 2],
    views: [usize; 2],
    s: usize,
    t: usize,
    u: usize,
    v: usize,
) -> f64 {
    let half = |n: usize| (n as f64 - 1.0) / 2.0;
    let corner = half(views[0]).hypot(half(views[1]));
    if vignetting == 0.0 || corner == 0.0 {
        return 1.0;
    }
    // The micro-image's centre, moved by the lenslet's place (-1 to 1 across the sensor).
    let place = |i: usize, n: usize| 2.0 * (i as f64 + 0.5) / n as f64 - 1.0;
    let cu = half(views[0]) + IMAGE_SHIFT * place(s, lenslets[0]);
    let cv = half(views[1]) + IMAGE_SHIFT * place(t, lenslets[1]);
    shade(vignetting, corner, [u as f64 - cu, v as f64 - cv])
}

/// [`vignette`] on a lenslet grid ([`crate::io::grid`]): view `(u, v)` of a micro-image
/// centred on its middle view. The grid is the micro-images' grid, found from a flat as
/// the toolboxes find it, so the chief ray's shift is in its pitch, not here.
pub fn vignette_on_grid(vignetting: f32, views: [usize; 2], u: usize, v: usize) -> f64 {
    let half = |n: usize| (n as f64 - 1.0) / 2.0;
    let corner = half(views[0]).hypot(half(views[1]));
    if vignetting == 0.0 || corner == 0.0 {
        return 1.0;
    }
    shade(vignetting, corner, [u as f64 - half(views[0]), v as f64 - half(views[1])])
}

/// The cos^4 law's share at `d` views from the micro-image's centre, the corner view
/// `corner` views away losing `vignetting`.
fn shade(vignetting: f32, corner: f64, d: [f64; 2]) -> f64 {
    let a = 1.0 / (1.0 - f64::from(vignetting)).sqrt() - 1.0;
    let r2 = (d[0] * d[0] + d[1] * d[1]) / (corner * corner);
    1.0 / (1.0 + a * r2).powi(2)
}

/// One sensor drawn from its description: what each pixel adds and multiplies.
#[derive(Clone, Debug)]
pub struct Sensor {
    /// Its description.
    pub description: SensorDescription,
    /// Bands (the response matrix's side).
    pub bands: usize,
    /// Response matrix, `[filter][band]` ([`response`]).
    pub response: Vec<f64>,
    /// Each pixel's dark level above the black level, DN, row-major.
    pub dark: Vec<f32>,
    /// Each pixel's gain times its view's vignetting, row-major (on a lenslet grid the
    /// gain alone: the camera shades each view cell a pixel covers, [`vignette_on_grid`]).
    pub gain: Vec<f32>,
    /// Hot pixels, `[row, col]`, in row-major order.
    pub hot: Vec<[u32; 2]>,
}

impl Sensor {
    /// The sensor `d` describes, for frames of `lenslets` x `views` pixels over `bands_nm`,
    /// with `range_dn` DN between black and white (hot pixels sit 10-50 % of it above
    /// black); behind a lenslet grid, frames of `grid`'s sensor size.
    ///
    /// # Errors
    /// A description out of its ranges.
    pub fn new(
        d: &SensorDescription,
        lenslets: [usize; 2],
        views: [usize; 2],
        bands_nm: &[f32],
        range_dn: f32,
        grid: Option<&GridDescription>,
    ) -> Result<Self> {
        d.check()?;
        let response = response(&d.filters, bands_nm)?;
        let (rows, cols) = match grid {
            Some(g) => (g.sensor[0], g.sensor[1]),
            None => (lenslets[0] * views[0], lenslets[1] * views[1]),
        };
        // Its own stream: the same sensor whatever seeds the scene's noise.
        let mut rng = ChaCha8Rng::seed_from_u64(d.seed ^ 0x5e45_0a5e_45a0_5e45);
        let dark_sd = Normal::new(0.0f32, d.dark_sd_dn).map_err(|e| anyhow::anyhow!("dark_sd_dn: {e}"))?;
        let prnu = Normal::new(1.0f32, d.prnu).map_err(|e| anyhow::anyhow!("prnu: {e}"))?;
        let (mut dark, mut gain, mut hot) = (vec![0.0f32; rows * cols], vec![1.0f32; rows * cols], Vec::new());
        for row in 0..rows {
            for col in 0..cols {
                let p = row * cols + col;
                let mut level = dark_sd.sample(&mut rng);
                if d.hot_fraction > 0.0 && rng.random_bool(d.hot_fraction) {
                    level = level.abs() + range_dn * rng.random_range(0.1f32..0.5);
                    hot.push([row as u32, col as u32]);
                }
                dark[p] = level;
                let (s, u, t, v) = (row / views[0], row % views[0], col / views[1], col % views[1]);
                let shade =
                    if grid.is_some() { 1.0 } else { vignette(d.vignetting, lenslets, views, s, t, u, v) as f32 };
                gain[p] = prnu.sample(&mut rng).max(0.0) * shade;
            }
        }
        Ok(Self { description: *d, bands: bands_nm.len(), response, dark, gain, hot })
    }

    /// What pixel `p` behind filter `filter` turns light `spectrum` (one value per band)
    /// into, in units of white, before its dark level: its gain times the filter's
    /// response.
    pub fn signal(&self, p: usize, filter: usize, spectrum: impl Fn(usize) -> f32) -> f32 {
        let row = &self.response[filter * self.bands..(filter + 1) * self.bands];
        let l: f64 = row.iter().enumerate().map(|(b, &r)| r * f64::from(spectrum(b).max(0.0))).sum();
        self.gain[p] * l as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::spectra::BAND_NM;

    fn filters(leakage: f32) -> FilterDescription {
        FilterDescription { leakage, ..FilterDescription::IDEAL }
    }

    #[test]
    fn rows_hold_their_leakage_and_sum_to_one() {
        for leakage in [0.0f32, 0.1, 0.3] {
            let r = response(&filters(leakage), &BAND_NM).unwrap();
            let b = BAND_NM.len();
            for f in 0..b {
                let row = &r[f * b..(f + 1) * b];
                assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12, "row {f} sums to {}", row.iter().sum::<f64>());
                assert!((row[f] - (1.0 - f64::from(leakage))).abs() < 1e-12);
                assert!(row.iter().all(|&x| x >= 0.0));
                if leakage == 0.0 {
                    assert!(row.iter().enumerate().all(|(i, &x)| i == f || x == 0.0));
                }
            }
        }
    }

    /// The leaked light comes from where the filter transmits: the neighbours of the main
    /// peak and the bands under the secondary peaks (125 nm = 5 bands of 25 nm away) more
    /// than the floor's bands in between.
    #[test]
    fn the_leakage_comes_from_the_peaks() {
        let r = response(&filters(0.2), &BAND_NM).unwrap();
        let b = BAND_NM.len();
        let f = 6; // 550 nm: secondary peaks at 425 and 675 nm, bands 1 and 11
        let row = &r[f * b..(f + 1) * b];
        assert!(row[1] > 3.0 * row[3] && row[11] > 3.0 * row[9], "{row:?}");
        assert!(row[5] > row[4] && row[7] > row[8], "the main peak's tails: {row:?}");
        // A wider main peak leaks more into the next bands.
        let wide = response(&FilterDescription { width_nm: 40.0, ..filters(0.2) }, &BAND_NM).unwrap();
        assert!(wide[f * b + 5] > row[5]);
    }

    #[test]
    fn the_centre_lenslets_corner_view_loses_the_vignetting() {
        let (lenslets, views) = ([5, 5], [5, 5]);
        assert!((vignette(0.5, lenslets, views, 2, 2, 0, 0) - 0.5).abs() < 1e-12);
        assert!((vignette(0.5, lenslets, views, 2, 2, 4, 4) - 0.5).abs() < 1e-12);
        assert_eq!(vignette(0.5, lenslets, views, 2, 2, 2, 2), 1.0);
        // Falls with the distance from the centre.
        let v = |u, v| vignette(0.5, lenslets, views, 2, 2, u, v);
        assert!(v(2, 2) > v(2, 3) && v(2, 3) > v(3, 3) && v(3, 3) > v(4, 4));
        // An edge lenslet's micro-image is off centre: its views are shaded unevenly.
        let edge = |u| vignette(0.5, lenslets, views, 0, 2, u, 2);
        assert!(edge(0) > edge(4), "{} {}", edge(0), edge(4));
        assert_eq!(vignette(0.0, lenslets, views, 0, 0, 0, 0), 1.0);
    }

    #[test]
    fn a_sensor_is_its_seeds_and_its_statistics_are_asked_for() {
        let d = SensorDescription { dark_sd_dn: 4.0, hot_fraction: 0.01, prnu: 0.02, ..SensorDescription::IDEAL };
        let a = Sensor::new(&d, [40, 40], [5, 5], &BAND_NM, 3000.0, None).unwrap();
        let b = Sensor::new(&d, [40, 40], [5, 5], &BAND_NM, 3000.0, None).unwrap();
        assert_eq!((&a.dark, &a.gain, &a.hot), (&b.dark, &b.gain, &b.hot));
        let n = a.dark.len() as f64;
        let hot = a.hot.len() as f64 / n;
        assert!((0.007..0.013).contains(&hot), "hot fraction {hot}");
        let cold: Vec<f64> = a.dark.iter().filter(|&&x| x < 100.0).map(|&x| f64::from(x)).collect();
        let sd = (cold.iter().map(|x| x * x).sum::<f64>() / cold.len() as f64).sqrt();
        assert!((3.8..4.2).contains(&sd), "dark sd {sd}");
        let g: Vec<f64> = a.gain.iter().map(|&x| f64::from(x)).collect();
        let mean = g.iter().sum::<f64>() / n;
        let gsd = (g.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!((mean - 1.0).abs() < 0.002 && (0.019..0.021).contains(&gsd), "gain {mean} sd {gsd}");
        let other = Sensor::new(&SensorDescription { seed: 2, ..d }, [40, 40], [5, 5], &BAND_NM, 3000.0, None).unwrap();
        assert_ne!(a.dark, other.dark);
    }
}
