//! `slf simulate`: record a light field with the camera model (mask, optics, noise, 16-bit
//! frames, defects) into a capture folder.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;
use slf_host::io::lightfield::read_npy;
use slf_host::sim::camera::{CameraConfig, simulate};

use super::import::with_camera_bands;
use crate::args::{Family, positive};

#[derive(clap::Args)]
pub struct Args {
    /// Light field .npy (U, V, H, W, B): 13 bands, or any other count with --wavelengths.
    pub input: PathBuf,
    /// Wavelengths of the light field's bands when it does not have the camera's 13
    /// (START:STOP:STEP or a comma list, nm): resampled over the camera's band filters.
    #[arg(long)]
    pub wavelengths: Option<String>,
    /// Capture folder to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Mask family: which band each pixel sees in each snapshot.
    #[arg(long, value_enum, default_value_t = Family::Pixel)]
    pub mask: Family,
    /// Snapshots k (1..=13).
    #[arg(short, long, default_value_t = 1)]
    pub snapshots: u8,
    /// Seed of the mask, noise and defects.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Read noise, DN (finite, at or above 0).
    #[arg(long, default_value_t = 2.0, value_parser = non_negative)]
    pub read_noise: f32,
    /// Electrons at white (shot noise); finite, above 0.
    #[arg(long, default_value_t = 20_000.0, value_parser = positive)]
    pub full_well: f32,
    /// No shot or read noise.
    #[arg(long)]
    pub no_noise: bool,
    /// Fraction of defective pixels, in [0, 1).
    #[arg(long, default_value_t = 0.0, value_parser = fraction)]
    pub defects: f64,
    /// Frame file format.
    #[arg(long, value_enum, default_value_t = FrameFormat::Pgm)]
    pub format: FrameFormat,
}

pub fn run(args: Args) -> Result<()> {
    let Args { input, wavelengths, output, mask, snapshots, seed, read_noise, full_well, no_noise, defects, format } =
        args;
    let lf = with_camera_bands(read_npy(&input)?, wavelengths.as_deref(), &input)?;
    let mut cam = CameraConfig::pixel(seed, snapshots).with_mask(mask.mask(seed, snapshots));
    cam.read_noise = read_noise;
    cam.full_well = Some(full_well);
    cam.defect_fraction = defects;
    cam.frame_ext = format!("{format:?}").to_lowercase();
    if no_noise {
        cam = cam.noiseless();
    }
    let capture = simulate(&lf, &cam).map_err(|e| anyhow::anyhow!("{}: {e:#}", input.display()))?;
    let (clipped, total) = capture.saturated_pixels();
    if clipped > 0 {
        eprintln!(
            "warning: {}: {clipped} of {total} pixels ({:.2} %) saturated: the light field exceeds white \
             (max {:.3}, clips at {:.3}); saturated pixels are not measurements",
            input.display(),
            100.0 * clipped as f64 / total as f64,
            lf.max(),
            1.0 / cam.white_fraction
        );
    }
    capture.save(&output)?;
    println!("wrote {} ({} snapshots)", output.display(), capture.frames.len());
    Ok(())
}

/// The frame file format `slf simulate` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FrameFormat {
    /// Binary 16-bit PGM (P5).
    Pgm,
    /// 16-bit grey PNG.
    Png,
    /// uint16 `.npy`, 2 axes.
    Npy,
}

/// A finite number at or above zero, for clap.
fn non_negative(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number at or above 0")),
    }
}

/// A fraction in `[0, 1)`, for clap.
fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => Err(format!("{s:?} is not a fraction in [0, 1)")),
    }
}
