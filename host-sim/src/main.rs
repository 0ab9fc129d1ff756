//! `slf`: simulate captures of the compressive spectral light-field camera, decode them
//! with the firmware decoder, and measure the result. `slf --help` lists the commands.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use slf_host::baseline::{Dense1D, Factors};
use slf_host::camera::{CameraConfig, simulate};
use slf_host::capture::{Capture, MaskDescription};
use slf_host::decode::{Basis, DecodeOptions, DecodeReport, PaperDictionary, decode_with};
use slf_host::firmware::{
    ChoiceRule, DEFAULT_ENSEMBLE, Dictionary, LensletSize, Mask, MaskFamily, MemberChoice, PaperShape, PaperWorkspace,
    Sl0Config, blob, solve, write_blob,
};
use slf_host::lightfield::{Dtype, LightField, read_npy, write_npy};
use slf_host::metrics::{Metrics, evaluate};
use slf_host::preview::write_comparison;
use slf_host::scene::{self, SceneSize};
use slf_host::train;

#[derive(Parser)]
#[command(name = "slf", version, about = "Compressive spectral light-field camera: simulate, decode, measure")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Family {
    Pixel,
    Lenslet,
    Kronecker,
}

impl Family {
    fn family(self) -> MaskFamily {
        match self {
            Family::Pixel => MaskFamily::Pixel,
            Family::Lenslet => MaskFamily::Lenslet,
            Family::Kronecker => MaskFamily::Kronecker,
        }
    }

