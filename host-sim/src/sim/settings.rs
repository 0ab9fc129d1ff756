//! What a user asks of a simulated capture: `slf simulate`'s flags, in one place for the
//! command and the Python package (`slf.simulate`), so both take the same defaults and
//! ranges and give the same one-line errors ([`SimulateSettings::from_flags`] parses the
//! flags from strings, the way the package passes its keywords).

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use slf_firmware::MaskFamily;

use crate::io::capture::{Capture, MaskDescription};
use crate::io::grid::MAX_ROTATION_DEG;
use crate::io::lightfield::LightField;
use crate::io::sensor::{FilterDescription, SensorDescription};
use crate::sim::camera::{CameraConfig, GridSettings, simulate};
use crate::sim::flags::{FromFlags, positive};
use crate::sim::import::{check_decodable, with_camera_bands};

/// `--mask`: the mask family, which band each pixel sees in each snapshot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Family {
    /// A band per sensor pixel and snapshot.
    Pixel,
    /// A band per lenslet and snapshot: every view of a lenslet sees it.
    Lenslet,
    /// The paper's separable mask: a band per 5 x 5-lenslet patch and snapshot.
    Kronecker,
}

impl Family {
    /// The firmware's mask family.
    pub fn family(self) -> MaskFamily {
        match self {
            Family::Pixel => MaskFamily::Pixel,
            Family::Lenslet => MaskFamily::Lenslet,
            Family::Kronecker => MaskFamily::Kronecker,
        }
    }

    /// The mask drawn from `seed` for `k` snapshots.
    pub fn mask(self, seed: u64, k: u8) -> MaskDescription {
        MaskDescription::seeded(self.family(), seed, k)
    }
}

/// The frame file format a saved capture uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FrameFormat {
    /// Binary 16-bit PGM (P5).
    Pgm,
    /// 16-bit grey PNG.
    Png,
    /// uint16 `.npy`, 2 axes.
    Npy,
}

impl FrameFormat {
    /// The frame files' extension.
    pub fn extension(self) -> &'static str {
        match self {
            FrameFormat::Pgm => "pgm",
            FrameFormat::Png => "png",
            FrameFormat::Npy => "npy",
        }
    }
}

/// `slf simulate`'s settings: the camera and its noise, but not where the light field comes
/// from or where the capture goes.
#[derive(Args, Clone, Debug)]
pub struct SimulateSettings {
    /// Wavelengths of the light field's bands when it does not have the camera's 13
    /// (START:STOP:STEP or a comma list, nm): resampled over the camera's band filters.
    #[arg(long)]
    pub wavelengths: Option<String>,
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
    /// A real sensor (all off by default: the ideal sensor the decoder assumes).
    #[command(flatten)]
    pub sensor: SensorSettings,
    /// A real lenslet array (off by default: `U x V` pixels under every lenslet).
    #[command(flatten)]
    pub grid: GridFlags,
}

/// `slf simulate`'s lenslet-grid flags ([`crate::io::grid`]): any of them puts the
/// lenslet array where they say; the capture records it (`lenslet_grid`, version 2).
#[derive(Args, Clone, Debug, Default)]
pub struct GridFlags {
    /// The lenslet rows' angle to the sensor's rows, degrees in [-10, 10] (positive turns
    /// them down to the right): a real array is glued on a few tenths of a degree off.
    #[arg(long, value_parser = rotation)]
    pub rotation: Option<f64>,
    /// Pixels from one micro-image centre to the next (PX, or ROWS,COLS), within 20 % of
    /// the views (default: the views, 5).
    #[arg(long, value_parser = pair)]
    pub pitch: Option<[f64; 2]>,
    /// Lenslet (0, 0)'s micro-image centre on the sensor, ROW,COL in pixels (default: the
    /// array centred on the sensor).
    #[arg(long, value_parser = pair, allow_hyphen_values = true)]
    pub grid_offset: Option<[f64; 2]>,
}

impl GridFlags {
    /// The grid these flags describe; `None` if none is given.
    pub fn settings(&self) -> Option<GridSettings> {
        if self.rotation.is_none() && self.pitch.is_none() && self.grid_offset.is_none() {
            return None;
        }
        Some(GridSettings { rotation_deg: self.rotation.unwrap_or(0.0), pitch: self.pitch, offset: self.grid_offset })
    }
}

/// A rotation in degrees, within [`MAX_ROTATION_DEG`] (read as f64: the grid's own type).
fn rotation(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v.abs() <= MAX_ROTATION_DEG => Ok(v),
        _ => Err(format!("{s:?} is not a number in [-{MAX_ROTATION_DEG}, {MAX_ROTATION_DEG}] (degrees)")),
    }
}

