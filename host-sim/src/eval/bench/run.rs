//! The sweep: its settings (one factor at a time around the default), each decoded over
//! the scenes and timed on one thread and on all; and the paper-scale run.

use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use slf_firmware::{ChoiceRule, DisparityRange, MaskFamily, MemberChoice, Sl0Config};

use super::mark_pareto;
use super::model::F64Dct;
use super::{Point, frame_patches, short};
use crate::decode::baselines::Baseline;
use crate::decode::cs::{Basis, DecodeOptions, NoiseSource, PatchViews, Window, decode, decode_with, patch_count};
use crate::decode::preset::Preset;
use crate::eval::metrics::evaluate;
use crate::io::capture::MaskDescription;
use crate::io::lightfield::LightField;
use crate::sim::camera::{CameraConfig, simulate};
use crate::sim::scene::{self, SceneSize};

/// What is being decoded with.
#[derive(Clone, Debug)]
enum Decoder {
    Basis(Basis),
    F64,
    /// A method without compressed sensing; its time is per CS patch of the same capture.
    Baseline(Baseline),
}

/// Sweep size.
#[derive(Clone, Debug, Default)]
pub struct BenchOptions {
    /// Small scenes, two of them, k = 3 only, no exhaustive choice: CI-sized.
    pub quick: bool,
    pub progress: bool,
    /// Only the settings whose name contains this.
    pub only: Option<String>,
    /// The mask families (empty: all three).
    pub masks: Vec<MaskFamily>,
}

