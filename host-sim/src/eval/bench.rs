//! Speed against error: `slf bench`.
//!
//! For each mask family and k, a one-factor-at-a-time sweep around the default solver:
//! `sigma_f`, `L`, `sigma_min`, the noise-aware stop, the basis (DCT, ensemble exhaustive,
//! ensemble screened) and the precision (the f32 decoder against an f64 reference that
//! runs through the same tile pipeline). Every point records PSNR / SSIM / SA (mean over the
//! scenes) and time per patch on one thread and on all threads. Output: a CSV, a markdown
//! table with the Pareto front (per mask family: no other point is both faster and better)
//! marked, and a PNG plot of PSNR against time per patch, one curve per mask family, on
//! which the presets (`slf decode --preset`) and the baselines are labelled by name.
//!
//! Each point also gives a frame figure: the seconds a 512 x 512-pixel-per-view frame
//! (the paper's scale, 5 x 5 views) takes on one core at that point's time per patch of
//! the disjoint grid; with the device's counts ([`crate::eval::device_frame`]) the table
//! also gives the projected seconds of a 100 x 100-lenslet frame on the device.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use plotters::prelude::*;
use slf_firmware::{
    ChoiceRule, Dictionary, DisparityRange, Ended, MaskFamily, MemberChoice, ModelOutcome, Outcome, PatchModel,
    Sl0Config, SolveError, Workspace,
};

use crate::decode::baselines::Baseline;
use crate::decode::cs::{Basis, DecodeOptions, NoiseSource, PatchViews, Window, decode, decode_with, patch_count};
use crate::decode::paper_1d::{Factors, analyze_5d, solve_5d, solve_5d_seeded};
use crate::decode::preset::Preset;
use crate::eval::device_frame::{self, DeviceFrame};
use crate::eval::metrics::evaluate;
use crate::io::capture::MaskDescription;
use crate::io::capture::regular_file;
use crate::io::lightfield::LightField;
use crate::io::output::write_bytes;
use crate::sim::camera::{CameraConfig, simulate};
use crate::sim::scene::{self, SceneSize};

/// The f64 reference: SL0 with the DCT in f64 (the host's 5D reference), written back
/// through the workspace so it runs in the same tile pipeline as the f32 decoder; for
/// `5 x 5 x PU x PV x 13` patches.
pub struct F64Dct<const PU: usize, const PV: usize> {
    factors: Factors<f64>,
    /// The f32 DCT tables widened to f64, for writing the result back through them.
    widened: Factors<f64>,
    dict: Dictionary<5, 5, PU, PV, 13>,
}

impl<const PU: usize, const PV: usize> Default for F64Dct<PU, PV> {
    fn default() -> Self {
        let dict = Dictionary::dct();
        Self { factors: Factors::dct_f64_of([5, 5, PU, PV, 13]), widened: Factors::from_dictionary(&dict), dict }
    }
}

impl<const PU: usize, const PV: usize, const N: usize> PatchModel<5, 5, PU, PV, 13, N> for F64Dct<PU, PV> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<5, 5, PU, PV, 13, N>) -> Result<ModelOutcome, SolveError> {
        cfg.validate()?;
        let m = ws.measurements();
        if m.count() == 0 {
            return Err(SolveError::NoMeasurements);
        }
        let meas: Vec<Option<f64>> = (0..N).map(|i| m.get(i).map(f64::from)).collect();
        let (x, iterations) = solve_5d::<f64>(&self.factors, &meas, cfg);
        Ok(self.write_back(&x, iterations, ws))
    }

    fn decode_seeded(
        &self,
        cfg: &Sl0Config,
        ws: &mut Workspace<5, 5, PU, PV, 13, N>,
    ) -> Result<ModelOutcome, SolveError> {
        cfg.validate()?;
        let m = ws.measurements();
        if m.count() == 0 {
            return Err(SolveError::NoMeasurements);
        }
        let meas: Vec<Option<f64>> = (0..N).map(|i| m.get(i).map(f64::from)).collect();
        let start: Vec<f64> = ws.patch().iter().map(|&x| f64::from(x)).collect();
        let (x, iterations) = solve_5d_seeded::<f64>(&self.factors, &meas, &start, cfg);
        Ok(self.write_back(&x, iterations, ws))
    }
}

