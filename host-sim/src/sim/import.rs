//! Real data as the camera sees it: `slf import views` and `slf import cube`'s flags, in one
//! place for the command and the Python package (`slf.import_views`, `slf.import_cube`),
//! resolved with the camera's band centres and filters ([`BAND_NM`], [`CAMERA_FILTER`]).
//! The readers themselves are [`crate::io::import`]'s; this layer knows the camera.
//!
//! Each settings type parses the command's flags from strings ([`ViewsSettings::from_flags`],
//! [`CubeSettings::from_flags`]), so the package and the command share defaults, ranges and
//! one-line errors, and [`ViewsSettings::run`] / [`CubeSettings::run`] return the light field
//! without writing it.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow, bail, ensure};
use clap::{Args, ValueEnum};

use crate::io::import::bands::{CAMERA_FILTER, parse_wavelengths};
use crate::io::import::cube::{self, CubeConfig, Depth, Light};
use crate::io::import::rgb::RgbLift;
use crate::io::import::views::{Fill, Imported, MAX_DISPARITY, Naming, ViewsConfig, import_views};
use crate::io::import::{Crop, Geometry, resample_lightfield};
use crate::io::lightfield::LightField;
use crate::sim::flags::{FromFlags, pair, positive};
use crate::sim::spectra_data::BAND_NM;

/// Where the spatial part of an import is cut and scaled.
#[derive(Args, Clone, Debug)]
pub struct GeometrySettings {
    /// A window of the input, ROW,COL,ROWS,COLS in input pixels (default: all of it).
    #[arg(long, value_parser = crop)]
    pub crop: Option<Crop>,
    /// Size after the crop, ROWS,COLS (area-averaged when shrinking).
    #[arg(long, value_parser = pair)]
    pub resize: Option<(usize, usize)>,
}

impl GeometrySettings {
    /// The reader's geometry.
    pub fn geometry(&self) -> Geometry {
        Geometry { crop: self.crop, resize: self.resize }
    }
}

/// `--fill`: missing views in the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FillKind {
    /// Refuse a window with missing views.
    None,
    /// Make a missing view from the nearest present one, moved by the disparity (the
    /// folder's published map, or one estimated from the present views).
    Warp,
}

/// `--light`: what a cube's values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightKind {
    /// The cube holds reflectance: lit by D65.
    Reflectance,
    /// The cube holds radiance relative to white already.
    Radiance,
}

/// `slf import views`: a folder of RGB views, lifted to 13 bands.
#[derive(Args, Clone, Debug)]
pub struct ViewsSettings {
    /// The folder.
    pub folder: PathBuf,
    /// File names with {row} and {col} placeholders, zero-padded as {row:02}
    /// (default: the HCI benchmark's input_CamNNN.png, NNN = row * grid columns + col).
    #[arg(long)]
    pub pattern: Option<String>,
    /// The number of the first row and column in --pattern names (0 or 1, usually).
    #[arg(long, default_value_t = 0, requires = "pattern")]
    pub index_base: usize,
    /// The full view grid, ROWS,COLS.
    #[arg(long, value_parser = pair, default_value = "9,9")]
    pub grid: (usize, usize),
    /// The window of views read, U,V (the decoder needs at least 4,4).
    #[arg(long, value_parser = pair, default_value = "5,5")]
    pub views: (usize, usize),
    /// The window's first view ROW,COL in the grid (default: centred).
    #[arg(long, value_parser = pair)]
    pub start: Option<(usize, usize)>,
    #[command(flatten)]
    pub geometry: GeometrySettings,
    /// Missing views in the window.
    #[arg(long, value_enum, default_value_t = FillKind::None)]
    pub fill: FillKind,
    /// The files hold linear values (default: sRGB-encoded, as PNGs usually are).
    #[arg(long)]
    pub linear: bool,
    /// The centre view's disparity map, .pfm (default: gt_disp_lowres.pfm in an HCI
    /// folder). Cut and scaled with the views, written as OUTPUT's stem + .disparity.npy.
    #[arg(long)]
    pub disparity: Option<PathBuf>,
    /// Largest disparity (pixels per view) tried when estimating one to fill views, at most
    /// 32.
    #[arg(long, default_value_t = 4.0, value_parser = max_disparity)]
    pub max_disparity: f32,
}

