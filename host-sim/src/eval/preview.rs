//! Colour previews: spectra -> CIE XYZ (1931 2-degree observer at the band centres) -> sRGB.
//!
//! Light-field values are radiance under D65 scaled so a white reflector is 1 in D65's
//! brightest band; XYZ is normalised so that reflector has Y = 1, then converted to linear
//! sRGB (IEC 61966-2-1 matrix, D65 white) and gamma-encoded. A preview is exposed so the
//! ground truth's 99th-percentile luminance is white, the same for every panel, so dark
//! scenes are visible and panels compare.

use std::path::Path;

use anyhow::{Result, ensure};
use image::{Rgb, RgbImage};

use crate::io::lightfield::LightField;
use crate::io::output::write_png_rgb;
use crate::sim::spectra::{CMF_1931, D65};

/// XYZ of a radiance spectrum (white reflector: Y = 1).
pub fn xyz(spectrum: &[f32]) -> [f64; 3] {
    let peak = D65.iter().fold(0.0f32, |m, &x| m.max(x)) as f64;
    let white_y: f64 = D65.iter().zip(&CMF_1931).map(|(&e, c)| f64::from(e) / peak * f64::from(c[1])).sum();
    let mut out = [0.0; 3];
    for (&l, c) in spectrum.iter().zip(&CMF_1931) {
        for (o, &cm) in out.iter_mut().zip(c) {
            *o += f64::from(l) * f64::from(cm) / white_y;
        }
    }
    out
}

/// Linear sRGB of XYZ.
pub fn linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    const M: [[f64; 3]; 3] = [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]];
    M.map(|r| r[0] * xyz[0] + r[1] * xyz[1] + r[2] * xyz[2])
}

/// The sRGB transfer function, `[0, 1]` linear to 8 bits.
pub fn encode(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let e = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (e * 255.0).round() as u8
}

fn central(lf: &LightField) -> (usize, usize) {
    (lf.views.0 / 2, lf.views.1 / 2)
}

/// The exposure that maps the 99th-percentile luminance of `lf`'s central view to 1.
pub fn exposure(lf: &LightField) -> f64 {
    let (u, v) = central(lf);
    let mut ys: Vec<f64> =
        (0..lf.rows * lf.cols).map(|p| xyz(lf.spectrum(u, v, p / lf.cols, p % lf.cols))[1]).collect();
    ys.sort_by(f64::total_cmp);
    let p99 = ys.get(ys.len() * 99 / 100).copied().unwrap_or(1.0);
    if p99 > 0.0 { 1.0 / p99 } else { 1.0 }
}

/// The central view of `lf` as an sRGB image at `exposure`.
pub fn render(lf: &LightField, exposure: f64) -> RgbImage {
    let (u, v) = central(lf);
    RgbImage::from_fn(lf.cols as u32, lf.rows as u32, |x, y| {
        let rgb = linear_srgb(xyz(lf.spectrum(u, v, y as usize, x as usize)).map(|c| c * exposure));
        Rgb(rgb.map(encode))
    })
}

/// Heat colour (black, red, yellow, white) of `t` in `[0, 1]`.
fn heat(t: f64) -> Rgb<u8> {
    let t = t.clamp(0.0, 1.0) * 3.0;
    let c = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    Rgb([c(t), c(t - 1.0), c(t - 2.0)])
}

/// Writes a PNG of the central view: ground truth | reconstruction | error map (mean
/// absolute error over bands, full scale = 10 % of the truth's maximum), each panel scaled
/// up at least 4 times (nearest neighbour), labelled, with the error map's colour bar and
/// its scale in the image. `label` (the method, mask and k) is written under the
/// reconstruction, so the image says what made it.
///
/// # Errors
/// Shapes that differ, or the file cannot be written.
pub fn write_comparison(path: &Path, truth: &LightField, recon: &LightField, label: &str) -> Result<()> {
    use plotters::prelude::*;
    ensure!(truth.shape() == recon.shape(), "shapes differ");
    let e = exposure(truth);
    let (a, b) = (render(truth, e), render(recon, e));
    let (w, h) = (truth.cols as u32, truth.rows as u32);
    // At least 4x, and at least about 300 pixels a panel.
    let scale = 4.max(300u32.div_ceil(w.max(h).max(1)));
    let (pw, ph) = (w * scale, h * scale);
    let (gap, top, bottom) = (12, 34, 64);
    let (width, height) = (3 * pw + 4 * gap, top + ph + bottom);
    let mut out = RgbImage::from_pixel(width, height, Rgb([32, 32, 32]));
    let full = 0.1 * f64::from(truth.max()).max(1e-12);
    let (u, v) = central(truth);
    let x0 = [gap, 2 * gap + pw, 3 * gap + 2 * pw];
    for y in 0..ph {
        for x in 0..pw {
            let (sx, sy) = (x / scale, y / scale);
            out.put_pixel(x0[0] + x, top + y, *a.get_pixel(sx, sy));
            out.put_pixel(x0[1] + x, top + y, *b.get_pixel(sx, sy));
            let (ts, rs) =
                (truth.spectrum(u, v, sy as usize, sx as usize), recon.spectrum(u, v, sy as usize, sx as usize));
            let err = ts.iter().zip(rs).map(|(&p, &q)| f64::from((p - q).abs())).sum::<f64>() / ts.len() as f64;
            out.put_pixel(x0[2] + x, top + y, heat(err / full));
        }
    }
    // The error map's colour bar, under it: 0 to full scale.
    let bar = (x0[2], top + ph + 10, pw, 14);
    for x in 0..bar.2 {
        for y in 0..bar.3 {
            out.put_pixel(bar.0 + x, bar.1 + y, heat(f64::from(x) / f64::from(bar.2.max(2) - 1)));
        }
    }
    let mut raw = out.into_raw();
    {
        let root = BitMapBackend::with_buffer(&mut raw, (width, height)).into_drawing_area();
        let font = ("sans-serif", 17).into_font().color(&WHITE);
        let small = ("sans-serif", 14).into_font().color(&WHITE);
        let text = |s: &str, x: u32, y: u32, f: &TextStyle| {
            root.draw(&Text::new(s.to_string(), (x as i32, y as i32), f.clone())).map_err(|e| anyhow::anyhow!("{e}"))
        };
        text(&format!("ground truth, view ({u}, {v})"), x0[0], 8, &font)?;
        text("reconstruction", x0[1], 8, &font)?;
        text(label, x0[1], top + ph + 12, &small)?;
        text("mean |error| over bands", x0[2], 8, &font)?;
        text("0", bar.0, bar.1 + bar.3 + 4, &small)?;
        let hi = format!("{full:.3} (10 % of max)");
        text(&hi, (bar.0 + bar.2).saturating_sub(8 * hi.len() as u32), bar.1 + bar.3 + 4, &small)?;
        text(&format!("{} x {} lenslets, sRGB at the truth's exposure", w, h), x0[0], top + ph + 12, &small)?;
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    write_png_rgb(path, width, height, &raw)
}
