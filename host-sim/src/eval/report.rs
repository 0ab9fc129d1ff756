//! The reports of `slf demo`, `slf sweep` and `slf compare`: scenes simulated, decoded
//! and measured, printed as markdown tables (and written to a file when asked).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use slf_firmware::{ChoiceRule, MaskFamily, MemberChoice};

use crate::decode::baselines::Baseline;
use crate::decode::cs::{Basis, DecodeOptions, DecodeReport, PatchViews, decode_with};
use crate::eval::metrics::{Metrics, evaluate};
use crate::eval::preview::write_comparison;
use crate::io::capture::MaskDescription;
use crate::io::lightfield::{Dtype, LightField, write_npy};
use crate::io::output::write_bytes;
use crate::sim::camera::{CameraConfig, simulate};
use crate::sim::scene::{self, SceneSize};

fn row(scene: &str, family: &str, k: u8, m: &Metrics, seconds: f64) -> String {
    format!("| {scene} | {family} | {k} | {:.2} | {:.4} | {:.2} | {:.2} |", m.psnr, m.ssim, m.sa, seconds)
}

const HEADER: &str =
    "| scene | mask | k | PSNR dB | SSIM | SA deg | decode s |\n| --- | --- | --- | --- | --- | --- | --- |";

fn run_one(
    truth: &LightField,
    cam: &CameraConfig,
    basis: &Basis,
    views: Option<PatchViews>,
    progress: bool,
) -> Result<(LightField, Metrics, DecodeReport)> {
    let capture = simulate(truth, cam)?;
    let opts = DecodeOptions { progress, patch_views: views, ..DecodeOptions::default() };
    let (recon, report) = decode_with(&capture, basis, &opts)?;
    if report.failed_tiles > 0 || report.uncovered > 0 {
        bail!("decode lost {} tiles, {} values uncovered", report.failed_tiles, report.uncovered);
    }
    let metrics = evaluate(truth, &recon)?;
    Ok((recon, metrics, report))
}

/// `slf demo`: one named scene with the pixel mask at k = 1 and 3, decoded with `basis`;
/// the truth, reconstructions and previews go to `out`.
///
/// # Errors
/// An unknown scene, a failed decode, or a file that cannot be written.
pub fn demo(out: &Path, name: &str, size: usize, basis: &Basis, views: Option<PatchViews>) -> Result<()> {
    let start = Instant::now();
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let s = scene::named(name).with_context(|| format!("unknown scene {name:?}: one of {:?}", scene::NAMES))?;
    let truth = s.render(SceneSize { views: (5, 5), rows: size, cols: size });
    write_npy(&out.join("truth.npy"), &truth, Dtype::F32)?;
    outln!(
        "scene {name}: {size} x {size} lenslets, 5 x 5 views, 13 bands; pixel mask; {}; {} threads",
        basis.name(),
        rayon::current_num_threads()
    )?;
    outln!("{HEADER}")?;
    for k in [1u8, 3] {
        let cam = CameraConfig::pixel(7, k);
        let (recon, m, r) = run_one(&truth, &cam, basis, views, true)?;
        outln!("{}", row(name, "pixel", k, &m, r.seconds))?;
        write_npy(&out.join(format!("recon_k{k}.npy")), &recon, Dtype::F32)?;
        let label = format!("{}, pixel k = {k}", basis.name());
        write_comparison(&out.join(format!("preview_k{k}.png")), &truth, &recon, &label)?;
    }
    outln!("PSNR data range = max of ground truth ({:.4}).", truth.max())?;
    outln!(
        "previews (truth | reconstruction | error) in {}; total {:.1} s",
        out.display(),
        start.elapsed().as_secs_f64()
    )?;
    Ok(())
}

/// `slf sweep`: every named scene x mask family x k, decoded with `basis`.
///
/// # Errors
/// A failed decode or an unwritable `output`.
pub fn sweep(size: usize, ks: &[u8], output: Option<&Path>, basis: &Basis, views: Option<PatchViews>) -> Result<()> {
    let k_list: Vec<String> = ks.iter().map(u8::to_string).collect();
    let flags = match basis {
        Basis::Dct => "--dictionary dct".to_string(),
        Basis::Ensemble { choice, .. } => format!(
            "--dictionary ensemble --choice {}",
            match choice {
                slf_firmware::MemberChoice::Screened(_) => "screened",
                slf_firmware::MemberChoice::ScreenedResolve(_) => "screened-resolve",
                slf_firmware::MemberChoice::Exhaustive(_) => "exhaustive",
            }
        ),
    };
    let mut lines = vec![
        format!("# Quality with the {}: every test scene x mask family x k", basis.name()),
        String::new(),
        format!(
            "Produced by `cargo run --release -p slf-host -- sweep --size {size} --k {} {flags} -o FILE`: each \
             named scene at {size} x {size} lenslets x 5 x 5 views x 13 bands, the camera model's default sensor \
             (12 bits, black 64, white at 90 % of range, 20,000 e- full well, 2 DN read noise), seed 7, default \
             SL0, decoded with the {} by the firmware decoder on {} threads. PSNR's data range is the maximum of \
             each scene's ground truth; decode times are wall seconds per light field.",
            k_list.join(","),
            basis.name(),
            rayon::current_num_threads()
        ),
        String::new(),
        HEADER.to_string(),
    ];
    outln!("{HEADER}")?;
    for name in scene::NAMES {
        let truth =
            scene::named(name).context("named scene")?.render(SceneSize { views: (5, 5), rows: size, cols: size });
        for family in [MaskFamily::Pixel, MaskFamily::Lenslet, MaskFamily::Kronecker] {
            for &k in ks {
                let cam = CameraConfig::pixel(7, k).with_mask(MaskDescription::seeded(family, 7, k));
                let (_, m, r) = run_one(&truth, &cam, basis, views, false)?;
                let fam = format!("{family:?}").to_lowercase();
                let line = row(name, &fam, k, &m, r.seconds);
                outln!("{line}")?;
                lines.push(line);
            }
        }
    }
    if let Some(p) = output {
        write_bytes(p, (lines.join("\n") + "\n").as_bytes())?;
    }
    Ok(())
}