/// The sweep's points: a name, a decoder, and how it decodes. The solver's settings are
/// measured as the solver sees them: disjoint patches, the projection exactly as
/// configured (exact unless the point sets a noise level); the decode's own defaults (the
/// capture's noise model, overlapping patches) are points of their own.
fn settings(quick: bool) -> Vec<(String, Decoder, DecodeOptions)> {
    let solver = |sl0: Sl0Config| DecodeOptions {
        sl0,
        noise: NoiseSource::Config,
        stride: (5, 5),
        window: Window::Uniform,
        disparities: Some(DisparityRange::OFF),
        ..DecodeOptions::default()
    };
    let unsheared = |stride: u8, window: Window, adaptive: Option<f32>| DecodeOptions {
        stride: (stride, stride),
        window,
        adaptive,
        disparities: Some(DisparityRange::OFF),
        ..DecodeOptions::default()
    };
    let decode = |stride: u8, window: Window, adaptive: Option<f32>| DecodeOptions {
        disparities: Some(DisparityRange::DEFAULT),
        ..unsheared(stride, window, adaptive)
    };
    let halves = DisparityRange::DEFAULT.with_halves(true);
    let d = Sl0Config::DEFAULT;
    let dct = || Decoder::Basis(Basis::Dct);
    let ens = |choice| Decoder::Basis(Basis::Ensemble { blob: None, choice });
    let screened = || ens(MemberChoice::Screened(ChoiceRule::DEFAULT));
    let mut s = vec![
        ("DCT default".to_string(), dct(), d),
        ("DCT f64 reference".to_string(), Decoder::F64, d),
        ("DCT sigma_f 0.5".to_string(), dct(), Sl0Config { sigma_f: 0.5, ..d }),
        ("DCT sigma_f 0.85".to_string(), dct(), Sl0Config { sigma_f: 0.85, ..d }),
        ("DCT L 2".to_string(), dct(), Sl0Config { steps: 2, ..d }),
        ("DCT sigma_min 1e-2".to_string(), dct(), Sl0Config { sigma_min: 1e-2, ..d }),
        ("DCT sigma_min 3e-4".to_string(), dct(), Sl0Config { sigma_min: 3e-4, ..d }),
        ("DCT read noise only (2 DN)".to_string(), dct(), Sl0Config { noise: 2.0 / 3628.0, ..d }),
        ("ensemble screened".to_string(), screened(), d),
    ];
    // What a user would pick instead of CS: the baselines, in every run.
    s.extend(Baseline::ALL.map(|m| (m.name().to_string(), Decoder::Baseline(m), d)));
    // Where the decode's own points go in the list.
    let decode_points_at = s.len();
    // Modelling only what a patch needs: the early stop, the flat short path, and the
    // ensemble's warm start (default 1e-2) against a cold second solve. The quick run keeps
    // one point of each.
    let (tolerances, flats, warms): (&[f32], &[f32], &[f32]) =
        if quick { (&[1e-3], &[4e-3], &[1.0]) } else { (&[1e-3, 3e-4], &[1e-3, 4e-3], &[1.0, 3e-3]) };
    for &tolerance in tolerances {
        s.push((format!("DCT tolerance {tolerance:e}"), dct(), Sl0Config { tolerance, ..d }));
    }
    for &flat in flats {
        s.push((format!("DCT flat {flat:e}"), dct(), Sl0Config { flat, ..d }));
    }
    // The warm solves on the main schedule (the default before they had their own).
    let main_schedule = Sl0Config { warm_sigma_f: d.sigma_f, warm_steps: d.steps, ..d };
    for &warm_start in warms {
        let name = if warm_start == 1.0 {
            "ensemble screened cold".to_string()
        } else {
            format!("ensemble screened warm {warm_start:e}")
        };
        // A cold second solve is a first solve again: the main schedule too.
        let base = if warm_start == 1.0 { main_schedule } else { d };
        s.push((name, screened(), Sl0Config { warm_start, ..base }));
    }
    s.push((format!("ensemble screened, warm sigma_f {} L {}", d.sigma_f, d.steps), screened(), main_schedule));
    // A DCT win solved again instead of averaged (the default before the mean).
    s.push((
        "ensemble screened, DCT wins re-solved".to_string(),
        ens(MemberChoice::ScreenedResolve(ChoiceRule::DEFAULT)),
        d,
    ));
    s.push((
        "ensemble screened, tolerance 1e-3, flat 4e-3".to_string(),
        screened(),
        Sl0Config { tolerance: 1e-3, flat: 4e-3, ..d },
    ));
    if !quick {
        s.push(("ensemble exhaustive".to_string(), ens(MemberChoice::Exhaustive(ChoiceRule::DEFAULT)), d));
    }
    let mut points: Vec<(String, Decoder, DecodeOptions)> =
        s.into_iter().map(|(name, dec, sl0)| (name, dec, solver(sl0))).collect();
    // The decode's defaults: the capture's noise model, then overlapping patches (the
    // default stride 3 with the tapered window, and stride 2), and the adaptive rule.
    let mut decode_points = vec![
        ("ensemble screened, noise model".to_string(), screened(), unsheared(5, Window::Uniform, None)),
        (
            "ensemble screened, noise model, stride 3 tapered, unsheared".to_string(),
            screened(),
            unsheared(3, Window::Tapered, None),
        ),
        (
            "ensemble screened, noise model, stride 3 tapered, disparities -1:1 (the default's search at k > 1 off the lenslet mask)".to_string(),
            screened(),
            decode(3, Window::Tapered, None),
        ),
        (
            "ensemble screened, noise model, stride 2 tapered, disparities -1:1".to_string(),
            screened(),
            decode(2, Window::Tapered, None),
        ),
    ];
    if !quick {
        decode_points.push((
            "ensemble screened, noise model, stride 2 tapered, unsheared".to_string(),
            screened(),
            unsheared(2, Window::Tapered, None),
        ));
        decode_points.push((
            "DCT, noise model, stride 3 tapered, unsheared".to_string(),
            dct(),
            unsheared(3, Window::Tapered, None),
        ));
        decode_points.push((
            "DCT, noise model, stride 3 tapered, disparities -1:1".to_string(),
            dct(),
            decode(3, Window::Tapered, None),
        ));
        decode_points.push((
            "DCT, noise model, stride 3 tapered, disparities -1:1:0.5".to_string(),
            dct(),
            DecodeOptions { disparities: Some(halves), ..decode(3, Window::Tapered, None) },
        ));
        decode_points.push((
            "ensemble screened, noise model, stride 3 tapered, disparities -1:1:0.5 (the default's search at k = 1 and on the lenslet mask)".to_string(),
            screened(),
            DecodeOptions { disparities: Some(halves), ..decode(3, Window::Tapered, None) },
        ));
        decode_points.push((
            "ensemble screened, noise model, stride 3 adaptive 1.2, unsheared".to_string(),
            screened(),
            unsheared(3, Window::Tapered, Some(1.2)),
        ));
    }
    // The presets, as `slf decode --preset` runs them (the best only in the full sweep).
    let presets = || Preset::ALL.into_iter().filter(|&p| !quick || p != Preset::Best);
    decode_points.extend(presets().map(|p| (format!("preset {}", p.name()), Decoder::Basis(p.basis()), p.options())));
    // Each preset with the paper's patch (4 x 4 views in four angular windows) beside it:
    // the presets before the full-view patch (issue 40).
    decode_points.extend(presets().map(|p| {
        let opts = DecodeOptions { patch_views: Some(PatchViews::Four), ..p.options() };
        (format!("preset {} (4-view patch)", p.name()), Decoder::Basis(p.basis()), opts)
    }));
    points.splice(decode_points_at..decode_points_at, decode_points);
    points
}

