//! The calibration captures of a simulated sensor (issue 43): what a camera maker takes to
//! calibrate one, made with the same camera (mask, sensor, noise) as its scene captures, so
//! `slf calibrate` can be checked against the sensor that made them.
//!
//! - `dark-NN`: no light (the lens capped);
//! - `flat-NN`: a uniform white target under light of equal energy in every band, at
//!   [`FLAT_LEVEL`] of white;
//! - `band-BB-NN`: the same target under light of band `BB` only (a monochromator's
//!   sweep), at [`FLAT_LEVEL`] of white.
//!
//! `NN` counts exposures: each exposure draws its own noise, and `slf calibrate` averages
//! them.

use std::path::Path;

use anyhow::{Result, ensure};

use crate::io::capture::{Capture, DESCRIPTION, Light, MaskDescription};
use crate::io::folder::{Kind, WholeFolder};
use crate::io::lightfield::LightField;
use crate::io::output::Outputs;
use crate::sim::camera::{CameraConfig, simulate_under};

/// The flat's and the sweep's light, a fraction of white: bright for a good signal, below
/// the top code with the brightest pixel's gain.
pub const FLAT_LEVEL: f32 = 0.8;

/// The most exposures of each kind.
pub const MAX_EXPOSURES: usize = 256;

/// The calibration captures for `cam` over frames of `lenslets` lenslets of `views` views
/// and `bands` bands, `exposures` of each kind, named as the module says.
///
/// # Errors
/// `exposures` out of 1..=[`MAX_EXPOSURES`]; the camera's own errors ([`simulate_under`]).
pub fn calibration_captures(
    cam: &CameraConfig,
    lenslets: [usize; 2],
    views: [usize; 2],
    bands: usize,
    exposures: usize,
) -> Result<Vec<(String, Capture)>> {
    ensure!((1..=MAX_EXPOSURES).contains(&exposures), "exposures {exposures}: must be in 1..={MAX_EXPOSURES}");
    // Every capture is held until written, beside one light field a kind: checked before
    // any is made (--exposures 256 at 100 x 100 lenslets once took 2.1 GB unannounced).
    let kinds = 2 + bands as u64;
    let pixels = match &cam.grid {
        Some(g) => g.grid(lenslets, views).sensor.iter().map(|&n| n as u64).product(),
        None => (lenslets[0] * views[0]) as u64 * (lenslets[1] * views[1]) as u64,
    };
    let snapshots = match &cam.mask {
        MaskDescription::Kronecker { snapshots, .. } => u64::from(*snapshots),
        MaskDescription::Pixel(m) | MaskDescription::Lenslet(m) => {
            m.snapshots.map_or_else(|| m.tile.as_ref().map_or(1, |t| t.len() as u64), u64::from)
        }
    };
    let need = kinds * pixels * bands as u64 * 4 + kinds * exposures as u64 * snapshots * pixels * 2;
    crate::io::budget::check(
        need,
        &format!(
            "{kinds} kinds of calibration capture x {exposures} exposures of {} x {} pixels",
            lenslets[0] * views[0],
            lenslets[1] * views[1]
        ),
        "fewer --exposures",
    )?;
    let field = |band: Option<usize>, level: f32| {
        LightField::from_fn((views[0], views[1]), lenslets[0], lenslets[1], bands, |_, _, _, _, b| {
            if band.is_none_or(|band| band == b) { level } else { 0.0 }
        })
    };
    let mut kinds = vec![("dark".to_string(), Light::Dark, field(None, 0.0))];
    kinds.push(("flat".into(), Light::Flat { level: FLAT_LEVEL }, field(None, FLAT_LEVEL)));
    for b in 0..bands {
        kinds.push((
            format!("band-{b:02}"),
            Light::Band { band: b as u8, level: FLAT_LEVEL },
            field(Some(b), FLAT_LEVEL),
        ));
    }
    let mut out = Vec::with_capacity(kinds.len() * exposures);
    for (i, (name, light, lf)) in kinds.iter().enumerate() {
        for n in 0..exposures {
            // Each exposure its own noise; the mask and the sensor stay the camera's.
            let seed = cam.seed.wrapping_mul(1_000_003).wrapping_add((i * MAX_EXPOSURES + n + 1) as u64);
            let shot = CameraConfig { seed, ..cam.clone() };
            out.push((format!("{name}-{n:02}"), simulate_under(lf, &shot, *light)?));
        }
    }
    Ok(out)
}

/// `outputs` with the files of `captures` written into `dir` (one folder each, by name), so
/// that [`Outputs::check_distinct`] refuses a calibration capture over an input or the scene
/// capture before anything is written.
pub fn with_outputs(outputs: Outputs, captures: &[(String, Capture)], dir: &Path) -> Outputs {
    captures.iter().fold(outputs, |o, (name, c)| o.outputs(c.files_in(&dir.join(name)), "a calibration capture's file"))
}

/// Writes `captures` into `dir`, one capture folder each, by name (what `slf calibrate DIR`
/// reads). The set is written whole ([`WholeFolder`]): an existing `dir` must be empty or
/// hold only capture folders, and is replaced, so no capture of an earlier set (another
/// sensor's, say) is left beside the new ones.
///
/// # Errors
/// A `dir` holding anything else; I/O errors.
pub fn save(captures: &[(String, Capture)], dir: &Path) -> Result<()> {
    stage(captures, dir)?.persist()
}

/// As [`save`], short of putting the folder in place ([`WholeFolder::persist`]).
///
/// # Errors
/// As [`save`].
pub fn stage(captures: &[(String, Capture)], dir: &Path) -> Result<WholeFolder> {
    let folder = WholeFolder::create(dir, Kind::Folders(DESCRIPTION))?;
    for (name, c) in captures {
        let at = folder.path().join(name);
        std::fs::create_dir(&at).map_err(|e| anyhow::anyhow!("cannot create {}: {e}", at.display()))?;
        c.write_into(&at)?;
    }
    Ok(folder)
}

/// Checks that the calibration captures' folder `dir` and the scene capture's folder
/// `capture` are apart: neither is the other nor holds it (each is replaced whole).
///
/// # Errors
/// The two folders overlapping, named.
pub fn apart_from(dir: &Path, capture: &Path) -> Result<()> {
    let full = |p: &Path| {
        let p = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        // Existing folders by their real place (a link or `..` names the same folder).
        p.canonicalize().unwrap_or(p)
    };
    let (d, c) = (full(dir), full(capture));
    anyhow::ensure!(
        !(d.starts_with(&c) || c.starts_with(&d)),
        "--calibration-captures {}: {} the capture's folder -o {}, and each is written whole: give the calibration \
         captures a folder of their own",
        dir.display(),
        if d == c {
            "is"
        } else if d.starts_with(&c) {
            "is inside"
        } else {
            "holds"
        },
        capture.display()
    );
    Ok(())
}
