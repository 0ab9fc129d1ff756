//! Folders of RGB views: the HCI 4D light-field benchmark's layout and any layout with row
//! and column placeholders in the file name (Lytro-style `lf_RR_CC.png`).
//!
//! A `U x V` window of the view grid is read (by default the central 5 x 5), views are
//! decoded from sRGB to linear light (8- or 16-bit; `--linear` for files already linear),
//! cropped and resized ([`super::Geometry`]), and lifted to the camera's bands
//! ([`super::rgb`]).
//!
//! The HCI benchmark names view `(row, col)` of its 9 x 9 grid `input_CamNNN.png` with
//! `NNN = row * 9 + col`, and keeps the centre view's disparity in `gt_disp_lowres.pfm`
//! when it publishes it; that map is read, cut and scaled as the views are, and returned.
//!
//! A view missing from the window is refused, or with [`Fill::Warp`] made from the nearest
//! view present, moved by the disparity ([`super::parallax`]): the published map where
//! there is one, otherwise a plane sweep over the window's present views. The notes say
//! which views were made.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};

use super::parallax::{Disparity, estimate, warp};
use super::pfm::read_pfm;
use super::rgb::{RgbLift, srgb_to_linear};
use super::{Geometry, Plane, image_size, read_rgb};
use crate::io::lightfield::LightField;

/// How view files are named.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Naming {
    /// `input_CamNNN.png`, `NNN = row * grid columns + col`, three digits.
    Hci,
    /// A file name with `{row}` and `{col}` placeholders, optionally zero-padded as
    /// `{row:02}`; rows and columns count from [`ViewsConfig::index_base`].
    Pattern(String),
}

/// What to do with a view of the window that has no file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Refuse the import.
    None,
    /// Make it from the nearest present view, moved by the disparity.
    Warp,
}

/// Where and how to read a folder of views.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewsConfig {
    /// File naming.
    pub naming: Naming,
    /// The full view grid, `(rows, cols)`.
    pub grid: (usize, usize),
    /// The number of the first row and column in file names (pattern naming).
    pub index_base: usize,
    /// The window, `(U, V)` views.
    pub views: (usize, usize),
    /// The window's first view `(row, col)` in the grid; `None`: centred.
    pub start: Option<(usize, usize)>,
    /// Crop and resize.
    pub geometry: Geometry,
    /// Missing views.
    pub fill: Fill,
    /// The files hold linear values, not sRGB-encoded ones.
    pub linear: bool,
    /// A disparity map of the window's centre view (default: HCI's `gt_disp_lowres.pfm`
    /// in the folder, if there).
    pub disparity: Option<PathBuf>,
    /// Largest disparity the plane sweep tries, pixels per view step.
    pub max_disparity: f32,
}

impl Default for ViewsConfig {
    fn default() -> Self {
        Self {
            naming: Naming::Hci,
            grid: (9, 9),
            index_base: 0,
            views: (5, 5),
            start: None,
            geometry: Geometry::default(),
            fill: Fill::None,
            linear: false,
            disparity: None,
            max_disparity: 4.0,
        }
    }
}

/// The largest disparity the plane sweep that fills missing views tries, pixels per view
/// step: 8 times the largest of the HCI benchmark's scenes (about 4) and 32 times a lenslet
/// camera's; at 0.1-pixel steps, 641 candidates. A larger bound (1e9 asked for 17 GB of
/// candidates) is refused.
pub const MAX_DISPARITY: f32 = 32.0;

/// An imported light field, the disparity of its centre view if known, and what was done.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The light field, `(U, V, H, W, bands)`.
    pub lightfield: LightField,
    /// The centre view's disparity, cut and scaled as the views (pixels per view step).
    pub disparity: Option<Plane>,
    /// One line for each thing a user should know (filled views, estimated disparity).
    pub notes: Vec<String>,
}

