//! What the engine refuses ([`EngineError`]): a small `Copy` enum, as every layer's.

use core::fmt;

/// Why the engine refused a configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EngineError {
    /// Patch grids the engine cannot walk: a stride axis outside `1..=` the patch's size, an
    /// empty patch or tile, a patch over 64 lenslets or a halo over 64.
    Grids,
    /// A strip whose buffer is shorter than its shape needs, whose put columns are not inside
    /// its held ones, or that holds no row or no view.
    Strip,
    /// A tile's sums on slices shorter than the tile needs.
    TileSums,
}

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Grids => "patch grids: a stride outside 1..=the patch, an empty tile, or a patch or halo over 64",
            Self::Strip => "strip: a buffer shorter than its rows need, put columns outside the held ones, or no row",
            Self::TileSums => "tile sums: slices shorter than the tile needs",
        })
    }
}

impl core::error::Error for EngineError {}
