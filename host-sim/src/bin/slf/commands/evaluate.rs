//! `slf evaluate`: every baseline, the DCT and the ensemble on the given light fields at
//! pixel k = 1, 3 and lenslet k = 3: PSNR / SSIM / SA and ms per patch, per scene and mean
//! (`table.md`), and previews of a zoomed crop at pixel k = 1.

use slf_host::outln;
use std::path::PathBuf;

use anyhow::Result;
use slf_host::decode::cs::{PatchViews, read_blob};
use slf_host::decode::settings::patch_views;
use slf_host::eval::evaluation::{SETTINGS, evaluate_set, table};
use slf_host::io::lightfield::read_npy;

use crate::args::ranged;
use slf_host::decode::settings::WindowKind;
use slf_host::sim::import::check_decodable;
use slf_host::sim::scene::MIN_SCENE;

#[derive(clap::Args)]
pub struct Args {
    /// Light fields, (U, V, H, W, 13) .npy; each is named by its file stem.
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// Output folder (table.md and previews).
    #[arg(short, long, default_value = "slf-evaluate")]
    pub out: PathBuf,
    /// Ensemble blob (default: the shipped one).
    #[arg(long)]
    pub blob: Option<PathBuf>,
    /// Also decode with overlapping patches at these strides (1..=4 lenslets), as
    /// extra rows for the DCT and the ensemble (default: none; the presets' rows hold the
    /// default decode at stride 3 and the best at stride 2).
    #[arg(long, value_delimiter = ',', value_parser = ranged::<1, 4>)]
    pub stride: Vec<usize>,
    /// How overlapping patches are averaged in those rows.
    #[arg(long, value_enum, default_value_t = WindowKind::Tapered)]
    pub window: WindowKind,
    /// Views per axis of every CS row's patch, 4 or 5 [default: the decode's, 5 for 5 x
    /// 5-view lenslets; a --blob's own].
    #[arg(long, value_parser = patch_views, value_name = "4|5")]
    pub patch_views: Option<PatchViews>,
}

pub fn run(args: Args) -> Result<()> {
    let Args { inputs, out, blob, stride, window, patch_views } = args;
    slf_host::io::output::Outputs::new()
        .inputs(&inputs, "an input")
        .inputs(&blob, "--blob")
        .output(&out.join("table.md"), "the table in -o")
        .check_distinct()?;
    let blob = blob.map(|p| read_blob(&p)).transpose()?;
    let mut scenes: Vec<(String, _)> = Vec::new();
    for (i, p) in inputs.iter().enumerate() {
        let name = p.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        // Rows and previews are named by the file's stem: two of one name would share them.
        if let Some(j) = scenes.iter().position(|(n, _)| *n == name) {
            anyhow::bail!(
                "{} and {} are both named {name:?} (rows and previews are named by the file's stem): rename one",
                inputs[j].display(),
                inputs[i].display()
            );
        }
        let lf = read_npy(p)?;
        // What the decodes and metrics need, named with the file before any work.
        anyhow::ensure!(
            lf.bands == 13,
            "{}: {} bands, the camera's are 13: resample it first with slf import bands {} --wavelengths ... -o OUT",
            p.display(),
            lf.bands,
            p.display()
        );
        check_decodable(&lf, &p.display().to_string())?;
        anyhow::ensure!(
            lf.rows >= MIN_SCENE && lf.cols >= MIN_SCENE,
            "{}: {} x {} lenslets: the metrics need at least {MIN_SCENE} x {MIN_SCENE} (SSIM's window)",
            p.display(),
            lf.rows,
            lf.cols
        );
        scenes.push((name, lf));
    }
    let strides: Vec<(u8, u8)> = stride.iter().map(|&s| (s as u8, s as u8)).collect();
    let rows = evaluate_set(&scenes, &SETTINGS, blob.as_deref(), &strides, window.window(), patch_views, &out)?;
    let t = table(&rows, &SETTINGS);
    let path = out.join("table.md");
    slf_host::io::output::write_bytes(&path, t.as_bytes())?;
    outln!("{t}wrote {}", path.display())?;
    Ok(())
}
