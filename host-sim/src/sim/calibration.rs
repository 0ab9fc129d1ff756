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

/// The calibration captures of one sensor, named as the module says: made one at a time
/// ([`Self::for_each`], [`Self::stage`]: one kind's light field and one capture held, so a
/// large sensor's set is written in the memory of one capture), or all at once
/// ([`Self::collect`]: tests, the device's check).
#[derive(Clone, Debug)]
pub struct CalibrationCaptures {
    cam: CameraConfig,
    lenslets: [usize; 2],
    views: [usize; 2],
    bands: usize,
    exposures: usize,
}

impl CalibrationCaptures {
    /// The set for `cam` over frames of `lenslets` lenslets of `views` views and `bands`
    /// bands, `exposures` of each kind.
    ///
    /// # Errors
    /// `exposures` out of 1..=[`MAX_EXPOSURES`].
    pub fn new(
        cam: &CameraConfig,
        lenslets: [usize; 2],
        views: [usize; 2],
        bands: usize,
        exposures: usize,
    ) -> Result<Self> {
        ensure!((1..=MAX_EXPOSURES).contains(&exposures), "exposures {exposures}: must be in 1..={MAX_EXPOSURES}");
        Ok(Self { cam: cam.clone(), lenslets, views, bands, exposures })
    }

    /// The kinds: name, light, and the band lit (all where `None`) at which level.
    fn kinds(&self) -> Vec<(String, Light, Option<usize>, f32)> {
        let mut kinds = vec![("dark".to_string(), Light::Dark, None, 0.0)];
        kinds.push(("flat".into(), Light::Flat { level: FLAT_LEVEL }, None, FLAT_LEVEL));
        for b in 0..self.bands {
            kinds.push((format!("band-{b:02}"), Light::Band { band: b as u8, level: FLAT_LEVEL }, Some(b), FLAT_LEVEL));
        }
        kinds
    }

    /// The captures' names, in the order they are made.
    pub fn names(&self) -> Vec<String> {
        self.kinds().iter().flat_map(|(name, ..)| (0..self.exposures).map(move |n| format!("{name}-{n:02}"))).collect()
    }

    /// How many.
    pub fn len(&self) -> usize {
        (2 + self.bands) * self.exposures
    }

    /// None (never: at least the dark and the flat).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A light field's and a capture's bytes.
    fn sizes(&self) -> (u64, u64) {
        let pixels = match &self.cam.grid {
            Some(g) => g.grid(self.lenslets, self.views).sensor.iter().map(|&n| n as u64).product(),
            None => (self.lenslets[0] * self.views[0]) as u64 * (self.lenslets[1] * self.views[1]) as u64,
        };
        let snapshots = match &self.cam.mask {
            MaskDescription::Kronecker { snapshots, .. } => u64::from(*snapshots),
            MaskDescription::Pixel(m) | MaskDescription::Lenslet(m) => {
                m.snapshots.map_or_else(|| m.tile.as_ref().map_or(1, |t| t.len() as u64), u64::from)
            }
        };
        let field = self.lenslets.iter().chain(&self.views).map(|&n| n as u64).product::<u64>() * self.bands as u64 * 4;
        (field, snapshots * pixels * 2)
    }

    fn what(&self, count: &str) -> String {
        let (l, v) = (self.lenslets, self.views);
        format!("{count} of {} x {} pixels", l[0] * v[0], l[1] * v[1])
    }

    /// Calls `f(name, capture)` on each capture as it is made, in [`Self::names`]' order:
    /// one kind's light field and one capture held at a time (checked against the memory
    /// cap first).
    ///
    /// # Errors
    /// Over the memory cap; the camera's own errors ([`simulate_under`]); what `f` says.
    pub fn for_each(&self, mut f: impl FnMut(String, Capture) -> Result<()>) -> Result<()> {
        let (field, capture) = self.sizes();
        crate::io::budget::check(field + capture, &self.what("a calibration capture"), "a smaller sensor")?;
        for (i, (name, light, band, level)) in self.kinds().into_iter().enumerate() {
            let (views, [rows, cols]) = ((self.views[0], self.views[1]), self.lenslets);
            let lf = LightField::from_fn(views, rows, cols, self.bands, |_, _, _, _, b| {
                if band.is_none_or(|band| band == b) { level } else { 0.0 }
            });
            for n in 0..self.exposures {
                // Each exposure its own noise; the mask and the sensor stay the camera's.
                let seed = self.cam.seed.wrapping_mul(1_000_003).wrapping_add((i * MAX_EXPOSURES + n + 1) as u64);
                let shot = CameraConfig { seed, ..self.cam.clone() };
                f(format!("{name}-{n:02}"), simulate_under(&lf, &shot, light)?)?;
            }
        }
        Ok(())
    }

    /// Every capture, held (checked against the memory cap first: `--exposures 256` at
    /// 100 x 100 lenslets once took 2.1 GB unannounced).
    ///
    /// # Errors
    /// As [`Self::for_each`].
    pub fn collect(&self) -> Result<Vec<(String, Capture)>> {
        let (field, capture) = self.sizes();
        let what =
            self.what(&format!("{} kinds of calibration capture x {} exposures", 2 + self.bands, self.exposures));
        crate::io::budget::check(field + self.len() as u64 * capture, &what, "fewer --exposures")?;
        let mut out = Vec::with_capacity(self.len());
        self.for_each(|name, c| {
            out.push((name, c));
            Ok(())
        })?;
        Ok(out)
    }

    /// `outputs` with the files the captures will have in `dir` (one folder each, by name;
    /// each capture's frames named as `like`'s, made by the same camera), so that
    /// [`Outputs::check_distinct`] refuses a calibration capture over an input or the scene
    /// capture before anything is made.
    pub fn with_outputs(&self, outputs: Outputs, like: &Capture, dir: &Path) -> Outputs {
        self.names()
            .iter()
            .fold(outputs, |o, name| o.outputs(like.files_in(&dir.join(name)), "a calibration capture's file"))
    }

    /// Makes the captures and writes each into `dir` as it is made, one capture folder each
    /// (replaced whole: an existing `dir` must be empty or hold only capture folders, so no
    /// capture of an earlier set, another sensor's say, is left beside the new ones), short
    /// of putting the folder in place ([`WholeFolder::persist`]).
    ///
    /// # Errors
    /// A `dir` holding anything else; I/O errors; as [`Self::for_each`].
    pub fn stage(&self, dir: &Path) -> Result<WholeFolder> {
        let folder = WholeFolder::create(dir, Kind::Folders(DESCRIPTION))?;
        self.for_each(|name, c| write_one(&folder, &name, &c))?;
        Ok(folder)
    }
}

/// The calibration captures for `cam`, all held ([`CalibrationCaptures::collect`]).
///
/// # Errors
/// As [`CalibrationCaptures::new`] and [`CalibrationCaptures::collect`].
pub fn calibration_captures(
    cam: &CameraConfig,
    lenslets: [usize; 2],
    views: [usize; 2],
    bands: usize,
    exposures: usize,
) -> Result<Vec<(String, Capture)>> {
    CalibrationCaptures::new(cam, lenslets, views, bands, exposures)?.collect()
}

fn write_one(folder: &WholeFolder, name: &str, c: &Capture) -> Result<()> {
    let at = folder.path().join(name);
    std::fs::create_dir(&at).map_err(|e| anyhow::anyhow!("cannot create {}: {e}", at.display()))?;
    c.write_into(&at)
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
