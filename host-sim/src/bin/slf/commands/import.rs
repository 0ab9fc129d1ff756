//! `slf import`: real data in as the camera's 13 bands. Folders of RGB views, hyperspectral
//! cubes and light fields of other band counts, HDF5 light fields; written as a
//! `(U, V, H, W, 13)` light field `.npy`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Subcommand, ValueEnum};
use slf_host::io::import::bands::{CAMERA_FILTER, parse_wavelengths};
use slf_host::io::import::cube::{self, CubeConfig, Depth, Light};
use slf_host::io::import::hdf5::{Hdf5Layout, read_hdf5};
use slf_host::io::import::rgb::RgbLift;
use slf_host::io::import::views::{Fill, Naming, ViewsConfig, import_views};
use slf_host::io::import::{Crop, Geometry, resample_lightfield};
use slf_host::io::lightfield::{Dtype, LightField, read_npy, write_npy, write_npy_f32_2d};
use slf_host::sim::spectra_data::BAND_NM;

use crate::args::positive;

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub source: ImportSource,
}

pub fn run(args: Args) -> Result<()> {
    match args.source {
        ImportSource::Views {
            folder,
            output,
            pattern,
            index_base,
            grid,
            views,
            start,
            geometry,
            fill,
            linear,
            disparity,
            max_disparity,
        } => {
            let cfg = ViewsConfig {
                naming: pattern.map_or(Naming::Hci, Naming::Pattern),
                grid,
                index_base,
                views,
                start,
                geometry: geometry.geometry(),
                fill: if fill == FillArg::Warp { Fill::Warp } else { Fill::None },
                linear,
                disparity,
                max_disparity,
            };
            let lift = RgbLift::new(&BAND_NM, CAMERA_FILTER)?;
            let imported = import_views(&folder, &cfg, &lift)?;
            for n in &imported.notes {
                eprintln!("note: {}: {n}", folder.display());
            }
            write_npy(&output, &imported.lightfield, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), imported.lightfield.shape());
            if let Some(d) = imported.disparity {
                let p = disparity_path(&output);
                write_npy_f32_2d(&p, &d.data, d.rows, d.cols)?;
                println!("wrote {} (the centre view's disparity, pixels per view)", p.display());
            }
            Ok(())
        }
        ImportSource::Cube { input, output, wavelengths, white, light, views, disparity, disparity_map, geometry } => {
            let (data, notes) = if input.is_dir() {
                (cube::read_band_folder(&input)?, Vec::new())
            } else {
                cube::read_cube_npy(&input)?
            };
            for n in notes {
                eprintln!("note: {}: {n}", input.display());
            }
            let wl = match wavelengths {
                Some(w) => parse_wavelengths(&w)?,
                None if input.is_dir() && data.channels == 31 => parse_wavelengths("400:700:10")?,
                None => anyhow::bail!(
                    "{}: {} bands: give their wavelengths with --wavelengths (START:STOP:STEP or a list)",
                    input.display(),
                    data.channels
                ),
            };
            let light = if light == LightArg::Reflectance { Light::Reflectance } else { Light::Radiance };
            let bands = cube::to_camera_bands(&data, &wl, &BAND_NM, CAMERA_FILTER, white, light)
                .with_context(|| input.display().to_string())?;
            let cfg = CubeConfig {
                wavelengths: Some(wl),
                white,
                light,
                views,
                depth: match disparity_map {
                    Some(p) => Depth::Map(p),
                    None => Depth::Plane(disparity),
                },
                geometry: geometry.geometry(),
            };
            let (lf, map) = cube::to_lightfield(&bands, &cfg, (data.rows, data.cols))?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            if let Some(d) = map {
                let p = disparity_path(&output);
                write_npy_f32_2d(&p, &d.data, d.rows, d.cols)?;
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        ImportSource::Bands { input, output, wavelengths } => {
            let lf = with_camera_bands(read_npy(&input)?, Some(&wavelengths), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
        ImportSource::Hdf5 { input, output, dataset, axes, wavelengths, white } => {
            let lf = read_hdf5(&input, &Hdf5Layout { dataset, axes }, white)?;
            let lf = with_camera_bands(lf, wavelengths.as_deref(), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
    }
}

#[derive(Subcommand)]
pub enum ImportSource {
    /// A folder of RGB views (HCI benchmark naming, or --pattern), lifted to 13 bands by
    /// Mallett and Yuksel (2019) under D65.
    Views {
        /// The folder.
        folder: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// File names with {row} and {col} placeholders, zero-padded as {row:02}
        /// (default: the HCI benchmark's input_CamNNN.png, NNN = row * grid columns + col).
        #[arg(long)]
        pattern: Option<String>,
        /// The number of the first row and column in --pattern names (0 or 1, usually).
        #[arg(long, default_value_t = 0)]
        index_base: usize,
        /// The full view grid, ROWS,COLS.
        #[arg(long, value_parser = pair, default_value = "9,9")]
        grid: (usize, usize),
        /// The window of views read, U,V (the decoder needs at least 4,4).
        #[arg(long, value_parser = pair, default_value = "5,5")]
        views: (usize, usize),
        /// The window's first view ROW,COL in the grid (default: centred).
        #[arg(long, value_parser = pair)]
        start: Option<(usize, usize)>,
        #[command(flatten)]
        geometry: GeometryArgs,
        /// Missing views in the window.
        #[arg(long, value_enum, default_value_t = FillArg::None)]
        fill: FillArg,
        /// The files hold linear values (default: sRGB-encoded, as PNGs usually are).
        #[arg(long)]
        linear: bool,
        /// The centre view's disparity map, .pfm (default: gt_disp_lowres.pfm in an HCI
        /// folder). Cut and scaled with the views, written as OUTPUT's stem + .disparity.npy.
        #[arg(long)]
        disparity: Option<PathBuf>,
        /// Largest disparity (pixels per view) tried when estimating one to fill views.
        #[arg(long, default_value_t = 4.0, value_parser = positive)]
        max_disparity: f32,
    },
    /// A hyperspectral cube: a (H, W, B) .npy with --wavelengths, or a folder of band
    /// images (CAVE: NAME_ms_01.png .. NAME_ms_31.png, 400..=700 nm by 10 nm); views made
    /// by a disparity.
    Cube {
        /// The .npy or folder.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// Wavelengths of the cube's bands, START:STOP:STEP or a comma list, nm (default
        /// for a folder of 31 bands: 400:700:10).
        #[arg(long)]
        wavelengths: Option<String>,
        /// The value of a perfect white reflector (integer images read as fractions of
        /// their full scale).
        #[arg(long, default_value_t = 1.0, value_parser = positive)]
        white: f32,
        /// What the cube's values are.
        #[arg(long, value_enum, default_value_t = LightArg::Reflectance)]
        light: LightArg,
        /// Views U,V.
        #[arg(long, value_parser = pair, default_value = "5,5")]
        views: (usize, usize),
        /// A fronto-parallel plane at this disparity (pixels per view step).
        #[arg(long, default_value_t = 1.0, conflicts_with = "disparity_map")]
        disparity: f32,
        /// The centre view's disparity a pixel, .pfm of the cube's size (instead of a plane).
        #[arg(long)]
        disparity_map: Option<PathBuf>,
        #[command(flatten)]
        geometry: GeometryArgs,
    },
    /// A (U, V, H, W, B) light field .npy of any band count, resampled to the camera's 13
    /// bands over their filters.
    Bands {
        /// The light field .npy.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// Wavelengths of its bands, START:STOP:STEP or a comma list, nm.
        #[arg(long)]
        wavelengths: String,
    },
    /// A light field in an HDF5 file (read in pure Rust: no C library needed).
    Hdf5 {
        /// The .h5 file.
        input: PathBuf,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
        /// The dataset's path in the file, e.g. /lf/data.
        #[arg(long)]
        dataset: String,
        /// The dataset's axes, slowest first, as a permutation of u, v (views), h, w
        /// (space), b (bands), e.g. uvhwb or hwuvb.
        #[arg(long, default_value = "uvhwb")]
        axes: String,
        /// Wavelengths of its bands when it does not have the camera's 13 (START:STOP:STEP
        /// or a comma list, nm).
        #[arg(long)]
        wavelengths: Option<String>,
        /// The value of white (every value is divided by it).
        #[arg(long, default_value_t = 1.0, value_parser = positive)]
        white: f32,
    },
}

/// Where the spatial part of an import is cut and scaled.
#[derive(clap::Args, Clone, Debug)]
pub struct GeometryArgs {
    /// A window of the input, ROW,COL,ROWS,COLS in input pixels (default: all of it).
    #[arg(long, value_parser = crop)]
    crop: Option<Crop>,
    /// Size after the crop, ROWS,COLS (area-averaged when shrinking).
    #[arg(long, value_parser = pair)]
    resize: Option<(usize, usize)>,
}

impl GeometryArgs {
    fn geometry(&self) -> Geometry {
        Geometry { crop: self.crop, resize: self.resize }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FillArg {
    /// Refuse a window with missing views.
    None,
    /// Make a missing view from the nearest present one, moved by the disparity (the
    /// folder's published map, or one estimated from the present views).
    Warp,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightArg {
    /// The cube holds reflectance: lit by D65.
    Reflectance,
    /// The cube holds radiance relative to white already.
    Radiance,
}

/// A pair `A,B` of whole numbers, for clap.
fn pair(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once(',').ok_or_else(|| format!("{s:?} is not a pair A,B"))?;
    let num = |t: &str| t.trim().parse::<usize>().map_err(|_| format!("{t:?} in {s:?} is not a whole number"));
    Ok((num(a)?, num(b)?))
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

/// A light field with the camera's bands: as read if it has 13, resampled from
/// `wavelengths` otherwise.
pub fn with_camera_bands(lf: LightField, wavelengths: Option<&str>, input: &Path) -> Result<LightField> {
    match wavelengths {
        Some(w) => {
            let w = parse_wavelengths(w)?;
            let out =
                resample_lightfield(&lf, &w, &BAND_NM, CAMERA_FILTER).with_context(|| input.display().to_string())?;
            eprintln!("note: {}: {} bands resampled to the camera's 13", input.display(), lf.bands);
            Ok(out)
        }
        None if lf.bands != BAND_NM.len() => anyhow::bail!(
            "{}: {} bands; the camera has 13 (400..=700 nm by 25): give the light field's wavelengths with \
             --wavelengths to resample it",
            input.display(),
            lf.bands
        ),
        None => Ok(lf),
    }
}

/// The disparity file written beside an imported light field.
fn disparity_path(output: &Path) -> PathBuf {
    output.with_extension("disparity.npy")
}
