//! Two models, one of which decodes: the model trial's pick ([`crate::decode::trial`]).
//!
//! The pick is made once for a region of the frame (a tile, or the whole frame) from the
//! held-out errors of both models on a few pilot patches, then every patch of the region
//! is decoded by the picked model alone: no patch pays for both. [`Picked`] borrows both
//! models, so a pick per tile costs nothing but the flag.

use crate::operators::shape::Shape;
use crate::solver::choice::{ModelOutcome, PatchModel};
use crate::solver::sl0::{Sl0Config, SolveError};
use crate::solver::workspace::Workspace;

/// Which of two models.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Pick {
    /// The first (in the decode's use: the DCT with its trained schedules).
    First,
    /// The second (the screened ensemble).
    #[default]
    Second,
}

/// `first` or `second`, by `pick`: a [`PatchModel`] that decodes with the picked one.
#[derive(Clone, Copy, Debug)]
pub struct Picked<'m, A, Z> {
    pub first: &'m A,
    pub second: &'m Z,
    pub pick: Pick,
}

impl<S: Shape, A, Z> PatchModel<S> for Picked<'_, A, Z>
where
    A: PatchModel<S>,
    Z: PatchModel<S>,
{
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        match self.pick {
            Pick::First => self.first.decode(cfg, ws),
            Pick::Second => self.second.decode(cfg, ws),
        }
    }

    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        match self.pick {
            Pick::First => self.first.decode_seeded(cfg, ws),
            Pick::Second => self.second.decode_seeded(cfg, ws),
        }
    }

    fn estimating_solve(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<u16, SolveError> {
        match self.pick {
            Pick::First => self.first.estimating_solve(cfg, ws),
            Pick::Second => self.second.estimating_solve(cfg, ws),
        }
    }
}