/// `slf compare`: the DCT against the ensemble (exhaustive and screened) and the baselines
/// without CS on every named scene, per mask family and k, with solves and time per patch.
///
/// # Errors
/// An unreadable blob, a failed decode or an unwritable `output`.
pub fn compare(
    size: usize,
    ks: &[u8],
    output: Option<&Path>,
    blob: Option<&Path>,
    masks: &[MaskFamily],
    rule: ChoiceRule,
    views: Option<PatchViews>,
) -> Result<()> {
    let blob = blob.map(crate::decode::cs::read_blob).transpose()?;
    let bases = [
        Basis::Dct,
        Basis::Ensemble { blob: blob.clone(), choice: MemberChoice::Exhaustive(rule) },
        Basis::Ensemble { blob, choice: MemberChoice::Screened(rule) },
    ];
    let truths: Vec<LightField> = scene::NAMES
        .iter()
        .map(|n| scene::named(n).map(|s| s.render(SceneSize { views: (5, 5), rows: size, cols: size })))
        .collect::<Option<_>>()
        .context("named scene")?;
    let mut lines = vec![
        format!("| basis | mask | k | PSNR dB | SSIM | SA deg | solves / patch | ms / patch (1 core) |"),
        "| --- | --- | --- | --- | --- | --- | --- | --- |".to_string(),
    ];
    for l in &lines {
        outln!("{l}")?;
    }
    let threads = rayon::current_num_threads() as f64;
    let families = if masks.is_empty() {
        vec![MaskFamily::Pixel, MaskFamily::Lenslet, MaskFamily::Kronecker]
    } else {
        masks.to_vec()
    };
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    for family in families {
        for &k in ks {
            let mut patches_per_field = 0.0;
            for basis in &bases {
                let cam = CameraConfig::pixel(7, k).with_mask(MaskDescription::seeded(family, 7, k));
                let (mut p, mut s, mut a, mut secs, mut solves, mut patches) = (0.0, 0.0, 0.0, 0.0, 0u64, 0u64);
                for truth in &truths {
                    let (_, m, r) = run_one(truth, &cam, basis, views, false)?;
                    p += m.psnr;
                    s += m.ssim;
                    a += m.sa;
                    secs += r.seconds;
                    solves += r.solves;
                    patches += u64::from(r.patches.decoded);
                }
                let n = truths.len() as f64;
                let line = format!(
                    "| {} | {} | {k} | {:.2} | {:.4} | {:.2} | {:.1} | {:.2} |",
                    basis.name(),
                    format!("{family:?}").to_lowercase(),
                    p / n,
                    s / n,
                    a / n,
                    solves as f64 / patches as f64,
                    1e3 * secs * threads / patches as f64
                );
                outln!("{line}")?;
                lines.push(line);
                patches_per_field = patches as f64 / n;
            }
            // The baselines, timed on one thread (their time per patch is per CS patch of
            // the same sensor, to compare).
            for baseline in Baseline::ALL {
                let cam = CameraConfig::pixel(7, k).with_mask(MaskDescription::seeded(family, 7, k));
                let (mut p, mut s, mut a, mut secs) = (0.0, 0.0, 0.0, 0.0);
                for truth in &truths {
                    let capture = simulate(truth, &cam)?;
                    let (recon, r) = one.install(|| baseline.run(&capture))?;
                    let m = evaluate(truth, &recon)?;
                    (p, s, a, secs) = (p + m.psnr, s + m.ssim, a + m.sa, secs + r.seconds);
                }
                let n = truths.len() as f64;
                let line = format!(
                    "| {} | {} | {k} | {:.2} | {:.4} | {:.2} | 0 | {:.3} |",
                    baseline.name(),
                    format!("{family:?}").to_lowercase(),
                    p / n,
                    s / n,
                    a / n,
                    1e3 * secs / n / patches_per_field.max(1.0)
                );
                outln!("{line}")?;
                lines.push(line);
            }
        }
    }
    if let Some(path) = output {
        write_bytes(path, (lines.join("\n") + "\n").as_bytes())?;
    }
    Ok(())
}
