//! Hyperspectral cubes: a `(H, W, B)` `.npy` with its wavelengths, or a folder of band
//! images (CAVE's layout: `NAME_ms_01.png` .. `NAME_ms_31.png`, 400..=700 nm in 10 nm
//! steps), made into a `U x V`-view light field of the camera's bands.
//!
//! Steps: the cube's values are divided by `white` (the value of a perfect white
//! reflector); a reflectance cube is lit by D65 at its own wavelengths (an already-lit
//! radiance cube is not); each spectrum is integrated over the camera's band filters
//! ([`super::bands`]), scaled so white under D65 is 1 in the brightest band; the result is
//! cropped and resized; and views are made by a disparity ([`super::parallax`]): a
//! fronto-parallel plane, or a map (PFM) of the centre view's disparities.
//!
//! A cube has one viewpoint, so the views' differences are the disparity's alone: the light
//! field is Lambertian and has no occlusion, easier in the angular dimensions than a real
//! one; its spectra, unlike lifted RGB, are real.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};

use super::bands::{BandFilter, Resampler};
use super::parallax::{Disparity, warp};
use super::pfm::read_pfm;
use super::rgb_basis_data::{D65_5NM, FIRST_NM, STEP_NM};
use super::{Geometry, MAX_SIDE, Plane, read_rgb};
use crate::io::lightfield::LightField;
use crate::io::npy;

/// How a cube's values relate to light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Light {
    /// Reflectance (CAVE): lit by D65 on import.
    Reflectance,
    /// Radiance already: only scaled by `white`.
    Radiance,
}

/// How a cube becomes views.
#[derive(Clone, Debug, PartialEq)]
pub enum Depth {
    /// Every pixel at this disparity, pixels per view step.
    Plane(f32),
    /// The centre view's disparity a pixel, a `.pfm` of the cube's size.
    Map(PathBuf),
}

/// Settings of a cube import.
#[derive(Clone, Debug, PartialEq)]
pub struct CubeConfig {
    /// Wavelengths of the cube's bands, nm (default for a band folder: 400..=700 by 10
    /// nm for 31 bands).
    pub wavelengths: Option<Vec<f32>>,
    /// The value of a perfect white reflector (default 1: float data as is; integer
    /// images are read as fractions of their full scale).
    pub white: f32,
    /// Reflectance or radiance.
    pub light: Light,
    /// Views `(U, V)`.
    pub views: (usize, usize),
    /// The disparity that makes the views.
    pub depth: Depth,
    /// Crop and resize.
    pub geometry: Geometry,
}

impl Default for CubeConfig {
    fn default() -> Self {
        Self {
            wavelengths: None,
            white: 1.0,
            light: Light::Reflectance,
            views: (5, 5),
            depth: Depth::Plane(1.0),
            geometry: Geometry::default(),
        }
    }
}

/// The most bands a cube may have.
const MAX_BANDS: usize = 4096;

/// Reads a `(H, W, B)` `.npy` cube (float32, float64 or uint16 as a fraction of 65535).
pub fn read_cube_npy(path: &Path) -> Result<(Plane, Vec<String>)> {
    let a = npy::read(path)?;
    let s = &a.shape;
    ensure!(s.len() == 3, "{}: shape {s:?}: a cube is (H, W, B)", path.display());
    ensure!(
        (1..=MAX_SIDE).contains(&s[0]) && (1..=MAX_SIDE).contains(&s[1]) && (1..=MAX_BANDS).contains(&s[2]),
        "{}: shape {s:?}: need H and W in 1..={MAX_SIDE}, B in 1..={MAX_BANDS}",
        path.display()
    );
    let data = a.values.into_f32();
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        let b = i % s[2];
        let px = i / s[2];
        bail!("{}: value at (row {}, column {}, band {b}) is not finite", path.display(), px / s[1], px % s[1]);
    }
    Ok((Plane { rows: s[0], cols: s[1], channels: s[2], data }, a.notes))
}

/// The band images of a folder, in band order: files named `..._NN.png` (CAVE: `_ms_NN`),
/// sorted by `NN`. A folder holding only one subfolder (CAVE's archives nest
/// `NAME_ms/NAME_ms/`) is entered.
pub fn band_files(folder: &Path) -> Result<Vec<PathBuf>> {
    let list = |dir: &Path| -> Result<Vec<PathBuf>> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("{}: cannot list", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        v.sort();
        Ok(v)
    };
    let mut entries = list(folder)?;
    if entries.len() == 1 && entries[0].is_dir() {
        entries = list(&entries[0].clone())?;
    }
    let mut numbered: Vec<(u32, PathBuf)> = entries
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")))
        .filter_map(|p| {
            let stem = p.file_stem()?.to_str()?;
            let digits = stem.rsplit('_').next()?;
            let n: u32 = digits.parse().ok()?;
            Some((n, p))
        })
        .collect();
    ensure!(!numbered.is_empty(), "{}: no band images (NAME_NN.png) in it", folder.display());
    numbered.sort();
    if let Some(w) = numbered.windows(2).find(|w| w[0].0 == w[1].0) {
        bail!(
            "{}: two band images numbered {}: {} and {}",
            folder.display(),
            w[0].0,
            w[0].1.display(),
            w[1].1.display()
        );
    }
    Ok(numbered.into_iter().map(|(_, p)| p).collect())
}

