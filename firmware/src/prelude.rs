//! The front door: what an integrator needs to decode frames, in one `use`.
//!
//! ```
//! use slf_firmware::prelude::*;
//! ```
//!
//! brings the tile decoder and its configuration, the frame sources, the patch sink, the
//! shipped ensemble, the workspace, the error types, and names for the paper's patch
//! (5 x 5 lenslets x 4 x 4 views x 13 bands, 5,200 values) so that no code repeats
//! `5, 5, 4, 4, 13, 5200`. The solver's and the operators' internals (transforms, the
//! projection, the blob writer, the paper's pseudo-inverse path) stay in their modules.

use core::fmt;

pub use crate::decode::overlap::{Overlap, OverlapDecoder, OverlapError, OverlapReport, RowSink, Window};
pub use crate::decode::tile::{
    ConfigError, DecoderConfig, FrameReport, PatchOrigin, PatchReport, PatchSink, SensorGeometry, Tile, TileDecoder,
    TileError, TileReport, TileSource,
};
pub use crate::operators::blob::{DEFAULT_ENSEMBLE, DEFAULT_FULL_VIEW_ENSEMBLE, Ensemble};
pub use crate::operators::dictionary::{Dictionary, DictionaryError};
pub use crate::operators::disparity::{Disparity, DisparityRange};
pub use crate::operators::shape::{FullViewShape, PaperShape, PatchShape, PerValue, Shape};
pub use crate::sensor::defects::{DefectList, Pixel};
pub use crate::sensor::extent::{Array, Fixed};
pub use crate::sensor::mask::{BandTile, LensletSize, Mask, MaskFamily, SensingError};
pub use crate::sensor::raw::{FrameSource, LeU16Frame, RawFormat, RawFrame};
pub use crate::sensor::spi::{SpiFrameBuffer, SpiSourceError};
pub use crate::solver::choice::{ChoiceRule, EnsembleModel, MemberChoice, PatchModel};
pub use crate::solver::sl0::{Ended, Outcome, Sl0Config, SolveError};
pub use crate::solver::workspace::{FullViewWorkspace, PaperWorkspace, Workspace};

/// Values in the paper's patch: 5 x 5 x 4 x 4 x 13.
pub const PAPER_N: usize = 5200;

/// One decoded patch of the paper's shape, in `(s, t, u, v, band)` order, band fastest.
pub type PaperPatch = [f32; PAPER_N];

/// The tile decoder for the paper's patch.
pub type PaperDecoder<'a> = TileDecoder<'a, PaperShape>;

/// The overlapped decoder for the paper's patch.
pub type PaperOverlapDecoder<'a> = OverlapDecoder<'a, PaperShape>;

/// A dictionary (one member, or the 5D DCT) of the paper's patch.
pub type PaperDictionary = Dictionary<PaperShape>;

/// An ensemble blob of the paper's patch, validated.
pub type PaperEnsemble<'a> = Ensemble<'a, PaperShape>;

/// An ensemble with its member choice, for the paper's patch.
pub type PaperEnsembleModel<'a> = EnsembleModel<'a, PaperShape>;

/// Values in the full-view patch: 5 x 5 x 5 x 5 x 13, every view of a 5 x 5-view lenslet.
pub const FULL_VIEW_N: usize = 8125;

/// One decoded full-view patch, in `(s, t, u, v, band)` order, band fastest.
pub type FullViewPatch = [f32; FULL_VIEW_N];

/// The tile decoder for the full-view patch.
pub type FullViewDecoder<'a> = TileDecoder<'a, FullViewShape>;

/// The overlapped decoder for the full-view patch.
pub type FullViewOverlapDecoder<'a> = OverlapDecoder<'a, FullViewShape>;

/// A dictionary (one member, or the 5D DCT) of the full-view patch.
pub type FullViewDictionary = Dictionary<FullViewShape>;

/// An ensemble blob of the full-view patch, validated
/// ([`crate::DEFAULT_FULL_VIEW_ENSEMBLE`] is the shipped one).
pub type FullViewEnsemble<'a> = Ensemble<'a, FullViewShape>;

/// An ensemble with its member choice, for the full-view patch: the device's default model.
pub type FullViewEnsembleModel<'a> = EnsembleModel<'a, FullViewShape>;

/// What can go wrong while setting a decoder up, so that set-up code can use `?` across
/// layers. Decoding itself reports per tile and per patch ([`TileError`], [`TileReport`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SetupError {
    /// A mask, band tile, raw frame or defect list was refused.
    Sensing(SensingError),
    /// The decoder configuration was refused.
    Config(ConfigError),
    /// A dictionary blob was refused.
    Dictionary(DictionaryError),
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sensing(e) => write!(f, "sensing: {e}"),
            Self::Config(e) => write!(f, "decoder: {e}"),
            Self::Dictionary(e) => write!(f, "dictionary: {e}"),
        }
    }
}

impl core::error::Error for SetupError {}

impl From<SensingError> for SetupError {
    fn from(e: SensingError) -> Self {
        Self::Sensing(e)
    }
}

impl From<ConfigError> for SetupError {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}

impl From<DictionaryError> for SetupError {
    fn from(e: DictionaryError) -> Self {
        Self::Dictionary(e)
    }
}