/// `X` or `X,Y`: one finite number for both axes, or one each.
fn pair(s: &str) -> Result<[f64; 2], String> {
    let v: Vec<Option<f64>> = s.split(',').map(|x| x.trim().parse::<f64>().ok().filter(|v| v.is_finite())).collect();
    match v.as_slice() {
        [Some(x)] => Ok([*x, *x]),
        [Some(x), Some(y)] => Ok([*x, *y]),
        _ => Err(format!("{s:?} is not one finite number or two, comma-separated")),
    }
}

/// `slf simulate`'s real-sensor flags ([`crate::sim::sensor`]); a capture made with any of
/// them records its sensor (capture format version 2).
#[derive(Args, Clone, Debug)]
pub struct SensorSettings {
    /// Filter leakage: the fraction of a pixel's response to an equal-energy spectrum that
    /// comes from bands other than its filter's, in [0, 0.9].
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| within(s, 0.0, 0.9))]
    pub leakage: f32,
    /// The filters' main peak width (FWHM), nm, in [1, 200]: where leaked light comes from.
    #[arg(long, default_value_t = FilterDescription::IDEAL.width_nm, value_parser = |s: &str| within(s, 1.0, 200.0))]
    pub filter_width: f32,
    /// The filters' secondary peaks, relative to the main one, in [0, 1].
    #[arg(long, default_value_t = FilterDescription::IDEAL.secondary, value_parser = |s: &str| within(s, 0.0, 1.0))]
    pub secondary: f32,
    /// How far the secondary peaks lie from the main one (both sides), nm, in [0, 1000].
    #[arg(long, default_value_t = FilterDescription::IDEAL.secondary_nm, value_parser = |s: &str| within(s, 0.0, 1000.0))]
    pub secondary_nm: f32,
    /// The filters' transmission away from their peaks, relative to the main peak, in [0, 1].
    #[arg(long, default_value_t = FilterDescription::IDEAL.floor, value_parser = |s: &str| within(s, 0.0, 1.0))]
    pub leak_floor: f32,
    /// Spread of each pixel's dark level about the black level, DN, in [0, 1000].
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| within(s, 0.0, 1000.0))]
    pub dark_sd: f32,
    /// Fraction of hot pixels (dark level 10-50 % of the range above black), in [0, 0.5].
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| within(s, 0.0, 0.5).map(f64::from))]
    pub hot_pixels: f64,
    /// Spread of each pixel's gain about 1 (PRNU), in [0, 0.5].
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| within(s, 0.0, 0.5))]
    pub prnu: f32,
    /// Light the corner view under the centre lenslet loses against the centre view, in
    /// [0, 0.95].
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| within(s, 0.0, 0.95))]
    pub vignetting: f32,
    /// Seed of the sensor's dark levels, gains and hot pixels (one sensor for every capture
    /// made with it).
    #[arg(long, default_value_t = SensorDescription::IDEAL.seed)]
    pub sensor_seed: u64,
}

impl SensorSettings {
    /// The sensor these flags describe.
    pub fn description(&self) -> SensorDescription {
        SensorDescription {
            filters: FilterDescription {
                leakage: self.leakage,
                width_nm: self.filter_width,
                secondary: self.secondary,
                secondary_nm: self.secondary_nm,
                floor: self.leak_floor,
            },
            dark_sd_dn: self.dark_sd,
            hot_fraction: self.hot_pixels,
            prnu: self.prnu,
            vignetting: self.vignetting,
            seed: self.sensor_seed,
        }
    }
}

/// A simulated capture and what a user should hear about it.
#[derive(Clone, Debug)]
pub struct Simulated {
    pub capture: Capture,
    /// Notes (bands resampled) and warnings (pixels saturated), one line each.
    pub notes: Vec<String>,
}

impl SensorSettings {
    /// Refuses the filters' shape without leakage: it shapes only the leaked light, so
    /// `--filter-width 200 --secondary 1` without `--leakage` once wrote an ideal capture.
    ///
    /// # Errors
    /// The shape flags given, and the flag they need.
    pub fn check(&self) -> Result<()> {
        let ideal = FilterDescription::IDEAL;
        let given: Vec<&str> = [
            (self.filter_width != ideal.width_nm, "--filter-width"),
            (self.secondary != ideal.secondary, "--secondary"),
            (self.secondary_nm != ideal.secondary_nm, "--secondary-nm"),
            (self.leak_floor != ideal.floor, "--leak-floor"),
        ]
        .into_iter()
        .filter_map(|(g, name)| g.then_some(name))
        .collect();
        anyhow::ensure!(
            self.leakage > 0.0 || given.is_empty(),
            "{} given without --leakage above 0: the filters' shape only shapes the leaked light (give --leakage, \
             e.g. 0.1)",
            given.join(", ")
        );
        Ok(())
    }
}