    fn mask(self, seed: u64, k: u8) -> MaskDescription {
        MaskDescription::seeded(self.family(), seed, k)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum DictionaryKind {
    /// The 5D DCT.
    Dct,
    /// A learned ensemble (the shipped one unless --blob says otherwise).
    Ensemble,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Choice {
    /// Solve with the DCT, pick the member that best represents it, solve with that (2 solves).
    Screened,
    /// Solve with every member, keep the sparsest (K + 1 solves).
    Exhaustive,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Rule {
    /// Energy outside the --rule-tau largest coefficients.
    Residual,
    /// The l1 norm of the coefficients.
    L1,
}

impl Rule {
    fn rule(self, tau: u16) -> ChoiceRule {
        match self {
            Rule::Residual => ChoiceRule::Residual { tau },
            Rule::L1 => ChoiceRule::L1,
        }
    }
}

#[derive(clap::Args, Clone, Debug)]
struct BasisArgs {
    /// Basis to decode with.
    #[arg(long, value_enum, default_value_t = DictionaryKind::Ensemble)]
    dictionary: DictionaryKind,
    /// How an ensemble member is chosen per patch.
    #[arg(long, value_enum, default_value_t = Choice::Screened)]
    choice: Choice,
    /// Ensemble blob (default: the shipped 8-member ensemble).
    #[arg(long)]
    blob: Option<PathBuf>,
}

impl BasisArgs {
    fn basis(&self) -> Result<Basis> {
        Ok(match self.dictionary {
            DictionaryKind::Dct => Basis::Dct,
            DictionaryKind::Ensemble => {
                let blob = match &self.blob {
                    Some(p) => std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))?,
                    None => DEFAULT_ENSEMBLE.to_vec(),
                };
                let rule = ChoiceRule::DEFAULT;
                let choice = match self.choice {
                    Choice::Screened => MemberChoice::Screened(rule),
                    Choice::Exhaustive => MemberChoice::Exhaustive(rule),
                };
                Basis::Ensemble { blob, choice }
            }
        })
    }
}

#[derive(clap::Args, Clone, Debug)]
struct SolverArgs {
    /// SL0 sigma decrease factor per level, in (0, 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_f)]
    sigma_f: f32,
    /// SL0 steps per sigma level (L).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.steps)]
    steps: u16,
    /// SL0 step size mu.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.mu)]
    mu: f32,
    /// SL0 smallest sigma (normalised units, white = 1).
    #[arg(long, default_value_t = Sl0Config::DEFAULT.sigma_min)]
    sigma_min: f32,
    /// Hard bound on SL0 steps per patch.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.max_iterations)]
    max_iterations: u32,
    /// Noise standard deviation per measurement (normalised units); 0 forces equality.
    #[arg(long, default_value_t = 0.0)]
    noise: f32,
    /// Early stop: end a patch's solve once a sigma level moves it by less than this RMS
    /// per value (normalised units); 0 never stops early.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.tolerance)]
    tolerance: f32,
    /// The ensemble's second solve starts from the DCT's patch at this fraction of its
    /// largest coefficient, in (0, 1]; 1 is a cold start.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.warm_start)]
    warm_start: f32,
    /// Short path: a patch whose measurements of each band agree within this (normalised
    /// units) is decoded as each band's mean, with no solve; 0: exactly flat patches only.
    #[arg(long, default_value_t = Sl0Config::DEFAULT.flat)]
    flat: f32,
}

impl SolverArgs {
    fn config(&self) -> Result<Sl0Config> {
        let c = Sl0Config {
            sigma_f: self.sigma_f,
            steps: self.steps,
            mu: self.mu,
            sigma_min: self.sigma_min,
            max_iterations: self.max_iterations,
            noise: self.noise,
            tolerance: self.tolerance,
            warm_start: self.warm_start,
            flat: self.flat,
        };
        c.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(c)
    }
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a default scene with the pixel mask at k = 1 and k = 3, decode, report, preview.
    Demo {
        /// Where previews and files go.
        #[arg(long, default_value = "slf-demo")]
        out: PathBuf,
        /// Named scene.
        #[arg(long, default_value = "depth")]
        scene: String,
        /// Spatial size (lenslets per side).
        #[arg(long, default_value_t = 100)]
        size: usize,
        #[command(flatten)]
        basis: BasisArgs,
    },
    /// Write a named test scene or a random training scene as a (U, V, H, W, B) .npy.
    Scene {
        /// A name (smooth, texture, depth, saturated, dark) or `random`.
        name: String,
        /// Output .npy file.
        #[arg(short, long)]
        output: PathBuf,
        /// Seed of a random scene.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Spatial rows and columns.
        #[arg(long, default_value_t = 100)]
        size: usize,
        /// Views per side.
        #[arg(long, default_value_t = 5)]
        views: usize,
        /// Stored dtype.
        #[arg(long, value_enum, default_value_t = Dtype::F32)]
        dtype: Dtype,
    },
    /// Record a light field with the camera model: writes a capture folder.
    Simulate {
        /// Light field .npy (U, V, H, W, 13).
        input: PathBuf,
        /// Capture folder to write.
        #[arg(short, long)]
        output: PathBuf,
        #[arg(long, value_enum, default_value_t = Family::Pixel)]
        mask: Family,
        /// Snapshots k (1..=13).
        #[arg(short, long, default_value_t = 1)]
        snapshots: u8,
        /// Seed of the mask, noise and defects.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Read noise, DN.
        #[arg(long, default_value_t = 2.0)]
        read_noise: f32,
        /// Electrons at white (shot noise).
        #[arg(long, default_value_t = 20_000.0)]
        full_well: f32,
        /// No shot or read noise.
        #[arg(long)]
        no_noise: bool,
        /// Fraction of defective pixels.
        #[arg(long, default_value_t = 0.0)]
        defects: f64,
        /// Frame file format: pgm, png or npy.
        #[arg(long, default_value = "pgm")]
        format: String,
    },
    /// Decode a capture folder into a light field .npy.
    Decode {
        /// Capture folder (capture.json and frames).
        capture: PathBuf,
        /// Output .npy file.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        solver: SolverArgs,
        #[command(flatten)]
        basis: BasisArgs,
        /// Also write which ensemble member each patch used (CSV).
        #[arg(long)]
        member_map: Option<PathBuf>,
        /// Stored dtype.
        #[arg(long, value_enum, default_value_t = Dtype::F32)]
        dtype: Dtype,
        /// No progress bar.
        #[arg(short, long)]
        quiet: bool,
    },
    /// PSNR, SSIM and spectral angle of a reconstruction against the ground truth.
    Eval { truth: PathBuf, recon: PathBuf },
    /// The paper's 1D method against the 5D decoder on the same patches: time and memory.
    Baseline {
        /// Patches (each a fresh measurement of a test patch).
        #[arg(long, default_value_t = 3)]
        patches: usize,
        #[arg(long, value_enum, default_value_t = Family::Pixel)]
        mask: Family,
        #[arg(short, long, default_value_t = 1)]
        snapshots: u8,
    },
    /// Learn a dictionary ensemble from light fields (or random training scenes); writes a blob.
    Train {
        /// Output blob (the firmware's format).
        #[arg(short, long)]
        output: PathBuf,
        /// Training light fields (.npy); without them, random training scenes are rendered.
        #[arg(long, num_args = 1..)]
        input: Vec<PathBuf>,
        /// Random training scenes to render when no --input is given.
        #[arg(long, default_value_t = 24)]
        scenes: usize,
        /// Spatial size of each rendered training scene.
        #[arg(long, default_value_t = 60)]
        size: usize,
        /// Patches sampled for training.
        #[arg(long, default_value_t = 6000)]
        patches: usize,
        /// Members K.
        #[arg(long, default_value_t = 8)]
        members: usize,
        /// Coefficients kept per patch when coding.
        #[arg(long, default_value_t = 100)]
        tau: usize,
        #[arg(long, default_value_t = 10)]
        iterations: usize,
        /// Patches per member for the HOSVD initialisation.
        #[arg(long, default_value_t = 32)]
        group: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Learn every member (by default member 0 is the fixed 5D DCT).
        #[arg(long)]
        no_dct_member: bool,
    },
    /// PSNR / SSIM / SA of every test scene x mask family x k, with the DCT; a markdown table.
    Sweep {
        /// Spatial size (lenslets per side).
        #[arg(long, default_value_t = 60)]
        size: usize,
        /// Snapshot counts.
        #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
        k: Vec<u8>,
        /// Also write the table to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[command(flatten)]
        basis: BasisArgs,
    },
    /// Speed against error: sweep solver settings, bases, masks and k; CSV, markdown, PNG.
    Bench {
        /// Output folder (bench.csv, bench.md, bench.png).
        #[arg(short, long, default_value = "slf-bench")]
        out: PathBuf,
        /// A CI-sized run: two small scenes, k = 3, no exhaustive choice.
        #[arg(long)]
        quick: bool,
        /// Instead of the sweep: the paper's scale end to end (512 x 512 x 5 x 5 x 13).
        #[arg(long)]
        paper_scale: bool,
        /// Only the settings whose name contains this (e.g. "screened"); the table and
        /// plot then hold just those points.
        #[arg(long)]
        only: Option<String>,
        /// Mask families to sweep (default: all three).
        #[arg(long, value_delimiter = ',')]
        masks: Vec<Family>,
    },
    /// Write the capture the device binary decodes (frames as .npy and `capture.rs` constants).
    DeviceCapture {
        /// Folder (firmware/device).
        #[arg(short, long, default_value = "firmware/device")]
        output: PathBuf,
    },
    /// Compare the device binary's output (its semihosting log) with the host's decode of
    /// the same tiles; fails above 1e-5 relative difference.
    DeviceCheck {
        /// The device's output.
        log: PathBuf,
        /// The capture it decoded.
        #[arg(long, default_value = "firmware/device/capture")]
        capture: PathBuf,
    },
    /// Mean PSNR / SSIM / SA over the test scenes for {DCT, ensemble exhaustive, ensemble
    /// screened} x {pixel, lenslet, kronecker} x k, and time per patch; a markdown table.
    Compare {
        /// Spatial size (lenslets per side).
        #[arg(long, default_value_t = 40)]
        size: usize,
        #[arg(long, value_delimiter = ',', default_value = "1,3,5,7")]
        k: Vec<u8>,
        /// Also write the table to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Ensemble blob (default: the shipped one).
        #[arg(long)]
        blob: Option<PathBuf>,
        /// Only these mask families (default: all three).
        #[arg(long, value_enum, value_delimiter = ',')]
        masks: Vec<Family>,
        /// Member-choice rule.
        #[arg(long, value_enum, default_value_t = Rule::Residual)]
        rule: Rule,
        /// Coefficients kept by the residual rule.
        #[arg(long, default_value_t = 100)]
        rule_tau: u16,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                eprintln!(
                    "error: a command is required: demo, scene, simulate, decode, eval, baseline or sweep (see `slf --help`)"
                );
                return ExitCode::from(2);
            }
            // One readable line: clap's first line (its message), without usage and tips.
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("error: invalid arguments");
            eprintln!("{first} (see `slf --help`)");
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Demo { out, scene, size, basis } => demo(&out, &scene, size, &basis.basis()?),
        Command::Scene { name, output, seed, size, views, dtype } => {
            let s = if name == "random" {
                scene::random(seed)
            } else {
                scene::named(&name)
                    .with_context(|| format!("unknown scene {name:?}: one of {:?} or random", scene::NAMES))?
            };
            let lf = s.render(SceneSize { views: (views, views), rows: size, cols: size });
            write_npy(&output, &lf, dtype)?;
            println!("wrote {} ({:?})", output.display(), lf.shape());
            Ok(())
        }
        Command::Simulate {
            input,
            output,
            mask,
            snapshots,
            seed,
            read_noise,
            full_well,
            no_noise,
            defects,
            format,
        } => {
            let lf = read_npy(&input)?;
            let mut cam = CameraConfig::pixel(seed, snapshots).with_mask(mask.mask(seed, snapshots));
            cam.read_noise = read_noise;
            cam.full_well = Some(full_well);
            cam.defect_fraction = defects;
            cam.frame_ext = format;
            if no_noise {
                cam = cam.noiseless();
            }
            let capture = simulate(&lf, &cam)?;
            capture.save(&output)?;
            println!("wrote {} ({} snapshots)", output.display(), capture.frames.len());
            Ok(())
        }
        Command::Decode { capture, output, solver, basis, member_map, dtype, quiet } => {
            let cap = Capture::load(&capture)?;
            let opts = DecodeOptions { sl0: solver.config()?, progress: !quiet, ..DecodeOptions::default() };
            let (lf, r) = decode_with(&cap, &basis.basis()?, &opts)?;
            if let Some(path) = member_map {
                let mut csv = String::from(
                    "lenslet_row,lenslet_col,view_row,view_col,member
",
                );
                for (o, m) in &r.member_map {
                    csv += &format!(
                        "{},{},{},{},{m}
",
                        o.lenslet_row, o.lenslet_col, o.view_row, o.view_col
                    );
                }
                std::fs::write(&path, csv).with_context(|| format!("cannot write {}", path.display()))?;
            }
            write_npy(&output, &lf, dtype)?;
            println!(
                "decoded {} patches ({} flagged, {} failed, {} tiles failed) in {:.2} s; wrote {}",
                r.patches.decoded,
                r.patches.flagged,
                r.patches.failed,
                r.failed_tiles,
                r.seconds,
                output.display()
            );
            Ok(())
        }
        Command::Eval { truth, recon } => {
            let m = evaluate(&read_npy(&truth)?, &read_npy(&recon)?)?;
            println!("PSNR {:.3} dB (data range {:.6} = max of ground truth)", m.psnr, m.data_range);
            println!("SSIM {:.4}", m.ssim);
            println!("SA   {:.3} deg", m.sa);
            Ok(())
        }
        Command::Baseline { patches, mask, snapshots } => baseline(patches, mask, snapshots),
        Command::Bench { paper_scale: true, .. } => {
            println!("{}", slf_host::bench::paper_scale()?);
            Ok(())
        }
        Command::Bench { out, quick, only, masks, .. } => {
            let masks = masks.iter().map(|m| m.family()).collect();
            let opts = slf_host::bench::BenchOptions { quick, progress: true, only, masks };
            let points = slf_host::bench::run(&opts)?;
            slf_host::bench::write(&points, &out)?;
            println!("{} points; wrote {}/bench.csv, bench.md, bench.png", points.len(), out.display());
            Ok(())
        }
        Command::DeviceCapture { output } => slf_host::device::write_capture(&output),
        Command::DeviceCheck { log, capture } => slf_host::device::check(&log, &capture),
        Command::Sweep { size, k, output, basis } => sweep(size, &k, output.as_deref(), &basis.basis()?),
        Command::Compare { size, k, output, blob, masks, rule, rule_tau } => {
            compare(size, &k, output.as_deref(), blob.as_deref(), &masks, rule.rule(rule_tau))
        }
        Command::Train {
            output,
            input,
            scenes,
            size,
            patches,
            members,
            tau,
            iterations,
            group,
            seed,
            no_dct_member,
        } => {
            let start = Instant::now();
            let fields = if input.is_empty() {
                train::training_fields(scenes, size, 1000 + seed)
            } else {
                input.iter().map(|p| read_npy(p)).collect::<Result<Vec<_>, _>>()?
            };
            for (i, f) in fields.iter().enumerate() {
                anyhow::ensure!(
                    f.bands == 13 && f.views.0 >= 4 && f.views.1 >= 4 && f.rows >= 5 && f.cols >= 5,
                    "training light field {i} is too small for 5x5x4x4x13 patches: {:?}",
                    f.shape()
                );
            }
            let data = train::sample_patches(&fields, patches, seed);
            let cfg = train::TrainConfig {
                members,
                tau,
                iterations,
                group,
                seed,
                dct_member: !no_dct_member,
                progress: true,
            };
            let (dicts, reports) = train::train(&data, &cfg);
            println!("| iteration | members | ensemble coding error | DCT coding error |\n| --- | --- | --- | --- |");
            for (i, r) in reports.iter().enumerate() {
                println!("| {} | {} | {:.5} | {:.5} |", i + 1, r.members, r.ensemble_error, r.dct_error);
            }
            let final_err = train::ensemble_error(&data, &dicts, tau);
            println!(
                "final: {} members, coding error {final_err:.5} vs DCT {:.5} (tau {tau}, relative energy)",
                dicts.len(),
                reports.first().map_or(0.0, |r| r.dct_error)
            );
            let mut blob = vec![0u8; blob::blob_len(PaperShape::DIMS, dicts.len())];
            write_blob(&dicts, &mut blob).map_err(|e| anyhow::anyhow!("{e}"))?;
            std::fs::write(&output, &blob).with_context(|| format!("cannot write {}", output.display()))?;
            println!("wrote {} ({} bytes) in {:.1} s", output.display(), blob.len(), start.elapsed().as_secs_f64());
            Ok(())
        }
    }
}

fn row(scene: &str, family: &str, k: u8, m: &Metrics, seconds: f64) -> String {
    format!("| {scene} | {family} | {k} | {:.2} | {:.4} | {:.2} | {:.2} |", m.psnr, m.ssim, m.sa, seconds)
}

const HEADER: &str =
    "| scene | mask | k | PSNR dB | SSIM | SA deg | decode s |\n| --- | --- | --- | --- | --- | --- | --- |";

fn run_one(
    truth: &LightField,
    cam: &CameraConfig,
    basis: &Basis,
    progress: bool,
) -> Result<(LightField, Metrics, DecodeReport)> {
    let capture = simulate(truth, cam)?;
    let opts = DecodeOptions { progress, ..DecodeOptions::default() };
    let (recon, report) = decode_with(&capture, basis, &opts)?;
    if report.failed_tiles > 0 || report.uncovered > 0 {
        bail!("decode lost {} tiles, {} values uncovered", report.failed_tiles, report.uncovered);
    }
    let metrics = evaluate(truth, &recon)?;
    Ok((recon, metrics, report))
}

fn demo(out: &Path, name: &str, size: usize, basis: &Basis) -> Result<()> {
    let start = Instant::now();
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let s = scene::named(name).with_context(|| format!("unknown scene {name:?}: one of {:?}", scene::NAMES))?;
    let truth = s.render(SceneSize { views: (5, 5), rows: size, cols: size });
    write_npy(&out.join("truth.npy"), &truth, Dtype::F32)?;
    println!(
        "scene {name}: {size} x {size} lenslets, 5 x 5 views, 13 bands; pixel mask; {}; {} threads",
        basis.name(),
        rayon::current_num_threads()
    );
    println!("{HEADER}");
    for k in [1u8, 3] {
        let cam = CameraConfig::pixel(7, k);
        let (recon, m, r) = run_one(&truth, &cam, basis, true)?;
        println!("{}", row(name, "pixel", k, &m, r.seconds));
        write_npy(&out.join(format!("recon_k{k}.npy")), &recon, Dtype::F32)?;
        write_comparison(&out.join(format!("preview_k{k}.png")), &truth, &recon)?;
    }
    println!("PSNR data range = max of ground truth ({:.4}).", truth.max());
    println!(
        "previews (truth | reconstruction | error) in {}; total {:.1} s",
        out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn sweep(size: usize, ks: &[u8], output: Option<&Path>, basis: &Basis) -> Result<()> {
    let mut lines = vec![HEADER.to_string()];
    println!("{HEADER}");
    for name in scene::NAMES {
        let truth =
            scene::named(name).context("named scene")?.render(SceneSize { views: (5, 5), rows: size, cols: size });
        for family in [Family::Pixel, Family::Lenslet, Family::Kronecker] {
            for &k in ks {
                let cam = CameraConfig::pixel(7, k).with_mask(family.mask(7, k));
                let (_, m, r) = run_one(&truth, &cam, basis, false)?;
                let fam = format!("{family:?}").to_lowercase();
                let line = row(name, &fam, k, &m, r.seconds);
                println!("{line}");
                lines.push(line);
            }
        }
    }
    if let Some(p) = output {
        std::fs::write(p, lines.join("\n") + "\n").with_context(|| format!("cannot write {}", p.display()))?;
    }
    Ok(())
}

fn compare(
    size: usize,
    ks: &[u8],
    output: Option<&Path>,
    blob: Option<&Path>,
    masks: &[Family],
    rule: ChoiceRule,
) -> Result<()> {
    let blob = match blob {
        Some(p) => std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))?,
        None => DEFAULT_ENSEMBLE.to_vec(),
    };
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
    lines.iter().for_each(|l| println!("{l}"));
    let threads = rayon::current_num_threads() as f64;
    let families =
        if masks.is_empty() { vec![Family::Pixel, Family::Lenslet, Family::Kronecker] } else { masks.to_vec() };
    for family in families {
        for &k in ks {
            for basis in &bases {
                let cam = CameraConfig::pixel(7, k).with_mask(family.mask(7, k));
                let (mut p, mut s, mut a, mut secs, mut solves, mut patches) = (0.0, 0.0, 0.0, 0.0, 0u64, 0u64);
                for truth in &truths {
                    let (_, m, r) = run_one(truth, &cam, basis, false)?;
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
                println!("{line}");
                lines.push(line);
            }
        }
    }
    if let Some(path) = output {
        std::fs::write(path, lines.join("\n") + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

fn baseline(patches: usize, family: Family, k: u8) -> Result<()> {
    let dict: PaperDictionary = Dictionary::dct();
    let cfg = Sl0Config::DEFAULT;
    let truth =
        scene::named("texture").context("scene")?.render(SceneSize { views: (4, 4), rows: 5 * patches, cols: 5 });
    let lenslet = LensletSize { rows: 4, cols: 4 };
    let mask = match family {
        Family::Pixel => Mask::pixel(3, k, 13, lenslet),
        Family::Lenslet => Mask::lenslet(3, k, 13, lenslet),
        Family::Kronecker => Mask::kronecker(3, k, 13, lenslet, (5, 5)),
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (mut t5, mut t1, mut mem1) = (0.0, 0.0, 0usize);
    let mut worst = 0.0f32;
    for p in 0..patches {
        let mut ws = Box::new(PaperWorkspace::new());
        let mut measured = Vec::new();
        for i in 0..5200 {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            if mask.bands_at((5 * p + s) * 4 + u, t * 4 + v).contains(&(b as u8)) {
                let y = truth.get(u, v, 5 * p + s, t, b);
                ws.measurements_mut().set(i, y).map_err(|e| anyhow::anyhow!("{e}"))?;
                measured.push((i, y));
            }
        }
        let start = Instant::now();
        solve(&dict, &cfg, &mut ws).map_err(|e| anyhow::anyhow!("{e}"))?;
        t5 += start.elapsed().as_secs_f64();
        let idx: Vec<usize> = measured.iter().map(|m| m.0).collect();
        let y: Vec<f32> = measured.iter().map(|m| m.1).collect();
        let start = Instant::now();
        let one = Dense1D::<f32>::new(&Factors::from_dictionary(&dict), &idx).context("A A^T is singular")?;
        let setup = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let (x1, _) = one.solve(&y, &cfg);
        t1 += start.elapsed().as_secs_f64();
        mem1 = mem1.max(one.memory_bytes());
        worst = worst.max(x1.iter().zip(ws.patch()).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max));
        if p == 0 {
            println!("1D set-up (D, A, A^+ for one mask): {setup:.2} s");
        }
    }
    // 5D: the five matrices (as stored in a blob) and the workspace; 1D: D, A and A^+.
    let dict5 = blob::member_len(PaperShape::DIMS);
    let ws5 = std::mem::size_of::<PaperWorkspace>();
    println!("{patches} patches, {family:?} mask, k = {k}, default SL0; 1D vs 5D max abs difference {worst:.2e}");
    println!("| method | time per patch | memory |\n| --- | --- | --- |");
    println!("| 5D (firmware, f32) | {:.2} ms | {dict5} B dictionary + {ws5} B workspace |", 1e3 * t5 / patches as f64);
    println!("| 1D (dense f32, f64 sums) | {:.2} ms | {mem1} B (D, A, A^+) |", 1e3 * t1 / patches as f64);
    println!("time ratio 1D/5D {:.1}x (paper: 106x)", t1 / t5);
    println!(
        "memory ratio 1D/5D: dictionaries {:.0} (paper: 107,729), everything {:.0}",
        (5200.0f64 * 5200.0 * 4.0) / dict5 as f64,
        mem1 as f64 / (dict5 + ws5) as f64
    );
    Ok(())
}
