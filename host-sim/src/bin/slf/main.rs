//! `slf`: simulate captures of the compressive spectral light-field camera, decode them
//! with the firmware decoder, and measure the result. `slf --help` lists the commands.
//!
//! One file per command in `commands/` (its clap arguments and its `run`); argument groups
//! and value parsers that several commands share in `args.rs`. This file only dispatches.

mod args;
mod commands;

use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};
use commands::{
    baseline, bench, calibrate, compare, decode, demo, device_capture, device_check, eval, evaluate, import, scene,
    simulate, sweep, train, train_schedule,
};

#[derive(Parser)]
#[command(name = "slf", version, about = "Compressive spectral light-field camera: simulate, decode, measure")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Memory cap in GiB for what a command's inputs declare (an HDF5 dataset's shape, a
    /// training's scenes x size and patches, a calibration's captures), 0.01..=4096: above
    /// it the command is refused before it starts. Default 8, never above `ulimit -v`.
    #[arg(long, global = true, value_name = "GIB", value_parser = gib)]
    max_memory: Option<f64>,
}

fn gib(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if (0.01..=4096.0).contains(&x) => Ok(x),
        _ => Err(format!("{s:?} is not a size in GiB within 0.01..=4096")),
    }
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a default scene with the pixel mask at k = 1 and k = 3, decode, report, preview.
    Demo(demo::Args),
    /// Write a named test scene or a random training scene as a (U, V, H, W, B) .npy.
    Scene(scene::Args),
    /// Real data in: views, hyperspectral cubes, other light fields, as a (U, V, H, W, 13)
    /// light field .npy.
    Import(import::Args),
    /// Record a light field with the camera model: writes a capture folder.
    Simulate(simulate::Args),
    /// A sensor's calibration (dark levels, flats, vignetting, the filters' response matrix,
    /// hot pixels) from its calibration captures; writes a calibration folder.
    Calibrate(calibrate::Args),
    /// Decode a capture folder into a light field .npy.
    Decode(decode::Args),
    /// PSNR, SSIM and spectral angle of a reconstruction against the ground truth.
    Eval(eval::Args),
    /// The paper's 1D method against the 5D decoder on the same patches: time and memory.
    Baseline(baseline::Args),
    /// Learn a dictionary ensemble from light fields (or random training scenes); writes a blob.
    Train(train::Args),
    /// Learn the trained schedules of an ensemble's solves (SL0 unrolled to a few steps, its
    /// per-step sigma, mu and penalty weights learned); writes the blob with them.
    TrainSchedule(train_schedule::Args),
    /// PSNR / SSIM / SA of every test scene x mask family x k, decoded with --dictionary
    /// (default: the shipped ensemble, screened); a markdown table.
    Sweep(sweep::Args),
    /// Speed against error: sweep solver settings, bases, masks and k; CSV, markdown, PNG.
    Bench(bench::Args),
    /// Every baseline, the DCT and the ensemble on the given light fields at pixel k = 1, 3
    /// and lenslet k = 3: PSNR / SSIM / SA and ms per patch per scene and mean (table.md),
    /// and previews of a zoomed crop at pixel k = 1.
    Evaluate(evaluate::Args),
    /// Write the capture the device binary decodes (frames as .npy and `capture.rs` constants).
    DeviceCapture(device_capture::Args),
    /// Compare the device binary's output (its semihosting log) with the host's decode of
    /// the same tiles; fails above 1e-5 relative difference.
    DeviceCheck(device_check::Args),
    /// Mean PSNR / SSIM / SA over the test scenes for {DCT, ensemble exhaustive, ensemble
    /// screened} x {pixel, lenslet, kronecker} x k, and time per patch; a markdown table.
    Compare(compare::Args),
}

fn main() -> ExitCode {
    ignore_file_size_signal();
    use clap::{CommandFactory, FromArgMatches};
    let parsed = slf_host::sim::flags::negative_numbers(Cli::command())
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                let names: Vec<String> = Cli::command().get_subcommands().map(|c| c.get_name().to_string()).collect();
                eprintln!("error: a command is required: {} (see `slf --help`)", names.join(", "));
                return ExitCode::from(2);
            }
            // One readable line: clap's message (with the arguments it names on the lines
            // after), without usage and tips.
            eprintln!("error: {} (see `slf --help`)", slf_host::sim::flags::one_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = run(cli);
    // An interrupt's handler, removing the temporaries, may have made the command fail:
    // its exit 130 is how the run ended.
    slf_host::io::interrupt::settle();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output went away (`| head`): it has what it wanted.
        Err(e) if slf_host::io::stdout::closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", slf_host::io::message::one_line(&e));
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    // Before any command makes a temporary: an interrupt removes what it was writing.
    slf_host::io::interrupt::install()?;
    if let Some(cap) = cli.max_memory {
        slf_host::io::budget::set_cap((cap * f64::from(1u32 << 30)) as u64);
    }
    match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Scene(args) => scene::run(args),
        Command::Import(args) => import::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Calibrate(args) => calibrate::run(args),
        Command::Decode(args) => decode::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Baseline(args) => baseline::run(args),
        Command::Train(args) => train::run(args),
        Command::TrainSchedule(args) => train_schedule::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::DeviceCapture(args) => device_capture::run(args),
        Command::DeviceCheck(args) => device_check::run(args),
        Command::Compare(args) => compare::run(args),
    }
}

/// A write past the file-size limit (`ulimit -f`) is an error the write returns (EFBIG), so
/// the whole-write contract removes its temporary file; by default SIGXFSZ would end the
/// process first and leave `.NAME.XXXXXX.part` behind.
#[cfg(unix)]
fn ignore_file_size_signal() {
    use nix::sys::signal::{SigHandler, Signal, signal};
    // SAFETY: SIG_IGN installs no handler, so no code runs in signal context; this runs
    // first in main, before any thread that could race on the disposition exists.
    let _ = unsafe { signal(Signal::SIGXFSZ, SigHandler::SigIgn) };
}

#[cfg(not(unix))]
fn ignore_file_size_signal() {}