impl<const PU: usize, const PV: usize> F64Dct<PU, PV> {
    /// Writes the f64 patch `x` back: its DCT coefficients (f64 analysis with the f32
    /// tables), then one f32 synthesis (rounding ~1e-7, far below the f32-vs-f64
    /// differences).
    fn write_back<const N: usize>(
        &self,
        x: &[f64],
        iterations: u32,
        ws: &mut Workspace<5, 5, PU, PV, 13, N>,
    ) -> ModelOutcome {
        let s = analyze_5d(&self.widened, x);
        for (dst, v) in ws.coefficients_mut().iter_mut().zip(&s) {
            *dst = *v as f32;
        }
        ws.synthesize(&self.dict);
        let outcome = Outcome { iterations, levels: 0, sigma0: 0.0, residual: 0.0, ended: Ended::SigmaMin };
        ModelOutcome { outcome, member: None, solves: 1 }
    }
}

/// What is being decoded with.
#[derive(Clone, Debug)]
enum Decoder {
    Basis(Basis),
    F64,
    /// A method without compressed sensing; its time is per CS patch of the same capture.
    Baseline(Baseline),
}

/// One point of the sweep.
#[derive(Clone, Debug)]
pub struct Point {
    pub mask: String,
    pub k: u8,
    pub setting: String,
    pub psnr: f64,
    pub ssim: f64,
    pub sa: f64,
    /// Milliseconds per patch of the disjoint grid (a frame's cost over its disjoint
    /// patches) on one thread.
    pub ms_one: f64,
    /// Milliseconds of wall time per patch of the disjoint grid on all threads.
    pub ms_all: f64,
    /// Solves per patch of the disjoint grid.
    pub solves: f64,
    /// Seconds for a [`FRAME_LENSLETS`]-square frame (5 x 5 views) on one thread, at
    /// [`Self::ms_one`] per patch of its disjoint grid.
    pub frame_s: f64,
    pub pareto: bool,
}

/// Lenslets per side of the frame figure: 512 x 512 pixels per view, the paper's scale.
pub const FRAME_LENSLETS: u64 = 512;

/// Patches of the disjoint grid of a [`FRAME_LENSLETS`]-square frame with `windows`
/// angular windows: the decoder's 5 x 5-lenslet blocks that fit, as [`patch_count`] counts
/// them.
pub fn frame_patches(windows: u64) -> u64 {
    (FRAME_LENSLETS / 5).pow(2) * windows
}

