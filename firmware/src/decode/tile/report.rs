//! What a tile decode reports: a patch's flags and report, a tile's and a frame's counts,
//! and the decoder's errors.

use core::fmt;

use crate::sensor::raw::Invalid;
use crate::solver::sl0::{Outcome, SolveError};

use super::Tile;

/// Why samples of a patch were left out, as bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatchFlags(u8);

impl PatchFlags {
    /// A pixel of the defect list.
    pub const DEFECTIVE: Self = Self(1);
    /// A NaN or infinite sample.
    pub const NON_FINITE: Self = Self(2);
    /// A negative raw sample.
    pub const NEGATIVE: Self = Self(4);
    /// A sample above `max_valid` (saturated).
    pub const OVER_RANGE: Self = Self(8);

    /// Whether every bit of `other` is set.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// No flag set: every sample of the patch was a measurement.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The raw bits.
    pub fn bits(self) -> u8 {
        self.0
    }

    pub(super) fn insert(&mut self, other: Self) {
        self.0 |= other.0;
    }
}

impl From<Invalid> for PatchFlags {
    fn from(i: Invalid) -> Self {
        match i {
            Invalid::NonFinite => Self::NON_FINITE,
            Invalid::Negative => Self::NEGATIVE,
            Invalid::OverRange => Self::OVER_RANGE,
        }
    }
}

/// What happened to one decoded patch.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PatchReport {
    /// How the (last) solve ended.
    pub outcome: Outcome,
    /// The ensemble member used (none for a single dictionary).
    pub member: Option<u16>,
    /// Solves the patch cost.
    pub solves: u16,
    /// Why samples were left out, if any were.
    pub flags: PatchFlags,
    /// Samples used as measurements.
    pub measured: u16,
    /// Samples left out.
    pub excluded: u16,
    /// An unsheared estimate of a block that was decoded sheared at the frame's edge: it
    /// is only there for the views no sheared patch reached, and a sink weighs it by
    /// [`crate::operators::disparity::FALLBACK_WEIGHT`].
    pub fallback: bool,
    /// What the plausibility check ([`crate::solver::plausible`]) did with the patch.
    pub checked: Checked,
    /// The patch's error estimate from held-out measurements ([`crate::solver::holdout`]):
    /// an RMS error per value in the output's units; `None` unless the decoder estimates
    /// ([`TileDecoder::with_error_estimate`](super::TileDecoder::with_error_estimate)), and for patches it cannot estimate
    /// (interpolated, or too few measurements to hold any out).
    pub error: Option<f32>,
}

/// What the plausibility check did with a decoded patch ([`TileDecoder::with_plausibility`](super::TileDecoder::with_plausibility)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Checked {
    /// Every value within its pixel's bound (or the check is off, the patch was not solved
    /// (interpolated or flat), or saturated samples were left out of it: its light is
    /// brighter than its measurements say).
    #[default]
    Plausible,
    /// The model's decode broke the bounds; the patch was decoded again by the safe path
    /// (the DCT's hand-set schedule from the minimum-norm start), which kept within them.
    Redecoded,
    /// The safe path broke them too: its values above a bound were set to the bound.
    Clipped,
}

/// Counts for one tile or frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TileReport {
    /// Patches decoded and accepted by the sink.
    pub decoded: u32,
    /// Of those, patches with samples left out.
    pub flagged: u32,
    /// Patches that could not be decoded (rejected to the sink).
    pub failed: u32,
    /// Of the decoded, patches that measured fewer than [`Sl0Config::min_bands`](crate::solver::sl0::Sl0Config::min_bands) bands and
    /// were interpolated per pixel ([`Ended::Interpolated`](crate::solver::sl0::Ended::Interpolated)), not solved: a user reads
    /// which decoder made their pixels.
    pub interpolated: u32,
    /// Of the decoded, patches flat within [`Sl0Config::flat`](crate::solver::sl0::Sl0Config::flat), each band its mean
    /// ([`Ended::Flat`](crate::solver::sl0::Ended::Flat)), not solved.
    pub flat: u32,
    /// Of the decoded, patches whose model's decode broke the plausibility check and was
    /// replaced ([`Checked::Redecoded`] or [`Checked::Clipped`]).
    pub implausible: u32,
    /// Of those, patches whose safe decode broke it too and was clipped to the bounds.
    pub clipped: u32,
}

