//! `slf import`: real data in as the camera's 13 bands. Folders of RGB views, hyperspectral
//! cubes and light fields of other band counts, HDF5 light fields; written as a
//! `(U, V, H, W, 13)` light field `.npy`.

use slf_host::outln;
use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Subcommand;
use slf_host::io::import::hdf5::{Hdf5Layout, read_hdf5};
use slf_host::io::import::views::Imported;
use slf_host::io::lightfield::{Dtype, LightField, read_npy, write_npy, write_npy_f32_2d};
use slf_host::io::output::Outputs;
use slf_host::sim::import::{CubeSettings, ViewsSettings, with_camera_bands};

use crate::args::positive;

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub source: ImportSource,
}

pub fn run(args: Args) -> Result<()> {
    args.source.outputs().check()?;
    match args.source {
        ImportSource::Views { settings, output } => {
            let imported = settings.run()?;
            write_imported(&imported, &settings.folder, &output, " (the centre view's disparity, pixels per view)")
        }
        ImportSource::Cube { settings, output } => {
            let imported = settings.run()?;
            write_imported(&imported, &settings.input, &output, "")
        }
        ImportSource::Bands { input, output, wavelengths } => {
            let lf = camera_bands(read_npy(&input)?, Some(&wavelengths), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            outln!("wrote {} ({:?})", output.display(), lf.shape())?;
            Ok(())
        }
        ImportSource::Hdf5 { input, output, dataset, axes, wavelengths, white } => {
            let lf = read_hdf5(&input, &Hdf5Layout { dataset, axes }, white)?;
            let lf = camera_bands(lf, wavelengths.as_deref(), &input)?;
            write_npy(&output, &lf, Dtype::F32)?;
            outln!("wrote {} ({:?})", output.display(), lf.shape())?;
            Ok(())
        }
    }
}

#[derive(Subcommand)]
pub enum ImportSource {
    /// A folder of RGB views (HCI benchmark naming, or --pattern), lifted to 13 bands by
    /// Mallett and Yuksel (2019) under D65.
    Views {
        #[command(flatten)]
        settings: ViewsSettings,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// A hyperspectral cube: a (H, W, B) .npy with --wavelengths, or a folder of band
    /// images (CAVE: NAME_ms_01.png .. NAME_ms_31.png, 400..=700 nm by 10 nm); views made
    /// by a disparity.
    Cube {
        #[command(flatten)]
        settings: CubeSettings,
        /// Output light field .npy (U, V, H, W, 13).
        #[arg(short, long)]
        output: PathBuf,
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

/// Writes an imported light field, its notes on stderr and its disparity beside it.
impl ImportSource {
    /// What the import reads (a folder's files, one input file) and writes (the light field
    /// and, for views, its disparity map), to check against each other before the work.
    fn outputs(&self) -> Outputs {
        let (inputs, output, disparity): (Vec<PathBuf>, &Path, bool) = match self {
            Self::Views { settings, output } => {
                let files = std::fs::read_dir(&settings.folder)
                    .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                    .unwrap_or_default();
                (files, output, true)
            }
            Self::Cube { settings, output } => (vec![settings.input.clone()], output, false),
            Self::Bands { input, output, .. } | Self::Hdf5 { input, output, .. } => {
                (vec![input.clone()], output, false)
            }
        };
        let o = Outputs::new().inputs(inputs, "an input").output(output, "-o");
        if disparity { o.output(&disparity_path(output), "the disparity map beside -o") } else { o }
    }
}

fn write_imported(imported: &Imported, input: &Path, output: &Path, what: &str) -> Result<()> {
    for n in &imported.notes {
        eprintln!("note: {}: {n}", input.display());
    }
    write_npy(output, &imported.lightfield, Dtype::F32)?;
    outln!("wrote {} ({:?})", output.display(), imported.lightfield.shape())?;
    if let Some(d) = &imported.disparity {
        let p = disparity_path(output);
        write_npy_f32_2d(&p, &d.data, d.rows, d.cols)?;
        outln!("wrote {}{what}", p.display())?;
    }
    Ok(())
}

/// A light field with the camera's bands ([`with_camera_bands`]), its note on stderr.
pub fn camera_bands(lf: LightField, wavelengths: Option<&str>, input: &Path) -> Result<LightField> {
    let (lf, note) = with_camera_bands(lf, wavelengths, &input.display().to_string())?;
    if let Some(n) = note {
        eprintln!("{n}");
    }
    Ok(lf)
}

/// The disparity file written beside an imported light field.
fn disparity_path(output: &Path) -> PathBuf {
    output.with_extension("disparity.npy")
}
