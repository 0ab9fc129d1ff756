//! `slf decode`: a capture folder to a light field `.npy`, by compressed sensing (the
//! firmware's decoder, in parallel over tiles) or by a baseline without it. The decode's
//! flags are [`DecodeSettings`], shared with the Python package.

use slf_host::outln;
use std::path::PathBuf;

use anyhow::{Context, Result};
use slf_host::decode::cs::{Balance, NoiseSource, PatchDecoder, disparity_per_lenslet};
use slf_host::decode::options::Maps;
use slf_host::decode::pipeline::{Outcome, output_shape};
use slf_host::decode::report::NO_ESTIMATE;
use slf_host::decode::settings::DecodeSettings;
use slf_host::io::calibration::Calibration;
use slf_host::io::capture::Capture;
use slf_host::io::lightfield::{Dtype, stage_npy_f32_2d};
use slf_host::io::output::{Outputs, stage};
use slf_host::io::output_file::{OutputFile, OutputKind};

#[derive(clap::Args)]
pub struct Args {
    /// Capture folder (capture.json and frames).
    pub capture: PathBuf,
    /// Output, written as its rows are decoded: a .npy file, an HDF5 file (.h5, .hdf5) or
    /// a Zarr v3 store (.zarr, a folder; or --format): normalised units (white = 1), every method's values clamped to the
    /// sensor's physical range, 0 to (max_valid - black) / (white - black) (1.111 for the
    /// simulator's default sensor).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The output's format [default: hdf5 for a name ending in .h5 or .hdf5, zarr for .zarr,
    /// else npy].
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// HDF5 and Zarr: compress the light field's chunks by deflate at this level (1..=9;
    /// HDF5 with the shuffle filter, Zarr as gzip); none by default.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=9))]
    pub deflate: Option<u32>,
    #[command(flatten)]
    pub settings: DecodeSettings,
    /// Also write which decoder made each patch (CSV: the patch's origin, the disparity it
    /// was sheared to, the decoder: member, dictionary, interpolated or flat, and the
    /// ensemble member).
    #[arg(long)]
    pub member_map: Option<PathBuf>,
    /// Also write the chosen disparity per lenslet (.npy, lenslet rows x cols, f32: the
    /// mean over the blocks that cover it); not with --disparities 0:0.
    #[arg(long)]
    pub disparity_map: Option<PathBuf>,
    /// Also write each lenslet's error estimate (.npy, lenslet rows x cols, f32, the
    /// output's units: the RMS error per value the patches covering it estimate from
    /// measurements held out of one more solve; NaN where no patch was estimated). Implies
    /// --estimate.
    #[arg(long)]
    pub error_map: Option<PathBuf>,
    /// Also write each lenslet's share of views that lie on the sensor (.npy, lenslet rows x
    /// cols, f32): 1 but where a turned lenslet array's corner lenslets reach past the
    /// sensor's edges, whose views there are guessed from their neighbours, not measured.
    /// The decode's estimated PSNR leaves those lenslets out.
    #[arg(long)]
    pub coverage_map: Option<PathBuf>,
    /// Stored dtype.
    #[arg(long, value_enum, default_value_t = Dtype::F32)]
    pub dtype: Dtype,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `slf decode --format`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// A 5-axis `.npy` (U, V, H, W, 13), written as its rows are decoded.
    Npy,
    /// An HDF5 file: the chunked dataset `lightfield` (U, V, H, W, 13) with its axes, the
    /// band centres in nm, the capture's description and the decode's command as
    /// attributes (`slf import hdf5 OUT --dataset lightfield --axes uvhwb` reads it back).
    Hdf5,
    /// A Zarr v3 store (a folder): the array `lightfield` (U, V, H, W, 13) with its
    /// dimension names, the array `band` (the band centres in nm), and the capture's
    /// description and the decode's command as the group's attributes; Dask, xarray,
    /// zarr-python and napari open it lazily.
    Zarr,
}