/// `--max-disparity`: above 0, at most [`MAX_DISPARITY`].
fn max_disparity(s: &str) -> Result<f32, String> {
    let d = positive(s)?;
    if d > MAX_DISPARITY {
        return Err(format!("{s} pixels per view is more than the {MAX_DISPARITY} the plane sweep tries"));
    }
    Ok(d)
}

impl ViewsSettings {
    /// Reads the views: the light field `(U, V, H, W, 13)`, the centre view's disparity if
    /// the folder has one, and notes.
    ///
    /// # Errors
    /// What the reader refuses ([`import_views`]).
    pub fn run(&self) -> Result<Imported> {
        let cfg = ViewsConfig {
            naming: self.pattern.clone().map_or(Naming::Hci, Naming::Pattern),
            grid: self.grid,
            index_base: self.index_base,
            views: self.views,
            start: self.start,
            geometry: self.geometry.geometry(),
            fill: if self.fill == FillKind::Warp { Fill::Warp } else { Fill::None },
            linear: self.linear,
            disparity: self.disparity.clone(),
            max_disparity: self.max_disparity,
        };
        check_views(self.views)?;
        let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER)?;
        let imported = import_views(&self.folder, &cfg, &lift)?;
        check_lenslets(&imported.lightfield)?;
        Ok(imported)
    }
}

/// `slf import cube`: a hyperspectral cube, views made by a disparity.
#[derive(Args, Clone, Debug)]
pub struct CubeSettings {
    /// The .npy or folder.
    pub input: PathBuf,
    /// Wavelengths of the cube's bands, START:STOP:STEP or a comma list, nm (default
    /// for a folder of 31 bands: 400:700:10).
    #[arg(long)]
    pub wavelengths: Option<String>,
    /// The value of a perfect white reflector (integer images read as fractions of
    /// their full scale).
    #[arg(long, default_value_t = 1.0, value_parser = positive)]
    pub white: f32,
    /// What the cube's values are.
    #[arg(long, value_enum, default_value_t = LightKind::Reflectance)]
    pub light: LightKind,
    /// Views U,V.
    #[arg(long, value_parser = pair, default_value = "5,5")]
    pub views: (usize, usize),
    /// A fronto-parallel plane at this disparity (pixels per view step).
    #[arg(long, default_value_t = 1.0, conflicts_with = "disparity_map")]
    pub disparity: f32,
    /// The centre view's disparity a pixel, .pfm of the cube's size (instead of a plane).
    #[arg(long)]
    pub disparity_map: Option<PathBuf>,
    #[command(flatten)]
    pub geometry: GeometrySettings,
}

impl CubeSettings {
    /// Reads the cube and makes its views: the light field `(U, V, H, W, 13)`, the centre
    /// view's disparity map if one was given, and notes.
    ///
    /// # Errors
    /// What the readers refuse; a cube whose band count has no wavelengths.
    pub fn run(&self) -> Result<Imported> {
        check_views(self.views)?;
        let input = &self.input;
        let (data, notes) =
            if input.is_dir() { (cube::read_band_folder(input)?, Vec::new()) } else { cube::read_cube_npy(input)? };
        let wl = match &self.wavelengths {
            Some(w) => parse_wavelengths(w)?,
            None if input.is_dir() && data.channels == 31 => parse_wavelengths("400:700:10")?,
            None => bail!(
                "{}: {} bands: give their wavelengths with --wavelengths (START:STOP:STEP or a list)",
                input.display(),
                data.channels
            ),
        };
        let light = if self.light == LightKind::Reflectance { Light::Reflectance } else { Light::Radiance };
        let bands = cube::to_camera_bands(&data, &wl, &BAND_NM, CAMERA_FILTER, self.white, light)
            .with_context(|| input.display().to_string())?;
        let cfg = CubeConfig {
            wavelengths: Some(wl),
            white: self.white,
            light,
            views: self.views,
            depth: match &self.disparity_map {
                Some(p) => Depth::Map(p.clone()),
                None => Depth::Plane(self.disparity),
            },
            geometry: self.geometry.geometry(),
        };
        let (mut lightfield, disparity) = cube::to_lightfield(&bands, &cfg, (data.rows, data.cols))?;
        lightfield.check_finite().map_err(|e| {
            anyhow!(
                "{}: with --white {}: {e}: give the value of white in the cube's units",
                input.display(),
                crate::io::message::number(self.white)
            )
        })?;
        check_lenslets(&lightfield)?;
        // Measured reflectance dips below 0 where dark subtraction met noise; no surface
        // reflects less than nothing, and a light field below 0 is no light.
        let negative = lightfield.data.iter().filter(|&&x| x < 0.0).count();
        let mut notes = notes;
        if negative > 0 {
            let least = lightfield.data.iter().fold(0.0f32, |m, &x| m.min(x));
            lightfield.data.iter_mut().for_each(|x| *x = x.max(0.0));
            notes.push(format!(
                "{negative} of {} values below 0 (down to {least:.3}) set to 0: light is not negative",
                lightfield.data.len()
            ));
        }
        Ok(Imported { lightfield, disparity, notes })
    }
}

