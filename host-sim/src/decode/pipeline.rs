//! A decode from start to end: the settings a user gave ([`crate::decode::settings`])
//! run on a capture. Its checks that the capture and the flags fit (a calibration capture,
//! a frame with no light, a projection without a response), the calibration's correction
//! and unmixing, the grid to read through, then compressed sensing ([`crate::decode::cs`])
//! or a baseline, each putting the light field's rows to a sink; and what the decode
//! reports ([`Outcome`]).

use anyhow::{Result, bail, ensure};
use clap::ValueEnum;
use slf_firmware::BandCount;
use slf_firmware::{Response, ResponseModel};

use crate::decode::baselines::BaselineReport;
use crate::decode::calibrate::{unmix, unmixing};
use crate::decode::correction::corrected;
use crate::decode::cs::{DecodeOptions, DecodeReport, decode_into};
use crate::decode::settings::{DecodeSettings, GridChoice, Method, ResponseChoice};
use crate::io::calibration::Calibration;
use crate::io::capture::Capture;
use crate::io::lightfield::LightField;
use crate::io::patch::BANDS;
use crate::io::rows::{MapRows, RowShape, Rows};

/// A decode's light field and what it reports.
#[derive(Clone, Debug)]
pub struct Decoded {
    /// `(U, V, H, W, 13)`.
    pub light_field: LightField,
    /// What the method reports.
    pub outcome: Outcome,
}

/// What a decode reports, by method.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// Compressed sensing: the options it ran with (presets and flags resolved) and its
    /// report.
    Cs { options: Box<DecodeOptions>, report: Box<DecodeReport> },
    /// A baseline's report.
    Baseline { method: Method, report: BaselineReport },
}

impl DecodeSettings {
    /// Decodes `capture`. `progress` shows a bar on stderr once the decode has taken a
    /// second; `observer` is called after each tile with (tiles done, tiles in all).
    ///
    /// # Errors
    /// What [`Self::resolve`] refuses; a capture the method cannot take; a decode where no
    /// patch decoded (every patch saturated, defective or unreadable).
    pub fn run(&self, capture: &Capture, progress: bool, observer: &(dyn Fn(usize, usize) + Sync)) -> Result<Decoded> {
        let mut light_field = output_shape(capture).zeros()?;
        let outcome = self.run_into(capture, progress, observer, &mut light_field)?;
        Ok(Decoded { light_field, outcome })
    }

    /// [`Self::run`], each finished lenslet row of the light field ([`output_shape`]) put
    /// into `sink` in order: a compressed-sensing decode holds a band of rows, a baseline a
    /// window of lenslet rows as tall as its neighbourhood, never the frame.
    ///
    /// # Errors
    /// As [`Self::run`], or what the sink returns. On an error the sink may hold some rows
    /// (a file sink is then dropped unfinished: nothing is written).
    pub fn run_into(
        &self,
        capture: &Capture,
        progress: bool,
        observer: &(dyn Fn(usize, usize) + Sync),
        sink: &mut Rows<'_>,
    ) -> Result<Outcome> {
        // Values that would be accepted and ignored: the projection needs a calibration's
        // response, and turns half-pixel shears off (`-1:1:0.5` once gave `-1:1`'s bytes).
        if self.response_model == ResponseChoice::Projection {
            ensure!(
                self.calibration.is_some(),
                "--response-model projection given without --calibration: the response it projects is a \
                 calibration's"
            );
            ensure!(
                self.method.baseline().is_none(),
                "--response-model projection given with a baseline method, which unmixes its spectra: drop it, or \
                 use --method cs"
            );
            ensure!(
                !self.disparities.is_some_and(|d| d.has_halves()),
                "--disparities with half-pixel steps given with --response-model projection, which turns them off: \
                 give whole steps (e.g. -1:1) or --response-model unmix"
            );
        }
        // A calibration capture is no scene: decoding it once went without a word.
        ensure!(
            capture.description.light.is_scene(),
            "{}: a calibration capture (its light is dark, flat or a band), not a scene's: slf calibrate reads it",
            capture.source()
        );
        // A frame with no pixel above the black level recorded no light (a lens cap, an
        // exposure of zero): every method would decode zeros.
        let black = capture.description.black_level;
        ensure!(
            capture.frames.any(capture.frame_size(), |x| f32::from(x) > black)?,
            "every pixel of every frame is at or below the black level ({black} DN): no light was recorded"
        );
        // The output contract, on the capture as recorded: a corrected capture's saturation
        // is the top of 16 bits.
        let (lo, hi) = capture.raw_format().range();
        let calibrated;
        let mut grid_moved = [0, 0];
        let (capture, inverse, response) = match &self.calibration {
            Some(dir) => {
                let cal = Calibration::open(dir)?;
                (calibrated, grid_moved) = corrected(capture, &cal, self.grid != GridChoice::Auto)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
                // The same check on the corrected frames: a dark level at or above the raw
                // values once decoded to all zeros with "0 flagged".
                ensure!(
                    calibrated.frames.any(calibrated.frame_size(), |x| f32::from(x) > black && x != u16::MAX)?,
                    "{}: with its dark levels subtracted every pixel is at or below the black level ({black} DN): no \
                     light above the dark was recorded (is it this sensor's calibration?)",
                    dir.display()
                );
                let inverse = unmixing(&cal.description).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
                (&calibrated, Some(inverse), Some(cal.description.response))
            }
            None => (capture, None, None),
        };
        // `--grid capture`: the calibration kept the capture's own grid (`corrected`'s
        // `keep_grid`), so the capture is read as it is.
        let regridded;
        let capture = match self.grid {
            GridChoice::Auto | GridChoice::Capture => capture,
            GridChoice::Aligned => {
                regridded = capture.aligned()?;
                &regridded
            }
        };
        // Compressed sensing puts the response in the firmware's decode; baselines unmix
        // their spectra here.
        let rows: Option<Vec<[f32; BANDS]>> =
            response.map(|r| r.iter().filter_map(|row| row.as_slice().try_into().ok()).collect());
        let modelled = match rows.and_then(|rows| <[[f32; BANDS]; BANDS]>::try_from(rows).ok()) {
            Some(r) if self.method.baseline().is_none() => Some((
                Response::new(&r).map_err(|e| anyhow::anyhow!("the calibration's response matrix: {e}"))?,
                self.response_model.model(),
            )),
            _ => None,
        };
        let mut outcome = match (&inverse, modelled) {
            (Some(inverse), None) => {
                let bands = output_shape(capture).bands;
                // Unmixing can take a value below 0 or past the sensor's top (PPID's wrote
                // 20,531 of 83,200 values below 0): clamped again, as every method's output.
                let mut unmixed = MapRows::new(sink, |row: &mut [f32]| {
                    unmix(row, bands, inverse);
                    row.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
                });
                self.run_corrected(capture, modelled, progress, observer, &mut unmixed)
            }
            _ => self.run_corrected(capture, modelled, progress, observer, sink),
        }?;
        // A paged frame's read that failed read as no samples: the decode is refused, not
        // passed off as one that flagged those pixels.
        capture.frames.read_error()?;
        if let (Outcome::Cs { report, .. }, GridChoice::Auto) = (&mut outcome, self.grid) {
            report.grid_moved = grid_moved;
        }
        Ok(outcome)
    }

