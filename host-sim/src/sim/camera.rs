//! The camera model: a light field to raw frames.
//!
//! Pixel `(s*U + u, t*V + v)` lies under lenslet `(s, t)` at view `(u, v)` and, in snapshot
//! `j`, integrates band `mask.band(j, row, col)` of the light field there (the firmware's own
//! mask code decides, so simulation and decoding agree by construction). The signal is
//! `L * full_well` electrons with Poisson shot noise, converted to DN between the black and
//! white levels, plus Gaussian read noise, rounded and clipped to the sensor's bits (the top
//! code is saturated). Defective pixels are stuck at 0 or the top code and listed in the
//! capture description, as a calibrated camera would list them.
//!
//! Behind a lenslet grid ([`CameraConfig::grid`], [`crate::io::grid`]: rotated, a
//! non-integer pitch, offset) a pixel records each view cell it covers, weighted by the
//! share of its area the cell covers ([`crate::sim::footprint`]), across the micro-images'
//! borders too; the frames are the grid's sensor's size, and the capture records the grid
//! (`lenslet_grid`, version 2). Only the pixel mask (a filter per sensor pixel) is modelled
//! there: a lenslet or kronecker mask's filters sit on the lenslets.
//!
//! With a real sensor ([`crate::sim::sensor`]) a pixel records its filter's response to
//! every band, times its gain and its view's vignetting, above its own dark level; the
//! capture then records the sensor (`simulated_sensor`, version 2). The ideal sensor's
//! captures are made and written exactly as before.

use anyhow::{Result, ensure};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Poisson};

use crate::io::capture::{
    Capture, CaptureDescription, FORMAT, Light, MaskDescription, MaskSource, NoiseDescription, VERSION, VERSION_SENSOR,
};
use crate::io::frame_file::frame_names;
use crate::io::grid::{GridDescription, lenslet_view};
use crate::io::lightfield::LightField;
use crate::io::sensor::SensorDescription;
use crate::sim::footprint::footprint;
use crate::sim::sensor::{Sensor, vignette_on_grid};
use crate::sim::spectra::BAND_NM;

/// Everything about the simulated camera besides the light field.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraConfig {
    pub mask: MaskDescription,
    /// Sensor bits (12 is usual).
    pub bits: u8,
    /// Raw value of no light.
    pub black_level: u16,
    /// Fraction of the range between black and the top code that a white surface fills
    /// (headroom for highlights; 0.9 by default).
    pub white_fraction: f32,
    /// Electrons at the white level; `None` for no shot noise.
    pub full_well: Option<f32>,
    /// Read noise, DN.
    pub read_noise: f32,
    /// Fraction of pixels that are defective.
    pub defect_fraction: f64,
    /// Seed of the noise and defects.
    pub seed: u64,
    /// Frame file extension: `pgm`, `png` or `npy`.
    pub frame_ext: String,
    /// The sensor's imperfections ([`SensorDescription::IDEAL`]: none).
    pub sensor: SensorDescription,
    /// Where the lenslet array sits on the sensor: rotation, pitch, offset
    /// ([`crate::io::grid`]); `None` (or the aligned grid) for `U x V` pixels under every
    /// lenslet, its rows the sensor's.
    pub grid: Option<GridSettings>,
}

/// A lenslet grid as a user states it: the sensor's size and the offset follow from the
/// light field's lenslets ([`GridDescription::centred`]) unless given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSettings {
    /// Degrees (positive turns the lenslet rows down to the right).
    pub rotation_deg: f64,
    /// Pixels per lenslet, `[rows, cols]`; `None`: the light field's views.
    pub pitch: Option<[f64; 2]>,
    /// Lenslet (0, 0)'s micro-image centre `[row, col]`, pixels; `None`: the array
    /// centred on the sensor.
    pub offset: Option<[f64; 2]>,
}

impl GridSettings {
    /// The grid for a light field of `lenslets` lenslets of `views` views.
    pub fn grid(&self, lenslets: [usize; 2], views: [usize; 2]) -> GridDescription {
        let pitch = self.pitch.unwrap_or([views[0] as f64, views[1] as f64]);
        let centred = GridDescription::centred(lenslets, self.rotation_deg, pitch);
        GridDescription { offset: self.offset.unwrap_or(centred.offset), ..centred }
    }
}