/// Reads a folder of band images (8- or 16-bit, as fractions of full scale) as a cube.
pub fn read_band_folder(folder: &Path) -> Result<Plane> {
    let files = band_files(folder)?;
    ensure!(files.len() <= MAX_BANDS, "{}: {} band images, more than {MAX_BANDS}", folder.display(), files.len());
    let mut cube: Option<Plane> = None;
    let bands = files.len();
    for (b, f) in files.iter().enumerate() {
        // Grey (some CAVE files are stored as RGB(A) with equal channels): the first channel.
        let img = read_rgb(f)?;
        let (h, w) = (img.rows, img.cols);
        let c = cube.get_or_insert_with(|| Plane::zeros(h, w, bands));
        ensure!(
            (c.rows, c.cols) == (h, w),
            "{}: {w} x {h} pixels, the first band {} x {}",
            f.display(),
            c.cols,
            c.rows
        );
        for (px, v) in img.data.chunks_exact(3).enumerate() {
            c.data[px * bands + b] = v[0];
        }
    }
    cube.ok_or_else(|| anyhow::anyhow!("{}: no band images", folder.display()))
}

/// D65 at a wavelength, linear between its 5 nm samples, held beyond 380 and 780 nm.
pub fn d65_at(nm: f32) -> f32 {
    let t = ((nm - FIRST_NM) / STEP_NM).clamp(0.0, (D65_5NM.len() - 1) as f32);
    let i = (t.floor() as usize).min(D65_5NM.len() - 2);
    let f = t - i as f32;
    D65_5NM[i] + f * (D65_5NM[i + 1] - D65_5NM[i])
}

/// A cube (`channels` = its bands, at `wavelengths`) to the camera's bands, white = 1 in
/// the brightest band under D65: `(H, W, bands)`.
pub fn to_camera_bands(
    cube: &Plane,
    wavelengths: &[f32],
    centres_nm: &[f32],
    filter: BandFilter,
    white: f32,
    light: Light,
) -> Result<Plane> {
    ensure!(
        wavelengths.len() == cube.channels,
        "{} wavelengths for a cube of {} bands",
        wavelengths.len(),
        cube.channels
    );
    ensure!(white.is_finite() && white > 0.0, "white {white} must be finite and above 0");
    let resampler = Resampler::new(wavelengths, centres_nm, filter)?;
    // White under D65, band-integrated, sets the scale whatever the cube's light.
    let d65: Vec<f32> = wavelengths.iter().map(|&w| d65_at(w)).collect();
    let mut white_bands = vec![0.0; centres_nm.len()];
    resampler.apply(&d65, &mut white_bands);
    let peak = white_bands.iter().fold(0.0f32, |m, &x| m.max(x));
    let mut lit = cube.data.clone();
    for px in lit.chunks_exact_mut(cube.channels) {
        for (v, e) in px.iter_mut().zip(&d65) {
            *v = match light {
                Light::Reflectance => *v / white * e / peak,
                // Radiance relative to white: as is, so white radiance (D65 itself) is 1.
                Light::Radiance => *v / white,
            };
        }
    }
    let data = resampler.apply_all(&lit);
    Ok(Plane { rows: cube.rows, cols: cube.cols, channels: centres_nm.len(), data })
}

/// Makes the `U x V` views of a camera-band image by the configured disparity.
pub fn to_lightfield(image: &Plane, cfg: &CubeConfig, source: (usize, usize)) -> Result<(LightField, Option<Plane>)> {
    let (nu, nv) = cfg.views;
    ensure!((1..=16).contains(&nu) && (1..=16).contains(&nv), "views {nu} x {nv}: each in 1..=16");
    let (rows, cols) = cfg.geometry.output_size(image.rows, image.cols)?;
    LightField::check_size((nu, nv), rows, cols, image.channels).context("the imported light field")?;
    let img = cfg.geometry.apply(image)?;
    let map = match &cfg.depth {
        Depth::Plane(d) => {
            ensure!(d.is_finite() && d.abs() <= 64.0, "disparity {d} is not within -64..=64 pixels a view");
            None
        }
        Depth::Map(p) => {
            let m = read_pfm(p)?;
            ensure!(
                (m.rows, m.cols) == source,
                "{}: {} x {} disparities for a {} x {} cube",
                p.display(),
                m.cols,
                m.rows,
                source.1,
                source.0
            );
            Some(cfg.geometry.apply_disparity(&m)?)
        }
    };
    let disparity = match (&cfg.depth, &map) {
        (Depth::Plane(d), _) => Disparity::Plane(*d),
        (_, Some(m)) => Disparity::Map(m),
        (Depth::Map(_), None) => unreachable!("a map was read above"),
    };
    let bands = img.channels;
    let mut lf = LightField::zeros((nu, nv), img.rows, img.cols, bands);
    let per_view = img.rows * img.cols * bands;
    let (cu, cv) = ((nu / 2) as f64, (nv / 2) as f64);
    for u in 0..nu {
        for v in 0..nv {
            let view = warp(&img, disparity, u as f64 - cu, v as f64 - cv)?;
            let i = u * nv + v;
            lf.data[i * per_view..(i + 1) * per_view].copy_from_slice(&view.data);
        }
    }
    Ok((lf, map))
}
