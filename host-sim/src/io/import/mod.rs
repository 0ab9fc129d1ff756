//! `slf import`: real data in, as the `(U, V, H, W, 13)` light field the rest of slf uses.
//!
//! Layers, lowest first (a lower one never names a higher one):
//!
//! - [`Plane`]: an image of any channel count in memory, with crop, resize and bilinear
//!   sampling; [`pfm`] reads the float maps disparities come in.
//! - [`bands`]: any spectrum, integrated over the camera's band filters (Gaussian, FWHM 25
//!   nm); [`rgb`]: linear sRGB lifted to spectra by Mallett and Yuksel (2019) under D65.
//! - [`parallax`]: views made from one image by a disparity (a fronto-parallel plane or a
//!   map), estimated by a plane sweep where no map is given.
//! - [`views`] (folders of RGB views: the HCI benchmark's layout, or a pattern with row and
//!   column placeholders), [`cube`] (hyperspectral `.npy` cubes and folders of band images,
//!   CAVE's layout), [`hdf5`] (light fields in HDF5 files, any axis order): the sources,
//!   each to a [`crate::io::lightfield::LightField`];
//!   [`resample_lightfield`] takes a light field of any band count to the camera's.
//!
//! Values are radiance scaled so a white reflector is 1 in the brightest band under D65,
//! as everywhere in slf. Every source's sizes are checked before its data is read.

pub mod bands;
pub mod cube;
pub mod hdf5;
pub mod parallax;
pub mod pfm;
pub mod rgb;
pub mod rgb_basis_data;
pub mod views;

use std::path::Path;

use anyhow::{Context, Result, ensure};
use image::ImageBuffer;
use image::imageops::{FilterType, resize};

/// The largest side of an image or cube read.
pub const MAX_SIDE: usize = 16_384;

/// The size of an image file, `(rows, cols)`, from its header alone, checked against
/// [`MAX_SIDE`].
pub fn image_size(path: &Path) -> Result<(usize, usize)> {
    let (w, h) = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .with_context(|| format!("{}: cannot open", path.display()))?
        .into_dimensions()
        .with_context(|| format!("{}: not an image slf reads", path.display()))?;
    let (w, h) = (w as usize, h as usize);
    ensure!(
        (1..=MAX_SIDE).contains(&w) && (1..=MAX_SIDE).contains(&h),
        "{}: {w} x {h} pixels is not within 1..={MAX_SIDE} a side",
        path.display()
    );
    Ok((h, w))
}

/// Reads an image file (8- or 16-bit, grey or colour, values as fractions of full scale)
/// as three channels; its size is checked against [`MAX_SIDE`] before it is decoded.
pub fn read_rgb(path: &Path) -> Result<Plane> {
    let (h, w) = image_size(path)?;
    let img = image::open(path).with_context(|| format!("{}: cannot decode", path.display()))?.into_rgb32f();
    ensure!(
        (img.height() as usize, img.width() as usize) == (h, w),
        "{}: the header says {w} x {h} pixels, the image is {} x {}",
        path.display(),
        img.width(),
        img.height()
    );
    Ok(Plane { rows: h, cols: w, channels: 3, data: img.into_raw() })
}

/// An image in memory: `rows x cols` pixels of `channels` f32 values, interleaved,
/// row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Values a pixel.
    pub channels: usize,
    /// `rows * cols * channels` values.
    pub data: Vec<f32>,
}

/// A window of an image, in its pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// First row.
    pub row: usize,
    /// First column.
    pub col: usize,
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
}

/// Where the spatial part of an import is cut and scaled: crop first, then resize.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Geometry {
    /// A window of the input (default: all of it).
    pub crop: Option<Crop>,
    /// `(rows, cols)` after the crop (default: as cropped).
    pub resize: Option<(usize, usize)>,
}

impl Geometry {
    /// Checks the window against an input of `rows x cols` and returns the output size.
    pub fn output_size(&self, rows: usize, cols: usize) -> Result<(usize, usize)> {
        let (r, c) = match self.crop {
            Some(k) => {
                ensure!(k.rows > 0 && k.cols > 0, "crop {} x {} is empty", k.rows, k.cols);
                ensure!(
                    k.row.checked_add(k.rows).is_some_and(|e| e <= rows)
                        && k.col.checked_add(k.cols).is_some_and(|e| e <= cols),
                    "crop rows {}..{}, columns {}..{} is outside the {rows} x {cols} input",
                    k.row,
                    k.row.saturating_add(k.rows),
                    k.col,
                    k.col.saturating_add(k.cols)
                );
                (k.rows, k.cols)
            }
            None => (rows, cols),
        };
        if let Some((rr, cc)) = self.resize {
            ensure!(
                (1..=1 << 16).contains(&rr) && (1..=1 << 16).contains(&cc),
                "resize to {rr} x {cc}: each side must be in 1..=65536"
            );
            return Ok((rr, cc));
        }
        Ok((r, c))
    }