    /// [`Self::run_into`] on a capture as it is (corrected already, or needing no
    /// correction).
    fn run_corrected(
        &self,
        capture: &Capture,
        response: Option<(Response<BandCount<BANDS>>, ResponseModel)>,
        progress: bool,
        observer: &(dyn Fn(usize, usize) + Sync),
        sink: &mut Rows<'_>,
    ) -> Result<Outcome> {
        if let Some(baseline) = self.method.baseline() {
            let given = self.compressed_sensing_flags();
            ensure!(
                given.is_empty(),
                "{} given with --method {}, which uses none of the compressed-sensing flags: drop them, or use \
                 --method cs",
                given.join(", "),
                self.method.to_possible_value().map_or_else(String::new, |v| v.get_name().to_string())
            );
            let report = baseline.stream(capture, sink)?;
            return Ok(Outcome::Baseline { method: self.method, report });
        }
        let (basis, options) = self.resolve()?;
        let options = DecodeOptions { progress, response, maps: self.maps, ..options };
        let report = decode_into(capture, &basis, &options, observer, sink)?;
        let p = &report.patches;
        if p.decoded == 0 {
            bail!(
                "no patch decoded ({} failed, {} of {} tiles failed): every patch saturated, defective or \
                 unreadable",
                p.failed,
                report.failed_tiles,
                report.tiles
            );
        }
        Ok(Outcome::Cs { options: Box::new(options), report: Box::new(report) })
    }
}

/// The shape of the light field a decode of `capture` makes: its views and lenslets, a band
/// per filter type.
pub fn output_shape(capture: &Capture) -> RowShape {
    let d = &capture.description;
    RowShape { views: (d.views[0], d.views[1]), rows: d.lenslets[0], cols: d.lenslets[1], bands: d.bands_nm.len() }
}

impl Decoded {
    /// A warning when more than [`WARN_FRACTION`] of the patches failed or were flagged, or
    /// a tile failed ([`Outcome::warning`]).
    pub fn warning(&self) -> Option<String> {
        self.outcome.warning()
    }
}

impl Outcome {
    /// A warning when more than [`WARN_FRACTION`] of the patches failed or were flagged, or
    /// a tile failed.
    pub fn warning(&self) -> Option<String> {
        let Outcome::Cs { report: r, .. } = self else { return None };
        let p = &r.patches;
        let all = p.decoded + p.failed;
        ((p.failed + p.flagged) as f64 > WARN_FRACTION * f64::from(all) || r.failed_tiles > 0).then(|| {
            format!(
                "{} of {all} patches failed and {} were flagged (pixels left out), {} tiles failed",
                p.failed, p.flagged, r.failed_tiles
            )
        })
    }
}

/// A decode warns when more than this fraction of patches failed or were flagged.
pub const WARN_FRACTION: f64 = 0.01;
