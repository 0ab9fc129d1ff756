//! `slf evaluate`: every decode method a user could pick, on light fields they bring.
//!
//! For each light field (imported with `slf import`, or slf's own), each capture setting
//! (by default the camera's single shot, pixel mask k = 1; pixel k = 3; lenslet k = 3) and
//! each method (the three baselines without compressed sensing, the DCT and the shipped or
//! a given ensemble, screened, on disjoint patches, and the presets of `slf decode
//! --preset`): PSNR, SSIM, spectral angle and time per patch, per scene and as the mean
//! over scenes, as a markdown table. Every method decodes the same capture
//! (same mask, same noise).
//!
//! Times are on one thread for every method, per 5 x 5-lenslet patch of the sensor's
//! disjoint grid: the whole frame's time divided by that grid's patch count, for the
//! baselines (which have no patches) and for overlapping patches (which decode more), so
//! the column is a cost per frame and compares. Previews (truth, reconstruction, error) of a zoomed
//! central crop of each scene at the first setting go to the output folder.

use std::path::Path;

use anyhow::{Context, Result};
use slf_firmware::{ChoiceRule, MaskFamily, MemberChoice};

use crate::decode::baselines::Baseline;
use crate::decode::cs::{Basis, DecodeOptions, PatchViews, Window, decode_with, patch_count};
use crate::decode::preset::Preset;
use crate::eval::metrics::{Metrics, evaluate};
use crate::eval::preview::write_comparison;
use crate::io::capture::MaskDescription;
use crate::io::lightfield::LightField;
use crate::sim::camera::{CameraConfig, simulate};

/// A capture setting: mask family and snapshots.
pub type Setting = (MaskFamily, u8);

/// The default settings: the camera's single shot, three shots, and the lenslet mask.
pub const SETTINGS: [Setting; 3] = [(MaskFamily::Pixel, 1), (MaskFamily::Pixel, 3), (MaskFamily::Lenslet, 3)];

/// Side of the zoomed crop in the previews, lenslets.
const CROP: usize = 64;

/// One method's result on one scene and setting.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// The setting.
    pub setting: Setting,
    /// Method name.
    pub method: String,
    /// Quality.
    pub metrics: Metrics,
    /// Milliseconds per patch on one thread.
    pub ms_per_patch: f64,
}

/// A method: a baseline, or CS with a basis and decode options.
type Method = (String, Option<Baseline>, Option<(Basis, DecodeOptions)>);

/// The methods compared: the baselines, then CS with the DCT and with `blob` screened on
/// disjoint patches, both again at each of `strides`, then the presets (`blob` for the
/// ensemble's).
fn methods(blob: Option<&[u8]>, strides: &[(u8, u8)], window: Window, views: Option<PatchViews>) -> Vec<Method> {
    let mut m: Vec<Method> = Baseline::ALL.iter().map(|b| (b.name().to_string(), Some(*b), None)).collect();
    let bases = [
        Basis::Dct,
        Basis::Ensemble { blob: blob.map(<[u8]>::to_vec), choice: MemberChoice::Screened(ChoiceRule::DEFAULT) },
    ];
    for &stride in std::iter::once(&(5, 5)).chain(strides) {
        for basis in &bases {
            let name = if stride == (5, 5) {
                basis.name().to_string()
            } else {
                format!("{}, stride {}, {}", basis.name(), stride.0, format!("{window:?}").to_lowercase())
            };
            let opts = DecodeOptions { stride, window, patch_views: views, ..DecodeOptions::default() };
            m.push((name, None, Some((basis.clone(), opts))));
        }
    }
    for preset in Preset::ALL {
        let opts = DecodeOptions { patch_views: views, ..preset.options() };
        m.push((format!("preset {}", preset.name()), None, Some((preset.basis_with(blob), opts))));
    }
    m
}

/// A central `CROP x CROP` window of every view (the whole field if smaller).
fn central_crop(lf: &LightField) -> LightField {
    let (r, c) = (lf.rows.min(CROP), lf.cols.min(CROP));
    lf.window((lf.rows - r) / 2, (lf.cols - c) / 2, r, c)
}

/// A file-name-safe version of a method's name.
fn slug(s: &str) -> String {
    let s: String = s.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
    s.split('-').filter(|p| !p.is_empty()).collect::<Vec<_>>().join("-")
}