/// The fewest views a side the decoder takes: its patch's 4 x 4 angular window.
pub const MIN_VIEWS: usize = 4;
/// The fewest lenslets a side the decoder takes: its patch's 5 x 5.
pub const MIN_LENSLETS: usize = 5;

/// Refuses a window of views the decoder could not take, before anything is read.
fn check_views((u, v): (usize, usize)) -> Result<()> {
    ensure!(
        u >= MIN_VIEWS && v >= MIN_VIEWS,
        "--views {u},{v}: the decoder needs at least {MIN_VIEWS},{MIN_VIEWS} (its patch's angular window)"
    );
    Ok(())
}

/// Refuses an imported light field smaller than one patch, naming the size to ask for.
fn check_lenslets(lf: &LightField) -> Result<()> {
    ensure!(
        lf.rows >= MIN_LENSLETS && lf.cols >= MIN_LENSLETS,
        "the import is {} x {} pixels a view: the decoder needs at least {MIN_LENSLETS} x {MIN_LENSLETS} (its \
         patch's lenslets); --crop or --resize larger",
        lf.rows,
        lf.cols
    );
    Ok(())
}

/// Refuses a light field (named `source`) whose lenslets have fewer views, or which has
/// fewer lenslets, than the decoder's patch: what `simulate` and `evaluate` would otherwise
/// pass on for `decode` to refuse.
///
/// # Errors
/// The sizes and the minimum, one line.
pub fn check_decodable(lf: &LightField, source: &str) -> Result<()> {
    ensure!(
        lf.views.0 >= MIN_VIEWS && lf.views.1 >= MIN_VIEWS,
        "{source}: {} x {} views: the decoder needs lenslets of at least {MIN_VIEWS} x {MIN_VIEWS} views",
        lf.views.0,
        lf.views.1
    );
    ensure!(
        lf.rows >= MIN_LENSLETS && lf.cols >= MIN_LENSLETS,
        "{source}: {} x {} lenslets: the decoder needs at least {MIN_LENSLETS} x {MIN_LENSLETS} (its patch)",
        lf.rows,
        lf.cols
    );
    Ok(())
}

/// A light field with the camera's bands: as given if it has 13, resampled from
/// `wavelengths` otherwise; with a note when it was resampled. `source` names it in
/// messages.
///
/// # Errors
/// Wavelengths that do not parse or do not match the light field's bands; a band count
/// other than 13 without wavelengths.
pub fn with_camera_bands(
    lf: LightField,
    wavelengths: Option<&str>,
    source: &str,
) -> Result<(LightField, Option<String>)> {
    match wavelengths {
        Some(w) => {
            let w = parse_wavelengths(w)?;
            let out = resample_lightfield(&lf, &w, &BAND_NM, CAMERA_FILTER).with_context(|| source.to_string())?;
            Ok((out, Some(format!("note: {source}: {} bands resampled to the camera's 13", lf.bands))))
        }
        None if lf.bands != BAND_NM.len() => bail!(
            "{source}: {} bands; the camera has 13 (400..=700 nm by 25): give the light field's wavelengths with \
             --wavelengths to resample it",
            lf.bands
        ),
        None => Ok((lf, None)),
    }
}

/// A window `ROW,COL,ROWS,COLS`, for clap.
fn crop(s: &str) -> Result<Crop, String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>().map_err(|_| format!("{t:?} in {s:?} is not a whole number")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [row, col, rows, cols] => Ok(Crop { row, col, rows, cols }),
        _ => Err(format!("{s:?} is not ROW,COL,ROWS,COLS")),
    }
}

impl FromFlags for ViewsSettings {
    const COMMAND: &'static str = "views";
}

impl FromFlags for CubeSettings {
    const COMMAND: &'static str = "cube";
}