/// The file name of grid view `(row, col)`.
pub fn view_name(cfg: &ViewsConfig, row: usize, col: usize) -> Result<String> {
    Ok(match &cfg.naming {
        Naming::Hci => format!("input_Cam{:03}.png", row * cfg.grid.1 + col),
        Naming::Pattern(p) => {
            let mut s = p.clone();
            for (key, index) in [("row", row), ("col", col)] {
                let Some(value) = index.checked_add(cfg.index_base) else {
                    bail!("pattern {p:?}: {key} {index} + index base {} is past the largest index", cfg.index_base);
                };
                let Some(open) = s.find(&format!("{{{key}")) else {
                    bail!("pattern {p:?} has no {{{key}}} placeholder");
                };
                let Some(len) = s[open..].find('}') else { bail!("pattern {p:?}: {{{key} is not closed") };
                let spec = &s[open + 1 + key.len()..open + len];
                let text = match spec.strip_prefix(":0") {
                    Some(w) => {
                        let width: usize =
                            w.parse().map_err(|_| anyhow::anyhow!("pattern {p:?}: width {w:?} is not a number"))?;
                        format!("{value:0width$}")
                    }
                    None if spec.is_empty() => value.to_string(),
                    None => bail!("pattern {p:?}: {{{key}{spec}}} is not {{{key}}} or {{{key}:0N}}"),
                };
                s.replace_range(open..open + len + 1, &text);
            }
            s
        }
    })
}

/// Reads one view as linear RGB, its size checked before it is decoded.
fn read_view(path: &Path, linear: bool) -> Result<Plane> {
    let mut view = read_rgb(path)?;
    if !linear {
        view.data.iter_mut().for_each(|v| *v = srgb_to_linear(*v));
    }
    Ok(view)
}

