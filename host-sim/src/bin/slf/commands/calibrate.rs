//! `slf calibrate`: a sensor's calibration from its calibration captures (dark frames,
//! flats, a band sweep or measured filter curves), written as a calibration folder that
//! `slf decode --calibration` reads (`docs/capture-format.md`, "Calibration").

use std::path::PathBuf;

use anyhow::{Context, Result, ensure};
use slf_host::decode::calibrate::calibrate;
use slf_host::io::calibration::{DARK, DESCRIPTION, FLAT};
use slf_host::io::capture::Capture;
use slf_host::io::npy::{self, Element, Values};
use slf_host::io::output::Outputs;

#[derive(clap::Args)]
pub struct Args {
    /// Calibration capture folders (their `light`: dark, flat or a band); a folder holding
    /// only such folders (as `slf simulate --calibration-captures` writes) stands for them.
    #[arg(required = true)]
    pub captures: Vec<PathBuf>,
    /// Calibration folder to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Measured filter curves instead of a band sweep: a float .npy of shape (filters,
    /// bands), what a pixel behind each filter records of each band relative to light of
    /// equal energy in every band.
    #[arg(long)]
    pub response: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    let Args { captures, output, response } = args;
    // A folder of capture folders stands for its captures, in name order.
    let mut folders = Vec::new();
    for dir in &captures {
        if dir.join("capture.json").is_file() {
            folders.push(dir.clone());
        } else {
            let mut inner: Vec<PathBuf> = std::fs::read_dir(dir)
                .with_context(|| format!("{}: neither a capture folder nor a folder of them", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.join("capture.json").is_file())
                .collect();
            ensure!(!inner.is_empty(), "{}: holds no capture folder", dir.display());
            inner.sort();
            folders.extend(inner);
        }
    }
    let loaded: Vec<(String, Capture)> =
        folders.iter().map(|p| Capture::load(p).map(|c| (p.display().to_string(), c))).collect::<Result<_>>()?;
    let curves = match &response {
        Some(path) => {
            let bands = loaded.first().map_or(0, |(_, c)| c.description.bands_nm.len());
            let a = npy::read_checked(path, |s, element| {
                if s != [bands, bands] {
                    return Err(format!("is {s:?}: filter curves are (filters, bands) = ({bands}, {bands})"));
                }
                if element == Element::U16 {
                    return Err("holds uint16: filter curves are floats".into());
                }
                Ok(())
            })
            .map_err(|e| anyhow::anyhow!("{e}"))?;
            let Values::F32(v) = a.values else { anyhow::bail!("{}: filter curves are floats", path.display()) };
            Some(v.chunks(bands).map(<[f32]>::to_vec).collect())
        }
        None => None,
    };
    let mut inputs = Outputs::new();
    for (_, c) in &loaded {
        inputs = inputs.inputs(c.files(), "a calibration capture's file");
    }
    if let Some(path) = &response {
        inputs = inputs.input(path, "the filter curves");
    }
    inputs
        .outputs([output.join(DESCRIPTION), output.join(DARK), output.join(FLAT)], "a file of the calibration -o")
        .check_distinct()?;
    let (calibration, report) = calibrate(&loaded, curves)?;
    for line in &report.lines {
        eprintln!("{line}");
    }
    calibration.save(&output)?;
    println!("wrote {}", output.display());
    Ok(())
}