    /// Crops and resizes a disparity map (pixels per view step) of the input's size: its
    /// values scale with the image's width, so they stay in output pixels.
    pub fn apply_disparity(&self, map: &Plane) -> Result<Plane> {
        let cropped_cols = self.crop.map_or(map.cols, |k| k.cols);
        let mut out = self.apply(map)?;
        let scale = out.cols as f32 / cropped_cols as f32;
        out.data.iter_mut().for_each(|v| *v *= scale);
        Ok(out)
    }

    /// Crops and resizes a plane.
    pub fn apply(&self, plane: &Plane) -> Result<Plane> {
        let (rows, cols) = self.output_size(plane.rows, plane.cols)?;
        let cropped = match self.crop {
            Some(k) => plane.crop(k),
            None => plane.clone(),
        };
        if (rows, cols) == (cropped.rows, cropped.cols) {
            return Ok(cropped);
        }
        Ok(cropped.resize(rows, cols))
    }
}

impl Plane {
    /// A plane of zeros.
    pub fn zeros(rows: usize, cols: usize, channels: usize) -> Self {
        Self { rows, cols, channels, data: vec![0.0; rows * cols * channels] }
    }

    /// The values of pixel `(r, c)`.
    pub fn pixel(&self, r: usize, c: usize) -> &[f32] {
        let i = (r * self.cols + c) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// A window (already checked to lie inside).
    pub fn crop(&self, k: Crop) -> Plane {
        let mut out = Plane::zeros(k.rows, k.cols, self.channels);
        let w = k.cols * self.channels;
        for r in 0..k.rows {
            let src = ((k.row + r) * self.cols + k.col) * self.channels;
            out.data[r * w..(r + 1) * w].copy_from_slice(&self.data[src..src + w]);
        }
        out
    }

    /// Resized to `rows x cols`, each channel by the `image` crate's separable triangle
    /// filter, which widens its support when shrinking (an area-weighted average, no
    /// aliasing) and interpolates linearly when enlarging.
    ///
    /// `image` clamps float pixels to `[0, 1]`, which would cut radiance above white and
    /// every negative disparity; so each channel is mapped to `[0, 1]` first and back
    /// after. The triangle's weights are non-negative and sum to 1, so the mapping
    /// commutes with the filter and nothing is lost but rounding.
    pub fn resize(&self, rows: usize, cols: usize) -> Plane {
        let mut out = Plane::zeros(rows, cols, self.channels);
        for ch in 0..self.channels {
            let mut values: Vec<f32> = self.data.iter().skip(ch).step_by(self.channels).copied().collect();
            let lo = values.iter().fold(f32::INFINITY, |m, &v| m.min(v));
            let hi = values.iter().fold(f32::NEG_INFINITY, |m, &v| m.max(v));
            let span = if hi > lo { hi - lo } else { 1.0 };
            values.iter_mut().for_each(|v| *v = (*v - lo) / span);
            let img: ImageBuffer<image::Luma<f32>, Vec<f32>> =
                ImageBuffer::from_raw(self.cols as u32, self.rows as u32, values).expect("sizes match");
            let small = resize(&img, cols as u32, rows as u32, FilterType::Triangle);
            for (o, v) in out.data.iter_mut().skip(ch).step_by(self.channels).zip(small.into_raw()) {
                *o = lo + v * span;
            }
        }
        out
    }

    /// Bilinear sample of every channel at fractional `(y, x)`, clamped to the edges.
    pub fn sample(&self, y: f64, x: f64, out: &mut [f32]) {
        let y = y.clamp(0.0, (self.rows - 1) as f64);
        let x = x.clamp(0.0, (self.cols - 1) as f64);
        let (y0, x0) = (y.floor() as usize, x.floor() as usize);
        let (y1, x1) = ((y0 + 1).min(self.rows - 1), (x0 + 1).min(self.cols - 1));
        let (fy, fx) = ((y - y0 as f64) as f32, (x - x0 as f64) as f32);
        let (a, b, c, d) = (self.pixel(y0, x0), self.pixel(y0, x1), self.pixel(y1, x0), self.pixel(y1, x1));
        for (k, o) in out.iter_mut().enumerate() {
            let top = a[k] + fx * (b[k] - a[k]);
            let bottom = c[k] + fx * (d[k] - c[k]);
            *o = top + fy * (bottom - top);
        }
    }
}

/// A light field of any band count (sampled at `wavelengths`) resampled to the camera's
/// bands, each integrated over its filter ([`bands`]). Values are kept as they are
/// (radiance, white = 1): only the spectral axis changes.
pub fn resample_lightfield(
    lf: &crate::io::lightfield::LightField,
    wavelengths: &[f32],
    centres_nm: &[f32],
    filter: bands::BandFilter,
) -> Result<crate::io::lightfield::LightField> {
    ensure!(
        wavelengths.len() == lf.bands,
        "{} wavelengths given for a light field of {} bands",
        wavelengths.len(),
        lf.bands
    );
    let r = bands::Resampler::new(wavelengths, centres_nm, filter)?;
    let data = r.apply_all(&lf.data);
    Ok(crate::io::lightfield::LightField {
        views: lf.views,
        rows: lf.rows,
        cols: lf.cols,
        bands: centres_nm.len(),
        data,
    })
}