/// Imports the window of views `cfg` describes from `folder`, lifted to bands centred at
/// `centres_nm`.
pub fn import_views(folder: &Path, cfg: &ViewsConfig, lift: &RgbLift) -> Result<Imported> {
    ensure!(folder.is_dir(), "{}: not a folder", folder.display());
    ensure!(
        cfg.max_disparity.is_finite() && cfg.max_disparity > 0.0 && cfg.max_disparity <= MAX_DISPARITY,
        "--max-disparity {}: the plane sweep tries 0.1-pixel steps in 0 < d <= {MAX_DISPARITY} pixels per view",
        cfg.max_disparity
    );
    let (gr, gc) = cfg.grid;
    let (nu, nv) = cfg.views;
    ensure!((1..=64).contains(&gr) && (1..=64).contains(&gc), "grid {gr} x {gc}: each side must be in 1..=64");
    ensure!(nu >= 1 && nv >= 1 && nu <= gr && nv <= gc, "window {nu} x {nv} views does not fit the {gr} x {gc} grid");
    let (r0, c0) = cfg.start.unwrap_or(((gr - nu) / 2, (gc - nv) / 2));
    ensure!(
        r0 + nu <= gr && c0 + nv <= gc,
        "window rows {r0}..{}, columns {c0}..{} is outside the {gr} x {gc} grid",
        r0 + nu,
        c0 + nv
    );
    // Sizes before anything is decoded: the views held (three channels) and the light
    // field made, from the first present view's header.
    let names = (0..nu * nv).map(|i| Ok(folder.join(view_name(cfg, r0 + i / nv, c0 + i % nv)?)));
    let paths: Vec<PathBuf> = names.collect::<Result<_>>()?;
    let first_size = paths.iter().find(|p| p.exists()).map(|p| image_size(p)).transpose()?;
    if let Some((rows, cols)) = first_size {
        LightField::check_size((nu, nv), rows, cols, 3)
            .with_context(|| format!("{}: the views read", folder.display()))?;
        let (out_rows, out_cols) = cfg.geometry.output_size(rows, cols)?;
        LightField::check_size((nu, nv), out_rows, out_cols, lift.bands()).context("the imported light field")?;
    }
    let mut notes = Vec::new();
    let mut views: Vec<Option<Plane>> = Vec::with_capacity(nu * nv);
    let mut missing = Vec::new();
    for (i, path) in paths.into_iter().enumerate() {
        let (u, v) = (i / nv, i % nv);
        if path.exists() {
            // Each view's header against the first's before it is decoded.
            if let (Some((rows, cols)), (r, c)) = (first_size, image_size(&path)?) {
                ensure!((r, c) == (rows, cols), "{}: {c} x {r} pixels, other views {cols} x {rows}", path.display(),);
            }
            views.push(Some(read_view(&path, cfg.linear)?));
        } else {
            missing.push((u, v, path));
            views.push(None);
        }
    }
    let Some(first) = views.iter().flatten().next() else {
        bail!(
            "{}: none of the window's {} views is there (first: {})",
            folder.display(),
            nu * nv,
            missing[0].2.display()
        );
    };
    let (rows, cols) = (first.rows, first.cols);
    // The centre view's published disparity, if any.
    let disparity_path = cfg.disparity.clone().or_else(|| {
        let p = folder.join("gt_disp_lowres.pfm");
        (cfg.naming == Naming::Hci && p.is_file()).then_some(p)
    });
    let mut disparity = match &disparity_path {
        Some(p) => {
            let d = read_pfm(p)?;
            ensure!(
                (d.rows, d.cols) == (rows, cols),
                "{}: {} x {} disparities for {} x {} views",
                p.display(),
                d.cols,
                d.rows,
                cols,
                rows
            );
            Some(d)
        }
        None => None,
    };
    if !missing.is_empty() {
        if cfg.fill == Fill::None {
            bail!(
                "{} of {} views in the window are missing (first: {}); choose another window, or --fill warp",
                missing.len(),
                nu * nv,
                missing[0].2.display()
            );
        }
        let (cu, cv) = (nu / 2, nv / 2);
        let d = match disparity.take() {
            Some(d) => d,
            None => {
                let Some(reference) = &views[cu * nv + cv] else {
                    bail!("the window's centre view is missing: cannot estimate disparity to fill views");
                };
                let others: Vec<(f64, f64, &Plane)> = views
                    .iter()
                    .enumerate()
                    .filter(|(i, p)| p.is_some() && *i != cu * nv + cv)
                    .map(|(i, p)| ((i / nv) as f64 - cu as f64, (i % nv) as f64 - cv as f64, p.as_ref().unwrap()))
                    .collect();
                ensure!(!others.is_empty(), "only one view is present: cannot estimate disparity to fill views");
                let steps = (cfg.max_disparity / 0.1).round() as i32;
                let candidates: Vec<f32> = (-steps..=steps).map(|k| k as f32 * 0.1).collect();
                let d = estimate(reference, &others, &candidates, 3)?;
                notes.push(format!(
                    "disparity estimated by a plane sweep over {} present views ({} candidates in -{m}..={m} px)",
                    others.len() + 1,
                    candidates.len(),
                    m = cfg.max_disparity
                ));
                d
            }
        };
        let mut filled = Vec::new();
        for (u, v, _) in &missing {
            // The nearest present view (Euclidean in view steps; ties: the lower index).
            let (src, _) = views
                .iter()
                .enumerate()
                .filter(|(_, p)| p.is_some())
                .map(|(i, _)| (i, ((i / nv) as f64 - *u as f64).powi(2) + ((i % nv) as f64 - *v as f64).powi(2)))
                .fold((usize::MAX, f64::INFINITY), |b, (i, dist)| if dist < b.1 { (i, dist) } else { b });
            let (su, sv) = (src / nv, src % nv);
            let p = views[src].as_ref().expect("present");
            let w = warp(p, Disparity::Map(&d), *u as f64 - su as f64, *v as f64 - sv as f64)?;
            filled.push((u * nv + v, w));
            notes.push(format!(
                "view ({}, {}) of the grid was missing: made from view ({}, {}) moved by the disparity",
                r0 + u,
                c0 + v,
                r0 + su,
                c0 + sv
            ));
        }
        for (i, w) in filled {
            views[i] = Some(w);
        }
        disparity = Some(d);
    }
    let (out_rows, out_cols) = cfg.geometry.output_size(rows, cols)?;
    let bands = lift.bands();
    let mut lf = LightField::zeros((nu, nv), out_rows, out_cols, bands);
    let per_view = out_rows * out_cols * bands;
    for (i, view) in views.iter().enumerate() {
        let view = cfg.geometry.apply(view.as_ref().expect("every view present or filled"))?;
        let out = &mut lf.data[i * per_view..(i + 1) * per_view];
        for (px, o) in view.data.chunks_exact(3).zip(out.chunks_exact_mut(bands)) {
            lift.lift([px[0], px[1], px[2]], o);
        }
    }
    let disparity = disparity.map(|d| cfg.geometry.apply_disparity(&d)).transpose()?;
    Ok(Imported { lightfield: lf, disparity, notes })
}
