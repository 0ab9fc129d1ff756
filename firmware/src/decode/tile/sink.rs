//! Where decoded patches go, and where a seeded patch's start comes from.

use core::fmt;

use crate::operators::shape::{PerValue, Shape};
use crate::solver::sl0::SolveError;

use super::PatchOrigin;
use super::report::PatchReport;

/// Where decoded patches go.
pub trait PatchSink<S: Shape> {
    /// A write failure. `Copy`, to travel in errors.
    type Error: Copy + fmt::Debug;

    /// A decoded patch (layout of [`Shape::index`]) at `origin`, with its report.
    ///
    /// # Errors
    /// The sink's own error; the decoder then abandons the current tile.
    fn accept(
        &mut self,
        origin: PatchOrigin,
        patch: &PerValue<S, f32>,
        report: &PatchReport,
    ) -> Result<(), Self::Error>;

    /// A patch that could not be decoded; the decoder goes on with the next one.
    ///
    /// # Errors
    /// The sink's own error; the decoder then abandons the current tile.
    fn reject(&mut self, origin: PatchOrigin, error: SolveError) -> Result<(), Self::Error> {
        let _ = (origin, error);
        Ok(())
    }
}

/// Where a seeded decode ([`TileDecoder::decode_tile_seeded`](super::TileDecoder::decode_tile_seeded)) finds its start: an
/// estimate of a patch from its overlapping neighbours' decode (on the host, the disjoint
/// grid's averaged decode of the frame; the device's strip does not seed, see
/// `docs/bench/README.md`).
pub trait PatchSeed<S: Shape> {
    /// Writes the estimate of the patch at `origin` into `patch`, in the layout a
    /// [`PatchSink`] receives (sensor units, each value at the pixel
    /// [`PatchOrigin::lenslet`] names; a value it names none of is not read); `false` if
    /// there is none. A patch without an estimate, or with a NaN or an infinity in it, is
    /// decoded from nothing.
    fn seed(&mut self, origin: PatchOrigin, patch: &mut PerValue<S, f32>) -> bool;

    /// The estimate of band `band` of view `view` (of the lenslet's views) of sensor lenslet
    /// `lenslet`, in the units of [`Self::seed`]; `None` where there is none (the default).
    /// Behind a lenslet grid the read takes a pixel's share of a cell outside its patch out
    /// of its measurement by it ([`crate::solver::workspace::CellShares::known_outside`]).
    fn cell(&mut self, lenslet: (usize, usize), view: (usize, usize), band: usize) -> Option<f32> {
        let _ = (lenslet, view, band);
        None
    }
}

/// No estimate anywhere: every patch decodes from nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoSeed;

impl<S: Shape> PatchSeed<S> for NoSeed {
    fn seed(&mut self, _: PatchOrigin, _: &mut PerValue<S, f32>) -> bool {
        false
    }
}