/// Runs every method on every scene and setting; writes `table.md` and previews to `out`.
///
/// # Errors
/// A failed simulation or decode, or a file that cannot be written.
pub fn evaluate_set(
    scenes: &[(String, LightField)],
    settings: &[Setting],
    blob: Option<&[u8]>,
    strides: &[(u8, u8)],
    window: Window,
    views: Option<PatchViews>,
    out: &Path,
) -> Result<Vec<Row>> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let threads = rayon::current_num_threads() as f64;
    let mut rows = Vec::new();
    for (si, &(family, k)) in settings.iter().enumerate() {
        let cam = CameraConfig::pixel(7, k).with_mask(MaskDescription::seeded(family, 7, k));
        for (name, truth) in scenes {
            let capture = simulate(truth, &cam).with_context(|| name.clone())?;
            // Times are per patch of the paper's shape (a 4 x 4-view window), one unit for
            // every method and patch.
            let patches = patch_count(&capture, PatchViews::Four)? as f64;
            for (method, baseline, basis) in methods(blob, strides, window, views) {
                let (recon, ms) = match (baseline, &basis) {
                    (Some(b), _) => {
                        let (recon, r) = one.install(|| b.run(&capture))?;
                        (recon, 1e3 * r.seconds / patches)
                    }
                    (None, Some((basis, opts))) => {
                        let opts = DecodeOptions { progress: false, ..*opts };
                        let (recon, r) = decode_with(&capture, basis, &opts)?;
                        anyhow::ensure!(r.failed_tiles == 0 && r.uncovered == 0, "{name}: {method} lost tiles");
                        (recon, 1e3 * r.seconds * threads / patches)
                    }
                    _ => unreachable!("a method is a baseline or a basis"),
                };
                let metrics = evaluate(truth, &recon)?;
                outln!(
                    "{name} {family:?} k={k} {method}: {:.2} dB, SSIM {:.4}, SA {:.2} deg, {:.3} ms/patch",
                    metrics.psnr,
                    metrics.ssim,
                    metrics.sa,
                    ms
                )?;
                if si == 0 {
                    let p = out.join(format!("{}_{}.png", slug(name), slug(&method)));
                    let label = format!("{method}, {} k = {k}", format!("{family:?}").to_lowercase());
                    write_comparison(&p, &central_crop(truth), &central_crop(&recon), &label)?;
                }
                rows.push(Row { scene: name.clone(), setting: (family, k), method, metrics, ms_per_patch: ms });
            }
        }
    }
    Ok(rows)
}

/// The table: per setting, each scene's rows then the mean over scenes of each method.
pub fn table(rows: &[Row], settings: &[Setting]) -> String {
    let mut lines = vec![
        "| scene | mask | k | method | PSNR dB | SSIM | SA deg | ms / patch (1 core) |".to_string(),
        "| --- | --- | --- | --- | --- | --- | --- | --- |".to_string(),
    ];
    for &(family, k) in settings {
        let here: Vec<&Row> = rows.iter().filter(|r| r.setting == (family, k)).collect();
        let fam = format!("{family:?}").to_lowercase();
        for r in &here {
            lines.push(format!(
                "| {} | {fam} | {k} | {} | {:.2} | {:.4} | {:.2} | {:.3} |",
                r.scene, r.method, r.metrics.psnr, r.metrics.ssim, r.metrics.sa, r.ms_per_patch
            ));
        }
        let mut names: Vec<&str> = Vec::new();
        for r in &here {
            if !names.contains(&r.method.as_str()) {
                names.push(&r.method);
            }
        }
        for m in names {
            let of: Vec<&&Row> = here.iter().filter(|r| r.method == m).collect();
            let n = of.len() as f64;
            let mean = |f: &dyn Fn(&Row) -> f64| of.iter().map(|r| f(r)).sum::<f64>() / n;
            lines.push(format!(
                "| **mean** | {fam} | {k} | {m} | **{:.2}** | {:.4} | {:.2} | {:.3} |",
                mean(&|r| r.metrics.psnr),
                mean(&|r| r.metrics.ssim),
                mean(&|r| r.metrics.sa),
                mean(&|r| r.ms_per_patch)
            ));
        }
    }
    lines.join("\n") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The methods: the baselines, the DCT and the ensemble on disjoint patches, both again
    /// per extra stride, then the presets as `slf decode --preset` runs them.
    #[test]
    fn methods_are_the_baselines_the_bases_per_stride_and_the_presets() {
        let names = |strides: &[(u8, u8)]| -> Vec<String> {
            methods(None, strides, Window::Tapered, None).into_iter().map(|m| m.0).collect()
        };
        let plain = names(&[]);
        assert_eq!(plain.len(), Baseline::ALL.len() + 2 + Preset::ALL.len());
        assert_eq!(&plain[plain.len() - 3..], ["preset preview", "preset default", "preset best"]);
        let strided = names(&[(3, 3)]);
        assert_eq!(strided.len(), plain.len() + 2);
        assert!(strided.contains(&"DCT, stride 3, tapered".to_string()), "{strided:?}");
        assert!(strided.contains(&"ensemble screened, stride 3, tapered".to_string()), "{strided:?}");
        // The presets' options are the presets'.
        let all = methods(None, &[], Window::Tapered, None);
        let (_, _, Some((basis, opts))) = &all[all.len() - 3] else { panic!("the preview is a CS method") };
        assert!(matches!(basis, Basis::Dct));
        assert_eq!(opts.stride, Preset::Preview.options().stride);
        assert!(!opts.edge_fallback);
        let (_, _, Some((_, best))) = &all[all.len() - 1] else { panic!("best is a CS method") };
        assert_eq!(best.stride, Preset::Best.options().stride);
    }
}