impl CameraConfig {
    /// A `pixel` mask camera with `k` snapshots and the default sensor: 12 bits, black 64,
    /// white at 90 % of the range, 20,000 e- full well, 2 DN read noise, no defects.
    pub fn pixel(seed: u64, k: u8) -> Self {
        Self {
            mask: MaskDescription::Pixel(MaskSource { snapshots: Some(k), seed: Some(seed), tile: None }),
            bits: 12,
            black_level: 64,
            white_fraction: 0.9,
            full_well: Some(20_000.0),
            read_noise: 2.0,
            defect_fraction: 0.0,
            seed,
            frame_ext: "pgm".into(),
            sensor: SensorDescription::IDEAL,
            grid: None,
        }
    }

    /// The same sensor with another mask.
    pub fn with_mask(self, mask: MaskDescription) -> Self {
        Self { mask, ..self }
    }

    /// No noise at all (shot or read): for tests that isolate the decoder.
    pub fn noiseless(self) -> Self {
        Self { full_well: None, read_noise: 0.0, ..self }
    }

    /// Snapshots the mask takes.
    pub fn snapshots(&self) -> usize {
        match &self.mask {
            MaskDescription::Kronecker { snapshots, .. } => *snapshots as usize,
            MaskDescription::Pixel(s) | MaskDescription::Lenslet(s) => {
                s.tile.as_ref().map(|t| t.len()).or(s.snapshots.map(usize::from)).unwrap_or(0)
            }
        }
    }
}

/// Records `lf` (views = the lenslet's pixels) with `cam`.
///
/// # Errors
/// A bad mask or sensor description.
pub fn simulate(lf: &LightField, cam: &CameraConfig) -> Result<Capture> {
    simulate_under(lf, cam, Light::Scene)
}

