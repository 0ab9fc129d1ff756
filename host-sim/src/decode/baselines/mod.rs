//! Baselines: decode methods without compressed sensing, the yardsticks a user would pick
//! instead of CS.
//!
//! All read a capture's measurements exactly as the CS decoder does
//! ([`measurements`]) and put the light field `(U, V, S, T, B)` a lenslet row at a time
//! into a row sink, as the CS decode does: each holds a window of lenslet rows
//! ([`lagged`]) as tall as its neighbourhood needs, never the frame, so its memory does not
//! grow with the frame's height (the output's file is written as the rows come).
//!
//! - [`interpolate()`]: per pixel, the spectrum interpolated linearly in band index between
//!   the bands that pixel measured, held constant beyond the first and last. At one
//!   snapshot a pixel measures one band, so its spectrum is flat: what a camera without
//!   any spatial reasoning would give.
//! - [`demosaic()`]: each band estimated from the pixels that measured it nearby, all views
//!   of the lenslets within [`DemosaicConfig::radius`] lenslets weighted by a Gaussian of
//!   the lenslet distance ([`neighbourhood`]), matched to each pixel's own measurements.
//! - [`ppid()`]: the published multispectral demosaicking method of Mihoubi et al. (2017),
//!   by the pseudo-panchromatic image, adapted to a random filter array spread over views.
//!
//! Every baseline's output is clamped to the sensor's physical range, as the CS decode's
//! is: `0` (no light) to the brightest value a pixel can measure in normalised units
//! ([`slf_firmware::RawFormat::range`]).
//!
//! A pixel with no measurement (all its samples invalid) takes, in [`interpolate()`], the
//! mean spectrum of the measured pixels of its lenslet and the lenslets around it, and in
//! [`demosaic()`] and [`ppid()`] the neighbourhood's estimate; the report counts them.

mod demosaic;
mod interpolate;
mod lagged;
mod measurements;
mod neighbourhood;
mod ppid;

use anyhow::{Result, ensure};
pub use demosaic::DemosaicConfig;
pub use ppid::PpidConfig;

use self::measurements::{LensletRow, Reader};
use crate::io::capture::Capture;
use crate::io::lightfield::LightField;
use crate::io::rows::{RowShape, Rows, put_row};

/// A baseline decode method, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Baseline {
    /// [`interpolate()`].
    Interpolate,
    /// [`demosaic()`] with [`DemosaicConfig::default`].
    Demosaic,
    /// [`ppid()`] with [`PpidConfig::default`].
    Ppid,
}

impl Baseline {
    /// Every baseline, weakest first.
    pub const ALL: [Baseline; 3] = [Baseline::Interpolate, Baseline::Demosaic, Baseline::Ppid];

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Baseline::Interpolate => "baseline: per-pixel interpolation",
            Baseline::Demosaic => "baseline: neighbourhood demosaic",
            Baseline::Ppid => "baseline: PPID (Mihoubi et al. 2017)",
        }
    }

    /// Decodes `capture` with this baseline into memory.
    ///
    /// # Errors
    /// As [`Self::stream`], or a light field too large to hold.
    pub fn run(self, capture: &Capture) -> Result<(LightField, BaselineReport)> {
        in_memory(capture, |sink| self.stream(capture, sink))
    }

    /// Decodes `capture` with this baseline, putting each lenslet row into `sink` as it is
    /// made, in order.
    ///
    /// # Errors
    /// A capture whose mask cannot be built, one without a single measurement (after the
    /// last row), or what the sink returns.
    pub fn stream(self, capture: &Capture, sink: &mut Rows<'_>) -> Result<BaselineReport> {
        let start = std::time::Instant::now();
        let reader = Reader::new(capture)?;
        let mut report = match self {
            Baseline::Interpolate => interpolate::stream(&reader, sink),
            Baseline::Demosaic => demosaic::stream(&reader, &DemosaicConfig::default(), sink),
            Baseline::Ppid => ppid::stream(&reader, &PpidConfig::default(), sink),
        }?;
        report.seconds = start.elapsed().as_secs_f64();
        Ok(report)
    }
}