pub fn run(args: Args) -> Result<()> {
    let Args {
        capture,
        output,
        format,
        deflate,
        mut settings,
        member_map,
        disparity_map,
        error_map,
        coverage_map,
        dtype,
        quiet,
    } = args;
    let named = |ext: &[&str]| output.extension().is_some_and(|e| ext.iter().any(|x| e.eq_ignore_ascii_case(x)));
    let format = format.unwrap_or(if named(&["h5", "hdf5"]) {
        Format::Hdf5
    } else if named(&["zarr"]) {
        Format::Zarr
    } else {
        Format::Npy
    });
    anyhow::ensure!(
        format != Format::Npy || deflate.is_none(),
        "--deflate compresses an HDF5 or Zarr output: give -o OUT.h5, -o OUT.zarr or --format hdf5|zarr"
    );
    anyhow::ensure!(
        format == Format::Npy || dtype == Dtype::F32,
        "--dtype u16 is for a .npy output; the HDF5 and Zarr outputs are float32"
    );
    settings.estimate |= error_map.is_some();
    // The per-patch maps only when written: they grow with the frame.
    settings.maps = Maps { members: member_map.is_some(), disparities: disparity_map.is_some() };
    let cap = Capture::load(&capture)?;
    // Where the results go is checked before the decode, not found unwritable after it, and
    // no result may be written over a file the decode reads or another result.
    let outputs = Outputs::new()
        .inputs(cap.files(), "a file of the capture")
        .inputs(&settings.basis.blob, "--blob")
        .inputs(settings.calibration.iter().flat_map(|d| Calibration::files_in(d)), "a file of --calibration");
    let outputs =
        if format == Format::Zarr { outputs.folder_output(&output, "-o") } else { outputs.output(&output, "-o") };
    outputs
        .outputs(member_map.as_deref(), "--member-map")
        .outputs(disparity_map.as_deref(), "--disparity-map")
        .outputs(error_map.as_deref(), "--error-map")
        .outputs(coverage_map.as_deref(), "--coverage-map")
        .check()?;
    let cs = settings.method.baseline().is_none();
    anyhow::ensure!(cs || member_map.is_none(), "--member-map needs --method cs (baselines use no ensemble)");
    anyhow::ensure!(
        cs || !settings.estimate,
        "--error-map and --estimate need --method cs (baselines solve nothing to hold out of)"
    );
    anyhow::ensure!(
        cs || coverage_map.is_none(),
        "--coverage-map needs --method cs (a baseline's decode reports no lenslets past the sensor)"
    );
    anyhow::ensure!(
        cs || disparity_map.is_none(),
        "--disparity-map needs --method cs (baselines choose no disparity; nothing would be written)"
    );
    if cs {
        // The flags first, so a bad one is named before the decode and not as the capture's.
        let (_, opts) = settings.resolve()?;
        anyhow::ensure!(
            disparity_map.is_none() || !opts.disparities_for(&cap).is_off(),
            "--disparity-map needs disparities to search: with --disparities 0:0 every block is at 0"
        );
    }
    // The light field goes to the file as its rows are decoded; the file takes its place
    // only once the decode and the maps are done. An interrupt (Ctrl-C, SIGTERM) ends the
    // run at once and removes the temporary file (`slf_host::io::interrupt`).
    let kind = match format {
        Format::Npy => OutputKind::Npy(dtype),
        Format::Hdf5 => OutputKind::Hdf5(deflate),
        Format::Zarr => OutputKind::Zarr(deflate),
    };
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    let mut file = OutputFile::create(kind, &output, output_shape(&cap), &cap.description, &command)?;
    let outcome =
        settings.run_into(&cap, !quiet, &|_, _| {}, file.sink()).with_context(|| capture.display().to_string())?;
    if let Some(w) = outcome.warning() {
        eprintln!("warning: {}: {w}", capture.display());
    }
    let (opts, r) = match &outcome {
        Outcome::Baseline { method, report: r } => {
            file.finish(&format!("--method {method:?}"))?;
            outln!(
                "{:?}: {} sensor positions measured, {} filled from their neighbours, in {:.3} s; wrote {}",
                method,
                r.measured,
                r.filled,
                r.seconds,
                output.display()
            )?;
            return Ok(());
        }
        Outcome::Cs { options, report } => (options, report),
    };
    // The maps are written to their temporary files first and put in place only once the
    // light field's file is: a decode that fails at its last write leaves none of them.
    let mut staged = Vec::new();
    if let Some(path) = member_map {
        let mut csv = String::from("lenslet_row,lenslet_col,view_row,view_col,disparity,decoder,member\n");
        for (o, d) in &r.member_map {
            let member = if let PatchDecoder::Member(m) = d { m.to_string() } else { String::new() };
            csv += &format!(
                "{},{},{},{},{},{},{member}\n",
                o.lenslet_row,
                o.lenslet_col,
                o.view_row,
                o.view_col,
                o.disparity,
                d.name()
            );
        }
        staged.push(stage(&path, |w| Ok(w.write_all(csv.as_bytes())?))?);
    }
    let (rows, cols) = (cap.description.lenslets[0], cap.description.lenslets[1]);
    if let Some(path) = disparity_map {
        let map = disparity_per_lenslet(&r.disparity_map, rows, cols);
        staged.push(stage_npy_f32_2d(&path, &map, rows, cols)?);
    }
    // Asked for and none made: NaN everywhere, as a lenslet no patch estimated.
    let errors = r.error_map(rows, cols, settings.estimate);
    if let (Some(path), Some(map)) = (&error_map, &errors) {
        staged.push(stage_npy_f32_2d(path, map, rows, cols)?);
    }
    if let Some(path) = &coverage_map {
        staged.push(stage_npy_f32_2d(path, &r.off_sensor.coverage([rows, cols]), rows, cols)?);
    }
    let peak = f64::from(file.max());
    file.finish(&format!("{opts:?}"))?;
    for map in staged {
        map.persist()?;
    }
    let used = opts.solver_config(&cap);
    let ball = match (opts.noise, used.noise > 0.0 || used.shot > 0.0) {
        (_, false) => "exact projection".to_string(),
        (NoiseSource::Capture, true) => {
            format!("the capture's noise (sd {:.2e} + shot {:.2e} per unit)", used.noise, used.shot)
        }
        (NoiseSource::Config, true) => format!("noise sd {:.2e} + shot {:.2e} per unit", used.noise, used.shot),
    };
    if let Some(v) = r.patch_views {
        outln!("patch: {} (--patch-views {v})", v.shape_name())?;
    }
    outln!("projection: {ball}")?;
    let gains: Vec<String> = r.gains.iter().map(|g| format!("{g:.3}")).collect();
    match opts.balance {
        Balance::Off => outln!("white balance: off"),
        Balance::GreyWorld => outln!("white balance: grey world, gains {}", gains.join(" ")),
        Balance::Gains(_) => outln!("white balance: given gains {}", gains.join(" ")),
    }?;
    if !opts.disparities_for(&cap).is_off() {
        let counts: Vec<String> = r
            .disparity_counts
            .iter()
            .map(|(d, n)| format!("{}{d}: {n}", if d.in_halves() > 0 { "+" } else { "" }))
            .collect();
        outln!(
            "disparity: blocks per disparity {}; {} values of views no sheared patch reached, from their lenslet's other views",
            counts.join(", "),
            r.filled
        )?;
    }
    if let Some(g) = &r.grid {
        let off = &r.off_sensor;
        let edges = if off.lenslets > 0 {
            format!(
                "; {} lenslets reach past the sensor's edges ({} of their views unmeasured, guessed from their \
                 neighbours; `slf eval --border` scores without the edge lenslets)",
                off.lenslets, off.views
            )
        } else {
            String::new()
        };
        let moved = match r.grid_moved {
            [0, 0] => String::new(),
            [s, t] => format!(
                "; the calibration's grid named as the capture's: its lenslets moved by ({s}, {t}) to put lenslet (0, \
                 0) at ({:.2}, {:.2}) px",
                g.offset[0], g.offset[1]
            ),
        };
        outln!(
            "lenslet grid: turned {:.4} degrees, pitch {:.4} x {:.4} px, each pixel the shares of the view cells it \
             covers{moved}{edges}",
            g.rotation_deg,
            g.pitch[0],
            g.pitch[1]
        )?;
    }
    let p = opts.plausibility;
    if p.is_off() {
        outln!("plausibility: off")?;
    } else {
        outln!(
            "plausibility: {} implausible patches decoded again, {} of them clipped (a value above {} x its \
             neighbourhood's brightest measurement + {})",
            r.patches.implausible,
            r.patches.clipped,
            p.factor,
            p.margin
        )?;
    }
    // Said when asked for by name (the presets ask for it wherever the capture's disparities
    // may have halves).
    if let Some(why) = r.shear_trial_skipped.as_ref().filter(|_| settings.shear_trial == Some(true)) {
        outln!("shear trial: not run ({why})")?;
    }
    if r.shear_trial.is_some_and(|t| t.pilots == 0) {
        outln!(
            "shear trial: no pilot patch at a half-pixel disparity could be estimated; half-pixel disparities kept"
        )?;
    } else if let Some(t) = r.shear_trial {
        outln!(
            "shear trial: {} (held-out error over {} pilot patches at half-pixel disparities: half {:.5}, whole {:.5})",
            if t.halves { "half-pixel disparities kept" } else { "whole disparities only: the half ones alias" },
            t.pilots,
            t.half_error,
            t.whole_error
        )?;
    }
    if let Some(t) = r.trial.filter(|t| t.pilots == 0) {
        outln!(
            "model trial: no pilot patch could be estimated (too few bands measured, or the response in the \
             projection); decoded by the {}",
            if t.dct { "DCT" } else { "ensemble" }
        )?;
    } else if let Some(t) = r.trial {
        let model = if t.dct { "DCT" } else { "ensemble" };
        match t.by_decode {
            Some((dct, ensemble)) => outln!(
                "model trial: decoded by the {model} (held-out error of the frame decoded again from seven samples \
                 in eight: DCT {dct:.5}, ensemble {ensemble:.5}; over {} pilot patches: DCT {:.5}, ensemble {:.5})",
                t.pilots,
                t.dct_error,
                t.ensemble_error
            )?,
            None => outln!(
                "model trial: decoded by the {model} (held-out error over {} pilot patches: DCT {:.5}, ensemble {:.5}{})",
                t.pilots,
                t.dct_error,
                t.ensemble_error,
                if t.tied { "; within their spread, so the mask's usual model" } else { "" }
            )?,
        }
    }
    if let Some(why) = &r.blend_skipped {
        outln!("baseline blend: not made ({why}); the decode alone")?;
    }
    if let Some(b) = &r.blend {
        outln!(
            "baseline blend: PPID's weight {:.2} on average, above one half at {} of {} lenslets (by the held-out \
             errors of three decodes and PPIDs, each without one of every block's snapshots; {:.2} s)",
            b.mean_weight(),
            b.mostly_baseline(),
            b.weights.len(),
            b.seconds
        )?;
    }
    if let Some(map) = &errors {
        let psnr = r.estimated_psnr(map, cols, peak).map_or("none".into(), |p| format!("{p:.2} dB"));
        let left_out = match r.off_sensor.lenslets {
            0 => String::new(),
            n => format!(", the {n} lenslets that reach past the sensor left out"),
        };
        let by = if !r.estimated() {
            NO_ESTIMATE.to_string()
        } else if r.error_lenslets.is_empty() {
            format!("{} of {} patches from held-out measurements", r.error_map.len(), r.patches.decoded)
        } else if r.blend.is_some() {
            "the baseline blend's held-out decodes, every sample held out once".to_string()
        } else {
            format!("the frame decoded again from seven samples in eight ({:.2} s)", r.estimate_seconds)
        };
        outln!("error estimate: {by}; estimated PSNR {psnr} (data range {peak:.4} = the decode's maximum{left_out})")?;
    }
    let per = |n: u64| n as f64 / f64::from(r.patches.decoded.max(1));
    outln!(
        "sl0: {} solves, {} steps ({:.2} solves and {:.1} steps a patch, the last solve's steps counted)",
        r.solves,
        r.steps,
        per(r.solves),
        per(r.steps)
    )?;
    let seeds = if r.seed_rows > 0 { format!(" and {} rows of seeds", r.seed_rows) } else { String::new() };
    outln!(
        "memory: the decode held at most {} of the frame's {rows} lenslet rows of sums at once{seeds} ({:.1} MB in \
         its strip; the light field is written to {} as its rows are finished)",
        r.rows_held,
        r.strip_bytes as f64 / 1e6,
        output.display()
    )?;
    outln!(
        "decoded {} patches ({} solved, {} interpolated from fewer than {} bands, {} flat; {} flagged, {} failed, {} \
         tiles failed) in {:.3} s; wrote {}",
        r.patches.decoded,
        r.patches.solved(),
        r.patches.interpolated,
        opts.sl0.min_bands,
        r.patches.flat,
        r.patches.flagged,
        r.patches.failed,
        r.failed_tiles,
        r.seconds,
        output.display()
    )?;
    Ok(())
}