/// As [`simulate`], for a capture taken under `light` (a calibration capture: the light
/// field is the calibration target, recorded in the description, version 2).
///
/// # Errors
/// As [`simulate`].
pub fn simulate_under(lf: &LightField, cam: &CameraConfig, light: Light) -> Result<Capture> {
    ensure!(lf.bands == BAND_NM.len(), "light field has {} bands, the camera {}", lf.bands, BAND_NM.len());
    ensure!(
        lf.views.0 <= lf.rows && lf.views.1 <= lf.cols,
        "the light field has more views ({} x {}) than lenslets ({} x {}): slf reads (U, V, H, W, B); \
         is this array (H, W, U, V, B)? (numpy: np.transpose(a, (2, 3, 0, 1, 4)))",
        lf.views.0,
        lf.views.1,
        lf.rows,
        lf.cols
    );
    ensure!(
        cam.full_well.is_none_or(|f| f.is_finite() && f > 0.0),
        "full well {:?} electrons: must be finite and above 0",
        cam.full_well
    );
    ensure!(
        cam.read_noise.is_finite() && cam.read_noise >= 0.0,
        "read noise {} DN: must be finite, at or above 0",
        cam.read_noise
    );
    ensure!((0.0..1.0).contains(&cam.defect_fraction), "defect fraction {} out of [0, 1)", cam.defect_fraction);
    ensure!(
        cam.white_fraction.is_finite() && cam.white_fraction > 0.0 && cam.white_fraction <= 1.0,
        "white fraction {} out of (0, 1]",
        cam.white_fraction
    );
    ensure!((1..=16).contains(&cam.bits), "bits {} out of 1..=16", cam.bits);
    let top = ((1u32 << cam.bits) - 1) as f32;
    let black = f32::from(cam.black_level);
    ensure!(black < top, "black level {black} at or above the top code {top}");
    let white = black + cam.white_fraction * (top - black);
    let (lu, lv) = lf.views;
    // The aligned grid is no grid: its captures are made and written as before grids.
    let grid =
        cam.grid.map(|g| g.grid([lf.rows, lf.cols], [lu, lv])).filter(|g| !g.is_aligned([lf.rows, lf.cols], [lu, lv]));
    if let Some(g) = &grid {
        g.check([lf.rows, lf.cols], [lu, lv])?;
    }
    let (rows, cols) = grid.map_or((lf.rows * lu, lf.cols * lv), |g| (g.sensor[0], g.sensor[1]));
    let k = cam.snapshots();

    let mut rng = ChaCha8Rng::seed_from_u64(cam.seed);
    let defects: Vec<[u32; 2]> = (0..rows * cols)
        .filter(|_| cam.defect_fraction > 0.0 && rng.random_bool(cam.defect_fraction.min(1.0)))
        .map(|p| [(p / cols) as u32, (p % cols) as u32])
        .collect();
    let real = !cam.sensor.is_ideal();
    let description = CaptureDescription {
        format: FORMAT.into(),
        version: if real || !light.is_scene() || grid.is_some() { VERSION_SENSOR } else { VERSION },
        lenslets: [lf.rows, lf.cols],
        views: [lu, lv],
        bands_nm: BAND_NM.to_vec(),
        mask: cam.mask.clone(),
        frames: frame_names(k, &cam.frame_ext),
        bits: cam.bits,
        black_level: black,
        white_level: white,
        saturation_level: top,
        noise: cam.full_well.map(|fw| NoiseDescription { full_well_electrons: fw, read_noise_dn: cam.read_noise }),
        defective_pixels: defects.clone(),
        simulated_sensor: real.then_some(cam.sensor),
        light,
        lenslet_grid: grid,
        files: None,
    };
    // Build the mask through the capture so the description is checked the same way as a
    // loaded one.
    let blank = Capture::new(description.clone(), vec![vec![0; rows * cols]; k])?;
    let mask = blank.mask()?;
    let sensor = if real {
        Some(Sensor::new(&cam.sensor, [lf.rows, lf.cols], [lu, lv], &BAND_NM, white - black, grid.as_ref())?)
    } else {
        None
    };
    let read = Normal::new(0.0f32, cam.read_noise.max(0.0)).map_err(|e| anyhow::anyhow!("read noise: {e}"))?;
    let mut frames = vec![vec![0u16; rows * cols]; k];
    let vignetting = cam.sensor.vignetting;
    let mut cells = Vec::new();
    for row in 0..rows {
        for col in 0..cols {
            let bands = mask.bands_at(row, col);
            // The light field where the pixel lies: its view, or behind a grid each view
            // cell it covers, weighted by its share and shaded by its view's vignetting
            // (the lenslet's neighbours' cells too; no light outside the light field).
            let (s, u, t, v) = (row / lu, row % lu, col / lv, col % lv);
            if let Some(g) = &grid {
                footprint(g, [lu, lv], row, col, &mut cells);
            }
            let light = |b: usize| match &grid {
                None => lf.get(u, v, s, t, b),
                Some(_) => cells
                    .iter()
                    .filter_map(|&(cell, share)| {
                        let ([s, t], [u, v]) = lenslet_view(cell, [lf.rows, lf.cols], [lu, lv])?;
                        let shade = if real { vignette_on_grid(vignetting, [lu, lv], u, v) } else { 1.0 };
                        Some(share * shade * f64::from(lf.get(u, v, s, t, b).max(0.0)))
                    })
                    .sum::<f64>() as f32,
            };
            for (j, &band) in bands.iter().enumerate() {
                let p = row * cols + col;
                let l = match &sensor {
                    None => light(band as usize).max(0.0),
                    Some(sensor) => sensor.signal(p, band as usize, light),
                };
                let dark = sensor.as_ref().map_or(0.0, |sensor| sensor.dark[p]);
                let signal = match cam.full_well {
                    Some(fw) if l > 0.0 => {
                        let e = f64::from(l * fw);
                        let noisy = Poisson::new(e).map(|p| p.sample(&mut rng) as f32).unwrap_or(l * fw);
                        noisy / fw
                    }
                    _ => l,
                };
                let dn = black
                    + dark
                    + signal * (white - black)
                    + if cam.read_noise > 0.0 { read.sample(&mut rng) } else { 0.0 };
                frames[j][row * cols + col] = dn.round().clamp(0.0, top) as u16;
            }
        }
    }
    for &[r, c] in &defects {
        let stuck = if rng.random_bool(0.5) { 0 } else { top as u16 };
        for f in &mut frames {
            f[r as usize * cols + c as usize] = stuck;
        }
    }
    Capture::new(description, frames)
}