impl TileReport {
    /// Adds another tile's counts (a frame's report is its tiles' sum).
    pub fn add(&mut self, o: &Self) {
        self.decoded += o.decoded;
        self.flagged += o.flagged;
        self.failed += o.failed;
        self.interpolated += o.interpolated;
        self.flat += o.flat;
        self.implausible += o.implausible;
        self.clipped += o.clipped;
    }

    /// Patches solved by SL0: the decoded less the interpolated and the flat.
    pub fn solved(&self) -> u32 {
        self.decoded.saturating_sub(self.interpolated).saturating_sub(self.flat)
    }
}

/// Errors of the tile layer: decoder set-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// The mask's lenslet size differs from the sensor's.
    LensletMismatch,
    /// The patch has more views than a lenslet.
    PatchViews,
    /// The mask's band count differs from the patch type's `B`.
    BandMismatch,
    /// A kronecker mask whose block is not the patch type's `PS x PT`.
    BlockMismatch,
    /// The raw format cannot normalise (not finite, or `white <= black`).
    RawFormat,
    /// The solver config is out of range.
    Solver(SolveError),
    /// An overlap stride outside `1..=` the patch's size.
    Stride,
    /// Band gains outside `[1 / MAX_RATIO, MAX_RATIO]`.
    Gains,
    /// A response matrix that mixes bands on a kronecker mask (whose general path is for
    /// selections).
    Response,
    /// A flat field per view whose length is not the lenslet's views, or with a gain
    /// outside `[1 / MAX_RATIO, MAX_RATIO]`.
    ViewGains,
    /// A plausibility bound with a factor below 1, a negative margin, or a NaN.
    Plausibility,
    /// Held-out measurements of a fold below 2.
    HoldOut,
    /// A lenslet grid of other views than the sensor's, or on a lenslet or kronecker mask.
    Grid,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::LensletMismatch => f.write_str("mask and sensor disagree on the lenslet size"),
            Self::PatchViews => f.write_str("patch has more views than a lenslet"),
            Self::BandMismatch => f.write_str("mask and patch disagree on the band count"),
            Self::BlockMismatch => f.write_str("kronecker mask block differs from the patch's lenslets"),
            Self::RawFormat => f.write_str("raw format: need finite levels with white > black"),
            Self::Solver(e) => write!(f, "solver: {e}"),
            Self::Stride => f.write_str("overlap stride must be in 1..=patch size per axis"),
            Self::Gains => f.write_str("band gains must each be in [1/64, 64]"),
            Self::Response => f.write_str("a response matrix that mixes bands needs a pixel or lenslet mask"),
            Self::Grid => f.write_str("a lenslet grid needs a pixel mask and the sensor's views"),
            Self::ViewGains => f.write_str("view gains: one per view of a lenslet, each in [1/64, 64]"),
            Self::Plausibility => f.write_str("plausibility bound: factor >= 1 and margin >= 0"),
            Self::HoldOut => f.write_str("held-out measurements: one in 2 or more"),
        }
    }
}

impl core::error::Error for ConfigError {}

/// Errors of one tile decode. The patches delivered before it stay delivered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TileError<S, K> {
    /// The tile is empty, not made of whole patches, or outside the sensor.
    Geometry,
    /// The source failed; the rest of the tile was not decoded.
    Source(S),
    /// The sink failed; the rest of the tile was not decoded.
    Sink(K),
}

impl<S: fmt::Debug, K: fmt::Debug> fmt::Display for TileError<S, K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Geometry => f.write_str("tile is not whole patches inside the sensor"),
            Self::Source(e) => write!(f, "tile source failed: {e:?}"),
            Self::Sink(e) => write!(f, "patch sink failed: {e:?}"),
        }
    }
}

impl<S: fmt::Debug, K: fmt::Debug> core::error::Error for TileError<S, K> {}

/// Counts for a frame, and the first tile that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameReport<S, K> {
    /// Patch counts over all tiles.
    pub patches: TileReport,
    /// Tiles attempted.
    pub tiles: u32,
    /// Tiles abandoned by a source or sink error.
    pub failed_tiles: u32,
    /// The first abandoned tile and why.
    pub first_failure: Option<(Tile, TileError<S, K>)>,
}