/// The name a point is labelled with on the plot: a preset's or a baseline's; other
/// points are the sweep around them and stay unlabelled.
pub fn label(setting: &str) -> Option<&str> {
    setting.strip_prefix("preset ").or_else(|| Baseline::ALL.iter().map(|b| b.name()).find(|&n| n == setting))
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
            PatchViews::Four => decode::<4, 4, 5200, _>(capture, &F64Dct::<4, 4>::default(), opts),
            PatchViews::Five => decode::<5, 5, 8125, _>(capture, &F64Dct::<5, 5>::default(), opts),
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

/// A label as the plot prints it: a baseline without its "baseline: " and its reference
/// ("PPID", not "baseline: PPID (Mihoubi et al. 2017)"); the colour names the series.
fn short(label: &str) -> &str {
    let name = label.strip_prefix("baseline: ").unwrap_or(label);
    name.split(" (").next().unwrap_or(name)
}

/// Marks, per mask family and k, the points no other point beats in both time (one
/// thread) and PSNR.
pub fn mark_pareto(points: &mut [Point]) {
    let snapshot = points.to_vec();
    for p in points.iter_mut() {
        p.pareto = !snapshot.iter().any(|q| {
            q.mask == p.mask
                && q.k == p.k
                && q.ms_one <= p.ms_one
                && q.psnr >= p.psnr
                && (q.ms_one < p.ms_one || q.psnr > p.psnr)
        });
    }
}

/// Writes `bench.csv`, `bench.md` and `bench.png` into `dir`; `bench.md` ends with the
/// device's frame figure when `device` holds any rows. All three are made in memory first,
/// so a point the plot refuses writes no file.
///
/// # Errors
/// I/O and drawing errors.
pub fn write(points: &[Point], device: &[DeviceFrame], dir: &Path) -> Result<()> {
    anyhow::ensure!(!points.is_empty(), "no points to write");
    let csv = csv_of(points)?;
    let (md, png) = (markdown(points, device), plot(points)?);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_bytes(&dir.join("bench.csv"), &csv)?;
    write_bytes(&dir.join("bench.md"), md.as_bytes())?;
    write_bytes(&dir.join("bench.png"), &png)
}

/// Draws `bench.md` and `bench.png` into `dir` again from the `bench.csv` at `from` (with
/// the device's figure, say) without sweeping again, and returns the points. `dir`'s
/// `bench.csv` becomes a copy of `from`, byte for byte: when it is `from` itself it is
/// left as it is (before, it was written again at the table's rounding).
///
/// # Errors
/// As [`read_points`] and [`write()`].
pub fn redraw(from: &Path, device: &[DeviceFrame], dir: &Path) -> Result<usize> {
    regular_file(from, 16 << 20, "a bench table holds")?;
    let bytes = std::fs::read(from).with_context(|| format!("cannot read {}", from.display()))?;
    let points = points_of(csv::Reader::from_reader(&bytes[..])).with_context(|| from.display().to_string())?;
    let (md, png) = (markdown(&points, device), plot(&points)?);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let target = dir.join("bench.csv");
    let same = matches!((std::fs::canonicalize(from), std::fs::canonicalize(&target)), (Ok(a), Ok(b)) if a == b);
    if !same {
        write_bytes(&target, &bytes)?;
    }
    write_bytes(&dir.join("bench.md"), md.as_bytes())?;
    write_bytes(&dir.join("bench.png"), &png)?;
    Ok(points.len())
}

/// The points as `bench.csv`'s bytes.
fn csv_of(points: &[Point]) -> Result<Vec<u8>> {
    // Setting names hold commas ("ensemble screened, tolerance 1e-3, ..."): the csv crate
    // quotes them.
    let mut csv = csv::Writer::from_writer(Vec::new());
    csv.write_record([
        "mask",
        "k",
        "setting",
        "psnr_db",
        "ssim",
        "sa_deg",
        "ms_per_patch_1_thread",
        "ms_per_patch_all_threads",
        "solves_per_patch",
        "frame_512_s_1_thread",
        "pareto",
    ])?;
    for p in points {
        csv.write_record([
            p.mask.clone(),
            p.k.to_string(),
            p.setting.clone(),
            format!("{:.4}", p.psnr),
            format!("{:.5}", p.ssim),
            format!("{:.4}", p.sa),
            format!("{:.4}", p.ms_one),
            format!("{:.4}", p.ms_all),
            format!("{:.2}", p.solves),
            format!("{:.2}", p.frame_s),
            p.pareto.to_string(),
        ])?;
    }
    csv.into_inner().context("csv buffer")
}

/// The points as `bench.md`, with the device's figure after the table when there is one.
fn markdown(points: &[Point], device: &[DeviceFrame]) -> String {
    let mut md = String::from(
        "| mask | k | setting | PSNR dB | SSIM | SA deg | ms / patch (1 thread) | ms / patch (all) | solves | 512 x 512 frame, s (1 thread) | Pareto |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for p in points {
        md += &format!(
            "| {} | {} | {} | {:.2} | {:.4} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {} |\n",
            p.mask,
            p.k,
            p.setting,
            p.psnr,
            p.ssim,
            p.sa,
            p.ms_one,
            p.ms_all,
            p.solves,
            p.frame_s,
            if p.pareto { "yes" } else { "" }
        );
    }
    if !device.is_empty() {
        md += &device_frame::markdown(device);
    }
    md
}

/// The points of a `bench.csv` that [`write()`] wrote, to draw its table and plot again
/// (with the device's figure, say) without sweeping again. Values are as the CSV rounds
/// them (four decimals).
///
/// # Errors
/// A file that cannot be read, is not a regular file or is larger than 16 MiB, or has a
/// row that is not a point (its line is named).
pub fn read_points(path: &Path) -> Result<Vec<Point>> {
    regular_file(path, 16 << 20, "a bench table holds")?;
    let r = csv::Reader::from_path(path).with_context(|| format!("cannot read {}", path.display()))?;
    points_of(r).with_context(|| path.display().to_string())
}

/// The rows of a `bench.csv` reader as points; a fault names its line.
fn points_of<R: std::io::Read>(mut r: csv::Reader<R>) -> Result<Vec<Point>> {
    let mut points = Vec::new();
    for (i, row) in r.records().enumerate() {
        let line = i + 2;
        let row = row.with_context(|| format!("line {line}"))?;
        let at = |j: usize| row.get(j).with_context(|| format!("line {line}: {} fields", row.len()));
        let number = |j: usize| -> Result<f64> {
            let x = at(j)?;
            x.parse().with_context(|| format!("line {line}: field {} {x:?} is not a number", j + 1))
        };
        // What the plot and the Pareto front need: finite values in the range a decode can
        // give (a PSNR of 1.7e308 or a time of 1e-200 ms once held the plot's axes for
        // minutes), a time above zero.
        let within = |j: usize, what: &str, (lo, hi): (f64, f64)| -> Result<f64> {
            let x = number(j)?;
            anyhow::ensure!(x.is_finite(), "line {line}: field {} is {x}, not a finite number", j + 1);
            let show =
                |v: f64| if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() };
            anyhow::ensure!(
                (lo..=hi).contains(&x),
                "line {line}: field {} is {what} of {}, outside [{}, {}]",
                j + 1,
                show(x),
                show(lo),
                show(hi)
            );
            Ok(x)
        };
        let time = |j: usize| -> Result<f64> {
            let x = number(j)?;
            anyhow::ensure!(x.is_finite() && x > 0.0, "line {line}: field {} is a time of {x} ms, not above 0", j + 1);
            within(j, "a time in ms", TIME_MS)
        };
        points.push(Point {
            mask: at(0)?.to_owned(),
            k: at(1)?.parse().with_context(|| format!("line {line}: k"))?,
            setting: at(2)?.to_owned(),
            psnr: within(3, "a PSNR in dB", PSNR_DB)?,
            ssim: within(4, "an SSIM", (-1.0, 1.0))?,
            sa: within(5, "a spectral angle in degrees", (0.0, 180.0))?,
            ms_one: time(6)?,
            ms_all: time(7)?,
            solves: within(8, "a count of solves", (0.0, 1e9))?,
            frame_s: within(9, "a time in s", (0.0, 1e15))?,
            pareto: at(10)? == "true",
        });
    }
    anyhow::ensure!(!points.is_empty(), "no points (a header and no rows)");
    Ok(points)
}

