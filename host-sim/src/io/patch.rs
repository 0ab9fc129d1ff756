//! The patch the host decodes, named once: 5 x 5 lenslets x `PU x PV` views x 13 bands,
//! the firmware's [`PaperShape`] (4 x 4 views) or [`FullViewShape`] (5 x 5). The lenslets
//! and bands are read from those shapes; the views are the decode's setting
//! ([`crate::decode::options::PatchViews`]), and `N` follows from them. Every host type that
//! holds a patch is one of the aliases below, so no file spells the extents out.

use slf_firmware::schedule::{Schedule, Schedules, Weights};
use slf_firmware::{
    Dictionary, Ensemble, EnsembleModel, FullViewShape, PaperShape, PatchModel, PatchShape, ScheduledDictionary,
    TileDecoder, Workspace,
};

/// Lenslets along each side of the host's patch (the shapes' first two extents).
pub const LENSLETS: usize = PaperShape::DIMS[0];
/// Bands of the host's patch: the camera's filter types (the shapes' last extent).
pub const BANDS: usize = PaperShape::DIMS[4];

// Both of the host's patches have those lenslets and bands.
const _: () = assert!(
    PaperShape::DIMS[1] == LENSLETS
        && FullViewShape::DIMS[0] == LENSLETS
        && FullViewShape::DIMS[1] == LENSLETS
        && FullViewShape::DIMS[4] == BANDS
);

/// The host's patch shape with `PU x PV` views.
pub type HostShape<const PU: usize, const PV: usize, const N: usize> = PatchShape<LENSLETS, LENSLETS, PU, PV, BANDS, N>;
/// The firmware's tile decoder for the host's patch.
pub type HostDecoder<'a, const PU: usize, const PV: usize, const N: usize> =
    TileDecoder<'a, LENSLETS, LENSLETS, PU, PV, BANDS, N>;
/// The workspace of one of the host's patches.
pub type HostWorkspace<const PU: usize, const PV: usize, const N: usize> =
    Workspace<LENSLETS, LENSLETS, PU, PV, BANDS, N>;
/// A dictionary of the host's patch.
pub type HostDictionary<const PU: usize, const PV: usize> = Dictionary<LENSLETS, LENSLETS, PU, PV, BANDS>;
/// A dictionary with trained schedules, of the host's patch.
pub type HostScheduledDictionary<const PU: usize, const PV: usize> =
    ScheduledDictionary<LENSLETS, LENSLETS, PU, PV, BANDS>;
/// An ensemble blob of the host's patch.
pub type HostEnsemble<'a, const PU: usize, const PV: usize> = Ensemble<'a, LENSLETS, LENSLETS, PU, PV, BANDS>;
/// An ensemble with its member choice, of the host's patch.
pub type HostEnsembleModel<'a, const PU: usize, const PV: usize> = EnsembleModel<'a, LENSLETS, LENSLETS, PU, PV, BANDS>;
/// A trained schedule of the host's patch.
pub type HostSchedule<const PU: usize, const PV: usize> = Schedule<LENSLETS, LENSLETS, PU, PV, BANDS>;
/// The trained schedules of a blob of the host's patch.
pub type HostSchedules<const PU: usize, const PV: usize> = Schedules<LENSLETS, LENSLETS, PU, PV, BANDS>;
/// A schedule's penalty weights for the host's patch.
pub type HostWeights<const PU: usize, const PV: usize> = Weights<LENSLETS, LENSLETS, PU, PV, BANDS>;

/// A model that decodes the host's patch on any thread: the firmware's [`PatchModel`] for
/// these extents, `Sync` (every model is, through the blanket impl).
pub trait HostModel<const PU: usize, const PV: usize, const N: usize>:
    PatchModel<LENSLETS, LENSLETS, PU, PV, BANDS, N> + Sync
{
}

impl<const PU: usize, const PV: usize, const N: usize, M> HostModel<PU, PV, N> for M where
    M: PatchModel<LENSLETS, LENSLETS, PU, PV, BANDS, N> + Sync
{
}