fn run_decoder(
    capture: &crate::io::capture::Capture,
    dec: &Decoder,
    opts: &DecodeOptions,
) -> Result<(LightField, crate::decode::cs::DecodeReport)> {
    match dec {
        Decoder::Basis(b) => decode_with(capture, b, opts),
        Decoder::F64 => match opts.patch_views_for(capture, &Basis::Dct)? {
            PatchViews::Four => decode::<4, 4, 5200, _>(capture, &F64Dct::<4, 4, 5200>::default(), opts),
            PatchViews::Five => decode::<5, 5, 8125, _>(capture, &F64Dct::<5, 5, 8125>::default(), opts),
        },
        Decoder::Baseline(m) => {
            let (lf, _) = m.run(capture)?;
            let mut report = crate::decode::cs::DecodeReport::default();
            report.patches.decoded = u32::try_from(patch_count(capture, PatchViews::Four)?).unwrap_or(u32::MAX);
            Ok((lf, report))
        }
    }
}

/// Runs the sweep.
///
/// # Errors
/// A decode or thread-pool failure.
pub fn run(opts: &BenchOptions) -> Result<Vec<Point>> {
    let (size, names, ks): (usize, &[&str], &[u8]) =
        if opts.quick { (20, &["texture", "depth"], &[3]) } else { (40, &scene::NAMES, &[1, 3]) };
    let truths: Vec<LightField> = names
        .iter()
        .map(|n| scene::named(n).map(|s| s.render(SceneSize { views: (5, 5), rows: size, cols: size })))
        .collect::<Option<_>>()
        .context("named scene")?;
    let mut settings = settings(opts.quick);
    if let Some(only) = &opts.only {
        let names: Vec<String> = settings.iter().map(|(name, _, _)| short(name).to_string()).collect();
        settings.retain(|(name, _, _)| name.contains(only.as_str()));
        anyhow::ensure!(
            !settings.is_empty(),
            "--only {only:?} names no setting of the {} sweep (a part of a name, such as {:?})",
            if opts.quick { "quick" } else { "full" },
            names.iter().take(4).collect::<Vec<_>>()
        );
    }
    let families = if opts.masks.is_empty() {
        vec![MaskFamily::Pixel, MaskFamily::Lenslet, MaskFamily::Kronecker]
    } else {
        opts.masks.clone()
    };
    let total = (families.len() * ks.len() * settings.len() * truths.len()) as u64;
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
    if opts.progress {
        bar.set_draw_target(ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("bench {bar:40} {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().context("one-thread pool")?;
    let mut points = Vec::new();
    for &family in &families {
        for &k in ks {
            let captures: Vec<_> = truths
                .iter()
                .map(|t| simulate(t, &CameraConfig::pixel(7, k).with_mask(MaskDescription::seeded(family, 7, k))))
                .collect::<Result<_>>()?;
            for (name, dec, opts) in &settings {
                let family_name = format!("{family:?}").to_lowercase();
                bar.set_message(format!("{family_name} k={k} {name}"));
                let (mut p, mut s, mut a, mut t1, mut ta, mut solves, mut patches, mut frame) =
                    (0.0, 0.0, 0.0, 0.0, 0.0, 0u64, 0u64, 0.0);
                for (truth, capture) in truths.iter().zip(&captures) {
                    let start = Instant::now();
                    let (recon, report) = one.install(|| run_decoder(capture, dec, opts))?;
                    t1 += start.elapsed().as_secs_f64();
                    let start = Instant::now();
                    run_decoder(capture, dec, opts)?;
                    ta += start.elapsed().as_secs_f64();
                    let m = evaluate(truth, &recon)?;
                    (p, s, a) = (p + m.psnr, s + m.ssim, a + m.sa);
                    solves += report.solves;
                    // Per patch of the disjoint grid: a frame's cost, also for overlapping
                    // patches (which decode more of them) and baselines (which have none).
                    // (Patches of the paper's shape, 4 x 4 views: one unit for both shapes.)
                    let n = patch_count(capture, PatchViews::Four)?;
                    patches += n;
                    // The same capture's angular windows at the frame's size.
                    let blocks =
                        (capture.description.lenslets[0] as u64 / 5) * (capture.description.lenslets[1] as u64 / 5);
                    frame += frame_patches(n / blocks.max(1)) as f64;
                    bar.inc(1);
                }
                let n = truths.len() as f64;
                let np = patches.max(1) as f64;
                points.push(Point {
                    mask: family_name,
                    k,
                    setting: name.clone(),
                    psnr: p / n,
                    ssim: s / n,
                    sa: a / n,
                    ms_one: 1e3 * t1 / np,
                    ms_all: 1e3 * ta / np,
                    solves: solves as f64 / np,
                    frame_s: 1e-3 * (1e3 * t1 / np) * frame / n,
                    pareto: false,
                });
            }
        }
    }
    bar.finish_and_clear();
    mark_pareto(&mut points);
    Ok(points)
}

/// CPU seconds (user + system) this process has used, from `/proc/self/stat`.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line; after the name, field 3 (the state
    // letter) is index 0, so they are indices 11 and 12.
    let num = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    let ticks = num(11) + num(12);
    ticks / 100.0 // USER_HZ, 100 on Linux
}

/// Peak resident memory in bytes, from `/proc/self/status` (VmHWM).
fn peak_rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next().and_then(|k| k.parse::<u64>().ok()))
        .map_or(0, |kb| kb * 1024)
}

