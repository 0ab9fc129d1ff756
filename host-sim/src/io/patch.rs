//! The patch the host decodes, named once: 5 x 5 lenslets x `PU x PV` views x 13 bands,
//! the firmware's [`PaperShape`] (4 x 4 views) or [`FullViewShape`] (5 x 5). The lenslets
//! and bands are read from those shapes; the views are the decode's setting
//! ([`crate::decode::options::PatchViews`]), and `N` follows from them. Every host type that
//! holds a patch is one of the aliases below, so no file spells the extents out.

use slf_firmware::schedule::{Schedule, Schedules, Weights};
use slf_firmware::{
    Dictionary, Ensemble, EnsembleModel, Fixed, FullViewShape, PaperShape, PatchModel, PatchShape, ScheduledDictionary,
    Shape, TileDecoder, Workspace,
};

/// Lenslets along each side of the host's patch (the shapes' first two extents).
pub const LENSLETS: usize = PaperShape::PS;
/// Bands of the host's patch: the camera's filter types (the shapes' last extent).
pub const BANDS: usize = PaperShape::B;

// Both of the host's patches have those lenslets and bands.
const _: () = assert!(
    PaperShape::PT == LENSLETS
        && FullViewShape::PS == LENSLETS
        && FullViewShape::PT == LENSLETS
        && FullViewShape::B == BANDS
);

/// The bands of the host's patch, as the firmware's containers name them.
pub type HostBands = Fixed<BANDS>;

/// The host's patch shape with `PU x PV` views (and `N` values: stable Rust cannot compute
/// it in a type, and [`slf_firmware::Shape::CHECK`] refuses a wrong one). Every alias below
/// is a firmware type over it; with the extents as constants, its buffers are plain arrays
/// (`[f32; N]`, `[f32; BANDS]`) to host code.
pub type HostShape<const PU: usize, const PV: usize, const N: usize> = PatchShape<LENSLETS, LENSLETS, PU, PV, BANDS, N>;
/// The firmware's tile decoder for the host's patch.
pub type HostDecoder<'a, const PU: usize, const PV: usize, const N: usize> = TileDecoder<'a, HostShape<PU, PV, N>>;
/// The workspace of one of the host's patches.
pub type HostWorkspace<const PU: usize, const PV: usize, const N: usize> = Workspace<HostShape<PU, PV, N>>;
/// A dictionary of the host's patch.
pub type HostDictionary<const PU: usize, const PV: usize, const N: usize> = Dictionary<HostShape<PU, PV, N>>;
/// A dictionary with trained schedules, of the host's patch.
pub type HostScheduledDictionary<const PU: usize, const PV: usize, const N: usize> =
    ScheduledDictionary<HostShape<PU, PV, N>>;
/// An ensemble blob of the host's patch.
pub type HostEnsemble<'a, const PU: usize, const PV: usize, const N: usize> = Ensemble<'a, HostShape<PU, PV, N>>;
/// An ensemble with its member choice, of the host's patch.
pub type HostEnsembleModel<'a, const PU: usize, const PV: usize, const N: usize> =
    EnsembleModel<'a, HostShape<PU, PV, N>>;
/// A trained schedule of the host's patch.
pub type HostSchedule<const PU: usize, const PV: usize, const N: usize> = Schedule<HostShape<PU, PV, N>>;
/// The trained schedules of a blob of the host's patch.
pub type HostSchedules<const PU: usize, const PV: usize, const N: usize> = Schedules<HostShape<PU, PV, N>>;
/// A schedule's penalty weights for the host's patch.
pub type HostWeights<const PU: usize, const PV: usize, const N: usize> = Weights<HostShape<PU, PV, N>>;

/// A model that decodes the host's patch on any thread: the firmware's [`PatchModel`] for
/// these extents, `Sync` (every model is, through the blanket impl).
pub trait HostModel<const PU: usize, const PV: usize, const N: usize>: PatchModel<HostShape<PU, PV, N>> + Sync {}

impl<const PU: usize, const PV: usize, const N: usize, M> HostModel<PU, PV, N> for M where
    M: PatchModel<HostShape<PU, PV, N>> + Sync
{
}
