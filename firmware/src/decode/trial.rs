//! The model trial: which of two models decodes a region, chosen by how well each predicts
//! measurements it was not given.
//!
//! Every choice a model makes inside a patch (the ensemble's member, by the solution's
//! sparsity) is blind to the truth: a sparser solution is not a nearer one, and the screened
//! ensemble measured below the DCT alone on most scenes at pixel k = 3 while above it on
//! others. Held-out measurements are not blind ([`crate::solver::holdout`]): on a pilot
//! patch, both models decode from all but one measurement in eight, and the one whose
//! predictions of the held-out ones err less decodes the region. The pick is made on a few
//! pilots a region, so it costs a fraction of a solve a patch (each pilot: the first model's
//! decode and the second's, from the held-out measurements), and every other patch is
//! decoded once, by the picked model ([`crate::solver::picked::Picked`]).

use crate::decode::tile::{PatchOrigin, TileDecoder, TileSource};
use crate::solver::choice::PatchModel;
use crate::solver::holdout::HoldOut;
use crate::solver::interpolate::bands_measured;
use crate::solver::picked::Pick;
use crate::solver::workspace::Workspace;

/// What pilot patches measured of two models: the sums of their squared held-out error
/// estimates (sensor units), over the pilots both estimated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrialErrors {
    /// The first model's squared estimates, summed.
    pub first: f32,
    /// The second model's.
    pub second: f32,
    /// Pilot patches counted.
    pub pilots: u32,
}

impl TrialErrors {
    /// These errors and `other`'s, summed (a region's pilots together).
    pub fn add(&mut self, other: &Self) {
        self.first += other.first;
        self.second += other.second;
        self.pilots += other.pilots;
    }

    /// The model whose pilots erred less; the second (the decode's default) without pilots
    /// or on a tie.
    pub fn pick(&self) -> Pick {
        self.pick_leaning(Pick::Second, 1.0)
    }

    /// The model `towards` unless the other's pilots erred below `margin` times its
    /// (RMS over the pilots); `towards` without pilots ([`Self::pick`] is
    /// `pick_leaning(Pick::Second, 1.0)`). A decode that must stay cheap leans to its cheap model and pays
    /// for the other only where the pilots say it clearly predicts better.
    pub fn pick_leaning(&self, towards: Pick, margin: f32) -> Pick {
        let (kept, other) = match towards {
            Pick::First => (self.first, self.second),
            Pick::Second => (self.second, self.first),
        };
        let leave = self.pilots > 0 && other < margin * margin * kept;
        match (towards, leave) {
            (Pick::First, true) | (Pick::Second, false) => Pick::Second,
            (Pick::First, false) | (Pick::Second, true) => Pick::First,
        }
    }
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    TileDecoder<'_, PS, PT, PU, PV, B, N>
{
    /// The model trial on the block at lenslet `(row, col)`: its first window's patch,
    /// sheared as the decode shears it, decoded by `first` and by `second` from
    /// [`HoldOut::DEFAULT`]'s measurements; their held-out errors as one pilot (no pilot
    /// where either cannot estimate: too few bands measured, a mixing response, a failed
    /// solve). `ws` is clobbered.
    ///
    /// # Errors
    /// The source's error.
    pub fn trial<A, Z, S>(
        &self,
        first: &A,
        second: &Z,
        (row, col): (u16, u16),
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<TrialErrors, S::Error>
    where
        A: PatchModel<PS, PT, PU, PV, B, N>,
        Z: PatchModel<PS, PT, PU, PV, B, N>,
        S: TileSource,
    {
        let none = TrialErrors::default();
        let Some((view_row, view_col)) = self.windows().next() else { return Ok(none) };
        let disparity = self.choose_disparity(row as usize, col as usize, source)?;
        let origin = PatchOrigin { lenslet_row: row, lenslet_col: col, view_row, view_col, disparity };
        self.read_patch(origin, source, ws)?;
        if bands_measured::<B, N>(ws.measurements()) < u32::from(self.config().sl0.min_bands) {
            return Ok(none);
        }
        let (a, _) = self.estimate_error(first, &HoldOut::DEFAULT, origin, source, ws, true)?;
        // The estimate read the patch again: the same held-out measurements for the second.
        let (z, _) = self.estimate_error(second, &HoldOut::DEFAULT, origin, source, ws, true)?;
        Ok(match (a, z) {
            (Some(a), Some(z)) => TrialErrors { first: a * a, second: z * z, pilots: 1 },
            _ => none,
        })
    }

    /// The shear trial on the block at lenslet `(row, col)`: where its views agree best at a
    /// half-pixel disparity ([`Self::choose_disparity`]), the held-out error estimates of its
    /// first window's patch at that disparity (`first`) and at the better of the whole ones
    /// beside it (`second`), as one pilot, by the model's estimating solve as the shear
    /// check's ([`TileDecoder::with_shear_check`]); no pilot at a whole disparity. Summed
    /// over a frame's pilots, they say whether its half-pixel shears alias. `ws` is clobbered.
    ///
    /// # Errors
    /// The source's error.
    pub fn shear_trial<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource>(
        &self,
        model: &M,
        (row, col): (u16, u16),
        source: &mut S,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<TrialErrors, S::Error> {
        let half = self.choose_disparity(row as usize, col as usize, source)?;
        if half.is_whole() {
            return Ok(TrialErrors::default());
        }
        let [(_, at_half), (_, below), (_, above)] = self.shear_errors(model, (row, col), half, source, ws)?;
        let whole = match (below, above) {
            (Some(b), Some(a)) => Some(b.min(a)),
            (b, a) => b.or(a),
        };
        Ok(match (at_half, whole) {
            (Some(h), Some(w)) => TrialErrors { first: h * h, second: w * w, pilots: 1 },
            _ => TrialErrors::default(),
        })
    }
}