impl SimulateSettings {
    /// The camera these settings describe.
    pub fn camera(&self) -> CameraConfig {
        let mut cam =
            CameraConfig::pixel(self.seed, self.snapshots).with_mask(self.mask.mask(self.seed, self.snapshots));
        cam.read_noise = self.read_noise;
        cam.full_well = Some(self.full_well);
        cam.defect_fraction = self.defects;
        cam.frame_ext = self.format.extension().to_string();
        cam.sensor = self.sensor.description();
        cam.grid = self.grid.settings();
        if self.no_noise { cam.noiseless() } else { cam }
    }

    /// Records `lf` (named `source` in messages) with the camera.
    ///
    /// # Errors
    /// Wavelengths that do not parse or fit the light field; a light field the camera
    /// cannot record (see [`simulate`]).
    pub fn run(&self, lf: LightField, source: &str) -> Result<Simulated> {
        self.sensor.check()?;
        let (lf, note) = with_camera_bands(lf, self.wavelengths.as_deref(), source)?;
        // A capture the decoder could not take is refused here, not written for `decode`
        // to refuse.
        check_decodable(&lf, source)?;
        let cam = self.camera();
        let capture = simulate(&lf, &cam).with_context(|| source.to_string())?;
        let mut notes: Vec<String> = note.into_iter().collect();
        let negative = lf.data.iter().filter(|&&x| x < 0.0).count();
        if negative > 0 {
            let least = lf.data.iter().fold(0.0f32, |m, &x| m.min(x));
            notes.push(format!(
                "warning: {source}: {negative} of {} values below 0 (down to {least:.3}) recorded as no light",
                lf.data.len()
            ));
        }
        let (clipped, total) = capture.saturated_pixels()?;
        if clipped > 0 {
            let top = 1.0 / cam.white_fraction;
            // Who saturated them: the light field only when it exceeds white; else the
            // sensor's dark levels (--dark-sd 1000 once blamed the light field).
            let cause = if lf.max() > top {
                format!("the light field exceeds white (max {:.3}, clips at {top:.3})", lf.max())
            } else {
                format!(
                    "the light field stays below the clip ({:.3} of {top:.3}): the sensor's dark levels (--dark-sd, \
                     --hot-pixels) push them there",
                    lf.max()
                )
            };
            notes.push(format!(
                "warning: {source}: {clipped} of {total} pixels ({:.2} %) saturated: {cause}; saturated pixels are \
                 not measurements",
                100.0 * clipped as f64 / total as f64
            ));
        }
        Ok(Simulated { capture, notes })
    }
}

/// A finite number at or above zero, for clap.
fn non_negative(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number at or above 0")),
    }
}

/// A finite number in `[lo, hi]`, for clap.
fn within(s: &str, lo: f32, hi: f32) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && (lo..=hi).contains(&v) => Ok(v),
        _ => Err(format!("{s:?} is not a number in [{lo}, {hi}]")),
    }
}

/// A fraction in `[0, 1)`, for clap.
fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => Err(format!("{s:?} is not a fraction in [0, 1)")),
    }
}

impl FromFlags for SimulateSettings {
    const COMMAND: &'static str = "simulate";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_flags_is_the_commands_camera() {
        let s = SimulateSettings::from_flags(std::iter::empty::<&str>()).unwrap();
        let cam = s.camera();
        let mut want = CameraConfig::pixel(1, 1).with_mask(MaskDescription::seeded(MaskFamily::Pixel, 1, 1));
        want.read_noise = 2.0;
        want.full_well = Some(20_000.0);
        assert_eq!(cam, want);
        let s = SimulateSettings::from_flags(["--mask=lenslet", "-s", "3", "--seed=4", "--no-noise", "--format=npy"])
            .unwrap();
        let cam = s.camera();
        assert_eq!((cam.snapshots(), cam.frame_ext.as_str(), cam.read_noise), (3, "npy", 0.0));
        assert_eq!(cam.mask, MaskDescription::seeded(MaskFamily::Lenslet, 4, 3));
    }

    #[test]
    fn ranges_are_refused_in_one_line() {
        for (flag, says) in
            [("--read-noise=-1", "at or above 0"), ("--full-well=0", "above 0"), ("--defects=1", "[0, 1)")]
        {
            let e = SimulateSettings::from_flags([flag]).unwrap_err();
            assert!(e.contains(says) && e.contains(flag.split('=').next().unwrap()) && !e.contains('\n'), "{e}");
        }
    }
}