/// What a baseline did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaselineReport {
    /// Sensor positions (lenslet x view) with at least one measurement.
    pub measured: usize,
    /// Sensor positions with none, filled from their neighbourhood.
    pub filled: usize,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl BaselineReport {
    /// Counts a lenslet row's positions with and without a measurement.
    fn tally(&mut self, row: &LensletRow) {
        let (measured, filled) = row.measured_and_not();
        self.measured += measured;
        self.filled += filled;
    }

    /// # Errors
    /// No position of the whole frame held a measurement.
    fn ensure_measured(&self, reader: &Reader<'_>) -> Result<()> {
        ensure!(self.measured > 0, "{}: no pixel holds a measurement (all saturated or defective)", reader.source());
        Ok(())
    }
}

/// Puts a baseline's lenslet rows: each row clamped to the sensor's physical range (the
/// output contract of every decode method, the one the CS decoder keeps per patch: a
/// colour ratio or PPID's high-pass can push a value past what the sensor could have
/// recorded, and a measurement under the black level is below no light), from the
/// lenslet-major order the baselines compute in (`T x UV x B`) to a row's (`UV x T x B`).
struct Emit {
    shape: RowShape,
    range: (f32, f32),
    row: Vec<f32>,
}

impl Emit {
    fn new(reader: &Reader<'_>) -> Self {
        let shape =
            RowShape { views: reader.views, rows: reader.lenslets.0, cols: reader.lenslets.1, bands: reader.bands };
        Self { shape, range: reader.range(), row: vec![0.0; shape.row_len()] }
    }

    /// Puts lenslet row `s` of values `T x UV x B` into `sink`.
    fn row(&mut self, s: usize, lenslet_major: &[f32], sink: &mut Rows<'_>) -> Result<()> {
        let (uv, nb, lt) = (self.shape.views.0 * self.shape.views.1, self.shape.bands, self.shape.cols);
        let (lo, hi) = self.range;
        for (p, spectrum) in lenslet_major.chunks_exact(nb).enumerate() {
            let (t, k) = (p / uv, p % uv);
            let at = (k * lt + t) * nb;
            for (o, &x) in self.row[at..at + nb].iter_mut().zip(spectrum) {
                *o = x.clamp(lo, hi);
            }
        }
        put_row(sink, s, &self.row)
    }
}

/// A baseline streamed into a light field in memory, its size checked first.
fn in_memory(
    capture: &Capture,
    stream: impl FnOnce(&mut Rows<'_>) -> Result<BaselineReport>,
) -> Result<(LightField, BaselineReport)> {
    let mut lf = crate::decode::pipeline::output_shape(capture).zeros()?;
    let report = stream(&mut lf)?;
    Ok((lf, report))
}

/// Per-pixel spectral interpolation between the measured bands (see the module docs).
///
/// # Errors
/// A capture whose mask cannot be built, or one without a single measurement.
pub fn interpolate(capture: &Capture) -> Result<(LightField, BaselineReport)> {
    Baseline::Interpolate.run(capture)
}

/// Neighbourhood demosaic matched to each pixel's own measurements (see the module docs).
///
/// # Errors
/// A capture whose mask cannot be built, one without a single measurement, or settings out
/// of range.
pub fn demosaic(capture: &Capture, cfg: &DemosaicConfig) -> Result<(LightField, BaselineReport)> {
    in_memory(capture, |sink| demosaic::stream(&Reader::new(capture)?, cfg, sink))
}

/// PPID (Mihoubi et al. 2017; see [`ppid`](self::ppid) for the method and slf's
/// adaptation).
///
/// # Errors
/// A capture whose mask cannot be built, one without a single measurement, or settings out
/// of range.
pub fn ppid(capture: &Capture, cfg: &PpidConfig) -> Result<(LightField, BaselineReport)> {
    in_memory(capture, |sink| ppid::stream(&Reader::new(capture)?, cfg, sink))
}