/// The paper's scale end to end: a 512 x 512 x 5 x 5 x 13 light field (the depth scene),
/// one snapshot of the pixel mask, decoded with the shipped ensemble (screened) on every
/// thread. Returns a markdown report beside the paper's figure.
///
/// # Errors
/// A simulation or decode failure.
pub fn paper_scale() -> Result<String> {
    let threads = rayon::current_num_threads();
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let truth = scene::named("depth").context("scene")?.render(SceneSize { views: (5, 5), rows: 512, cols: 512 });
    let t_render = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let capture = simulate(&truth, &CameraConfig::pixel(7, 1))?;
    let t_sim = t1.elapsed().as_secs_f64();
    let (c1, t2) = (cpu_seconds(), Instant::now());
    let opts = DecodeOptions { progress: true, ..DecodeOptions::default() };
    let (recon, report) = decode_with(&capture, &Basis::default_ensemble(), &opts)?;
    let (t_dec, c_dec) = (t2.elapsed().as_secs_f64(), cpu_seconds() - c1);
    let p = crate::eval::metrics::psnr(&truth.data, &recon.data, f64::from(truth.max()));
    let sa = crate::eval::metrics::spectral_angle(&truth, &recon);
    let total = t0.elapsed().as_secs_f64();
    let patches = report.patches.decoded;
    Ok(format!(
        "| | slf (this machine) | paper (5D AMDE) |\n| --- | --- | --- |\n\
         | light field | 512 x 512 x 5 x 5 x 13, depth scene, pixel mask, k = 1 | 512 x 512 x 5 x 5 x 13, k = 1 |\n\
         | decode wall time | {t_dec:.1} s on {threads} thread{} | 79.5 s on 16 cores |\n\
         | decode core-seconds | {c_dec:.1} | 1,272 (79.5 x 16) |\n\
         | patches decoded | {patches} ({:.2} ms core time each, {:.1} solves each) | |\n\
         | end to end (render {t_render:.1} s, simulate {t_sim:.1} s, decode) | {total:.1} s, {:.1} core-seconds | |\n\
         | peak memory (resident) | {:.2} GB | |\n\
         | PSNR (data range = max of truth) / SA | {p:.2} dB / {sa:.2} deg | |\n",
        if threads == 1 { "" } else { "s" },
        1e3 * c_dec / f64::from(patches.max(1)),
        report.solves as f64 / f64::from(patches.max(1)),
        cpu_seconds() - c0,
        peak_rss() as f64 / 1e9
    ))
}