/// The PSNRs a bench table may hold, in dB: a plot's axis spans them in bounded time.
const PSNR_DB: (f64, f64) = (-1000.0, 1000.0);
/// The times per patch a bench table may hold, in ms: 1 ps to 11 days, 21 decades on the
/// plot's log axis.
const TIME_MS: (f64, f64) = (1e-9, 1e12);

/// The plot as PNG bytes.
fn plot(points: &[Point]) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let (width, height) = (1000u32, 700u32);
    let mut raw = vec![0u8; 3 * (width * height) as usize];
    draw(points, BitMapBackend::with_buffer(&mut raw, (width, height)))?;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png).write_image(&raw, width, height, image::ExtendedColorType::Rgb8)?;
    Ok(png)
}

fn draw(points: &[Point], backend: BitMapBackend<'_>) -> Result<()> {
    // A point that cannot be placed (a time of 0 on the log axis, a PSNR of NaN from a
    // decode that failed, values no decode gives) is in the table, not on the plot; the
    // axes span the others.
    let inside = |x: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&x);
    let points: Vec<Point> =
        points.iter().filter(|p| inside(p.ms_one, TIME_MS) && inside(p.psnr, PSNR_DB)).cloned().collect();
    anyhow::ensure!(!points.is_empty(), "no point with a time above 0 and a finite PSNR to plot");
    let points = &points[..];
    let root = backend.into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (tmin, tmax) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.ms_one), b.max(p.ms_one)));
    let (pmin, pmax) =
        points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.psnr), b.max(p.psnr)));
    let mut chart = ChartBuilder::on(&root)
        .caption("PSNR against time per patch (one thread); Pareto fronts joined", ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d((tmin * 0.8..tmax * 1.2).log_scale(), (pmin - 1.0)..(pmax + 1.0))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("ms per patch (one thread, log scale)")
        .y_desc("PSNR dB (mean over scenes)")
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    let mut series: Vec<(String, u8)> = points.iter().map(|p| (p.mask.clone(), p.k)).collect();
    series.dedup();
    for (i, (mask, k)) in series.iter().enumerate() {
        let c = colours[i % colours.len()];
        let pts: Vec<&Point> = points.iter().filter(|p| &p.mask == mask && p.k == *k).collect();
        chart
            .draw_series(pts.iter().map(|p| Circle::new((p.ms_one, p.psnr), 4, c.filled())))
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .label(format!("{mask} k={k}"))
            .legend(move |(x, y)| Circle::new((x, y), 4, c.filled()));
        // Presets and baselines by name, beside their dot.
        let style = ("sans-serif", 14).into_font().color(&c);
        chart
            .draw_series(pts.iter().filter_map(|p| {
                label(&p.setting).map(|name| {
                    EmptyElement::at((p.ms_one, p.psnr))
                        + Circle::new((0, 0), 7, c.stroke_width(2))
                        + Text::new(short(name).to_string(), (8, -20), style.clone())
                })
            }))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut front: Vec<(f64, f64)> = pts.iter().filter(|p| p.pareto).map(|p| (p.ms_one, p.psnr)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart.draw_series(LineSeries::new(front, c.stroke_width(2))).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_keeps_settings_with_commas_in_one_field() {
        let point = |setting: &str| Point {
            mask: "pixel".into(),
            k: 3,
            setting: setting.into(),
            psnr: 31.5,
            ssim: 0.9,
            sa: 4.2,
            ms_one: 1.5,
            ms_all: 0.8,
            solves: 2.25,
            frame_s: 12.5,
            pareto: true,
        };
        let dir = tempfile::tempdir().unwrap();
        let points = [point("DCT default"), point("ensemble screened, tolerance 1e-3, flat 4e-3")];
        write(&points, &[], dir.path()).unwrap();
        let mut r = csv::Reader::from_path(dir.path().join("bench.csv")).unwrap();
        let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
        assert_eq!(r.headers().unwrap().len(), 11);
        assert_eq!(rows.len(), 2);
        assert!(rows.iter().all(|row| row.len() == 11));
        assert_eq!(&rows[0][9], "12.50");
        assert_eq!(&rows[1][2], "ensemble screened, tolerance 1e-3, flat 4e-3");
        assert_eq!(&rows[1][3], "31.5000");
        // Read back, the points draw the same table; with the device's rows it gains their
        // figure after it.
        let md = std::fs::read_to_string(dir.path().join("bench.md")).unwrap();
        let again = read_points(&dir.path().join("bench.csv")).unwrap();
        assert_eq!(again.len(), 2);
        assert_eq!(again[1].setting, points[1].setting);
        assert_eq!((again[1].psnr, again[1].solves, again[1].frame_s, again[1].pareto), (31.5, 2.25, 12.5, true));
        let device =
            device_frame::parse("decode,patch_solves,instructions_per_solve,clock_mhz\nDCT,1600,5e7,480\n").unwrap();
        let other = tempfile::tempdir().unwrap();
        write(&again, &device, other.path()).unwrap();
        let md2 = std::fs::read_to_string(other.path().join("bench.md")).unwrap();
        assert_eq!(md2, md.clone() + &device_frame::markdown(&device));
        assert!(md2.contains("| DCT | 1600 | 50.0 M | 480 | 167 |"), "{md2}");
        // Issue 51, item 12: drawn again from its own folder's bench.csv, the file keeps
        // its bytes (before: 30.123456789 became 30.1235); into another folder, a copy.
        let own = dir.path().join("bench.csv");
        let text = std::fs::read_to_string(&own).unwrap().replace("31.5000", "30.123456789");
        std::fs::write(&own, &text).unwrap();
        assert_eq!(redraw(&own, &device, dir.path()).unwrap(), 2);
        assert_eq!(std::fs::read_to_string(&own).unwrap(), text);
        assert!(std::fs::read_to_string(dir.path().join("bench.md")).unwrap().contains("| 30.12 |"));
        let third = tempfile::tempdir().unwrap();
        redraw(&own, &[], third.path()).unwrap();
        assert_eq!(std::fs::read_to_string(third.path().join("bench.csv")).unwrap(), text);
        // A row that is not a point is refused with its line.
        let bad = dir.path().join("bad.csv");
        std::fs::write(&bad, "mask,k,setting\npixel,three,x\n").unwrap();
        assert!(format!("{:#}", read_points(&bad).unwrap_err()).contains("line 2"));
    }

    /// Issue 41, item 2: nothing to sweep or to draw is an error at once, and a point the
    /// plot cannot place does not stall it (before: `--only bogus` grew to 24 GB, a time
    /// of 0 or a PSNR of NaN ran past a minute).
    #[test]
    fn empty_or_unplaceable_benches_are_refused_or_drawn_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let opts = BenchOptions { quick: true, progress: false, only: Some("bogus".into()), masks: Vec::new() };
        let e = run(&opts).unwrap_err().to_string();
        assert!(e.contains("--only \"bogus\" names no setting"), "{e}");
        assert!(write(&[], &[], dir.path()).is_err());
        let header = "mask,k,setting,psnr_db,ssim,sa_deg,ms_per_patch_1_thread,ms_per_patch_all_threads,\
                      solves_per_patch,frame_512_s_1_thread,pareto\n";
        let csv = dir.path().join("bench.csv");
        std::fs::write(&csv, header).unwrap();
        assert!(format!("{:#}", read_points(&csv).unwrap_err()).contains("no points"));
        for (row, says) in [
            ("pixel,3,x,30,0.9,4,0,0.5,1,2,true", "line 2: field 7 is a time of 0 ms"),
            ("pixel,3,x,NaN,0.9,4,1,0.5,1,2,true", "line 2: field 4 is NaN"),
            ("pixel,3,x,inf,0.9,4,1,0.5,1,2,true", "line 2: field 4 is inf"),
        ] {
            std::fs::write(&csv, format!("{header}{row}\n")).unwrap();
            let e = format!("{:#}", read_points(&csv).unwrap_err());
            assert!(e.contains(says), "{e}");
        }
        // A sweep's own point of NaN or 0 ms: in the table, not on the plot; written quickly.
        let point = |psnr: f64, ms: f64| Point {
            mask: "pixel".into(),
            k: 3,
            setting: "x".into(),
            psnr,
            ssim: 0.9,
            sa: 4.0,
            ms_one: ms,
            ms_all: ms,
            solves: 1.0,
            frame_s: 1.0,
            pareto: false,
        };
        // Issue 51, item 1: values no decode gives are refused with their line and field,
        // at once (before: +-1.7e308 dB or times of 1e-200 and 1e200 ms ran the plot's axes
        // past 150 s, with bench.csv and bench.md already written).
        for (rows, says) in [
            ("pixel,3,x,1.7e308,0.9,4,1,0.5,1,2,true\npixel,3,y,-1.7e308,0.9,4,1,0.5,1,2,true", "line 2: field 4"),
            ("pixel,3,x,30,0.9,4,1e-200,0.5,1,2,true\npixel,3,y,30,0.9,4,1e200,0.5,1,2,true", "line 2: field 7"),
            ("pixel,3,x,30,0.9,4,1,0.5,1,2,true\npixel,3,y,30,0.9,4,1e200,0.5,1,2,true", "line 3: field 7"),
            ("pixel,3,x,30,1.5,4,1,0.5,1,2,true", "line 2: field 5 is an SSIM of 1.5"),
            ("pixel,3,x,30,0.9,-4,1,0.5,1,2,true", "line 2: field 6 is a spectral angle"),
        ] {
            let out = tempfile::tempdir().unwrap();
            std::fs::write(&csv, format!("{header}{rows}\n")).unwrap();
            let start = std::time::Instant::now();
            let e = format!("{:#}", redraw(&csv, &[], out.path()).unwrap_err());
            assert!(e.contains(says), "{e}");
            assert!(start.elapsed().as_secs() < 10, "refusing took {:?}", start.elapsed());
            assert_eq!(std::fs::read_dir(out.path()).unwrap().count(), 0, "a refused table wrote files");
        }
        // The widest table allowed draws at once.
        let wide = "pixel,3,x,-1000,0.9,4,1e-9,0.5,1,2,true\npixel,3,y,1000,0.9,4,1e12,0.5,1,2,true";
        std::fs::write(&csv, format!("{header}{wide}\n")).unwrap();
        let start = std::time::Instant::now();
        assert_eq!(redraw(&csv, &[], dir.path()).unwrap(), 2);
        assert!(start.elapsed().as_secs() < 30, "drawing took {:?}", start.elapsed());
        let start = std::time::Instant::now();
        write(&[point(f64::NAN, 1.0), point(30.0, 0.0), point(31.0, 2.0)], &[], dir.path()).unwrap();
        assert!(start.elapsed().as_secs() < 30, "drawing took {:?}", start.elapsed());
        assert!(std::fs::read_to_string(dir.path().join("bench.md")).unwrap().contains("| NaN |"));
        assert!(write(&[point(f64::NAN, 1.0)], &[], dir.path()).is_err());
    }
}
