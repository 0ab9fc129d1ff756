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

use core::ops::AddAssign;

use crate::decode::tile::{NoSeed, PatchOrigin, SHEAR_MARGIN, TileDecoder, TileSource};
use crate::operators::shape::Shape;
use crate::sensor::mask::MaskFamily;
use crate::solver::choice::PatchModel;
use crate::solver::holdout::HoldOut;
use crate::solver::interpolate::bands_measured;
use crate::solver::picked::Pick;
use crate::solver::workspace::Workspace;

/// Two held-out error estimates compared over the same pilot patches: the statistic both
/// trials decide by ([`ModelTrial`], [`ShearTrial`]). `first` and `second` are the sums of
/// the two sides' squared estimates (sensor units) over the pilots both estimated, and
/// `spread` the sum of the squares of their differences pilot by pilot (what says when the
/// sums tie, [`Self::tied`]). Which side is which is the trial's: its own type names them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairedErrors {
    /// The first side's squared estimates, summed.
    pub first: f32,
    /// The second side's.
    pub second: f32,
    /// The squared differences of the two, pilot by pilot, summed.
    pub spread: f32,
    /// Pilot patches counted.
    pub pilots: u32,
}

/// The model trial's pilots: the first model's errors against the second's
/// ([`TileDecoder::trial`]; every decode orders them the DCT first, the screened ensemble
/// second, as [`tie_prior`] reads them), and the solves the pilots spent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelTrial {
    /// `first`: the first model's; `second`: the second's.
    pub errors: PairedErrors,
    /// Solves the pilots ran, counted as they ran (those of a pilot that gave no estimate
    /// too).
    pub solves: u32,
}

/// The shear trial's pilots: the errors at a block's half-pixel disparity against those at
/// the better of the whole ones beside it ([`TileDecoder::shear_trial`]), and the solves the
/// pilots spent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShearTrial {
    /// `first`: at the half-pixel disparity; `second`: at the better whole one.
    pub errors: PairedErrors,
    /// Solves the pilots ran, counted as they ran.
    pub solves: u32,
}

impl ShearTrial {
    /// The squared errors at the half-pixel disparities, summed over the pilots.
    pub fn half(&self) -> f32 {
        self.errors.first
    }

    /// The squared errors at the better whole disparities, summed over the pilots.
    pub fn whole(&self) -> f32 {
        self.errors.second
    }

    /// Whether the frame's half-pixel shears alias: the whole disparities' errors below
    /// [`SHEAR_MARGIN`] times the half ones' (RMS over the pilots together), the shear
    /// check's margin on the frame's pilots; the trial's margin rule is the model trial's
    /// ([`PairedErrors::pick_leaning`], leaning to the half disparities).
    pub fn aliases(&self) -> bool {
        self.errors.pick_leaning(Pick::First, SHEAR_MARGIN) == Pick::Second
    }
}

impl AddAssign for PairedErrors {
    /// Another set of pilots' errors added (a region's pilots together).
    fn add_assign(&mut self, other: Self) {
        self.first += other.first;
        self.second += other.second;
        self.spread += other.spread;
        self.pilots += other.pilots;
    }
}

impl AddAssign for ModelTrial {
    fn add_assign(&mut self, other: Self) {
        self.errors += other.errors;
        self.solves += other.solves;
    }
}

impl AddAssign for ShearTrial {
    fn add_assign(&mut self, other: Self) {
        self.errors += other.errors;
        self.solves += other.solves;
    }
}

/// How many standard errors apart the two sums of a trial must be for it to tell the
/// models apart ([`PairedErrors::tied`]): about the 95 % level of a two-sided test on the
/// pilots' paired differences.
pub const TIE_SPREAD: f32 = 2.0;

/// Whether a frame of `family` at `snapshots` is better decoded by the DCT than by the
/// screened ensemble where the model trial's pilots cannot tell them apart
/// ([`PairedErrors::tied`]); `None` where the sets favour neither, and the lower sum
/// decides as before.
///
/// From the decodes by each model alone of 21 scenes (18 synthetic at 48 x 48 lenslets
/// and 3 real crops, `docs/results-trial-by-decode.md`): at pixel k = 1 the ensemble was
/// within 0.1 dB of the better on all but 4, the DCT on all but 9; at pixel k = 3 the DCT
/// on all but 5, the ensemble on all but 13; at lenslet k = 3 the ensemble on all but 3,
/// the DCT on all but 17. The more a block measures, the less the learned members' prior
/// helps; snapshot counts not measured take the nearest measured one's side. At kronecker
/// k = 3 the DCT was within 0.1 dB on all but 4 there, but on a second set (the synthetic
/// scenes at 60 x 60, seed 2, `docs/results-model-tie.md`) the DCT on ties lost 0.1 dB or
/// more on 7 of 16 where the lower sum lost on 3: no prior there.
pub fn dct_where_tied(family: MaskFamily, snapshots: usize) -> Option<bool> {
    match family {
        MaskFamily::Pixel => Some(snapshots > 1),
        MaskFamily::Lenslet => Some(false),
        MaskFamily::Kronecker => None,
    }
}

/// [`dct_where_tied`] as the trial's pick: the DCT is the first model of the model trial
/// and the ensemble its second, as every caller of [`TileDecoder::trial`] orders them.
pub fn tie_prior(family: MaskFamily, snapshots: usize) -> Option<Pick> {
    dct_where_tied(family, snapshots).map(|dct| if dct { Pick::First } else { Pick::Second })
}

impl PairedErrors {
    /// One pilot's errors: `first` and `second` are the two models' squared estimates.
    pub fn one(first: f32, second: f32) -> Self {
        let d = first - second;
        Self { first, second, spread: d * d, pilots: 1 }
    }

    /// Whether the two sums are within [`TIE_SPREAD`] standard errors of their difference,
    /// taken from the pilots' paired differences (`n` pilots, differences `d_i`, sum `D`:
    /// the sum's variance is `n (sum d_i^2 - D^2 / n) / (n - 1)`). Fewer than two pilots
    /// cannot tell: tied.
    pub fn tied(&self) -> bool {
        if self.pilots < 2 {
            return true;
        }
        let n = self.pilots as f32;
        let d = self.first - self.second;
        let var = (self.spread - d * d / n).max(0.0) * n / (n - 1.0);
        d * d <= TIE_SPREAD * TIE_SPREAD * var
    }

    /// The model whose pilots erred less, unless the two tie ([`Self::tied`]) and there is
    /// a `prior`, the one a frame of this mask and snapshot count is better decoded by
    /// where the pilots cannot tell ([`dct_where_tied`]); without one, the lower sum (the
    /// second on an equal one, as [`Self::pick`]). Without a pilot (a response in the
    /// projection, too few bands) nothing was measured and the second decodes, as
    /// [`Self::pick`] has it: the prior was read from frames the pilots could estimate.
    pub fn pick_unless_tied(&self, prior: Option<Pick>) -> Pick {
        match prior {
            Some(p) if self.takes_prior(prior) => p,
            _ => self.pick(),
        }
    }

    /// Whether [`Self::pick_unless_tied`] with `prior` takes the prior: there is one, a
    /// pilot was measured, and the sums tie.
    pub fn takes_prior(&self, prior: Option<Pick>) -> bool {
        prior.is_some() && self.pilots > 0 && self.tied()
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

impl<S: Shape> TileDecoder<'_, S> {
    /// The model trial on the block at lenslet `(row, col)`: its first window's patch,
    /// sheared as the decode shears it, decoded by `first` and by `second` from
    /// [`HoldOut::DEFAULT`]'s measurements; their held-out errors as one pilot (no pilot
    /// where either cannot estimate: too few bands measured, a mixing response, a failed
    /// solve), and the solves both decodes ran. `ws` is clobbered.
    ///
    /// # Errors
    /// The source's error.
    pub fn trial<A, Z, Src>(
        &self,
        first: &A,
        second: &Z,
        (row, col): (u16, u16),
        source: &mut Src,
        ws: &mut Workspace<S>,
    ) -> Result<ModelTrial, Src::Error>
    where
        A: PatchModel<S>,
        Z: PatchModel<S>,
        Src: TileSource,
    {
        let none = ModelTrial::default();
        let Some((view_row, view_col)) = self.windows().next() else { return Ok(none) };
        let disparity = self.choose_disparity(row as usize, col as usize, source)?;
        let origin = PatchOrigin { lenslet_row: row, lenslet_col: col, view_row, view_col, disparity };
        self.read_patch(origin, source, ws)?;
        if bands_measured::<S>(ws.measurements()) < u32::from(self.config().sl0.min_bands) {
            return Ok(none);
        }
        let (a, solves_a) =
            self.estimate_error::<_, _, NoSeed>(first, &HoldOut::DEFAULT, (origin, None), source, ws, true)?;
        // The estimate read the patch again: the same held-out measurements for the second.
        let (z, solves_z) =
            self.estimate_error::<_, _, NoSeed>(second, &HoldOut::DEFAULT, (origin, None), source, ws, true)?;
        let errors = match (a, z) {
            (Some(a), Some(z)) => PairedErrors::one(a * a, z * z),
            _ => PairedErrors::default(),
        };
        Ok(ModelTrial { errors, solves: u32::from(solves_a) + u32::from(solves_z) })
    }

    /// The shear trial on the block at lenslet `(row, col)`: where its views agree best at a
    /// half-pixel disparity ([`Self::choose_disparity`]), the held-out error estimates of its
    /// first window's patch at that disparity and at the better of the whole ones beside it,
    /// as one pilot, by `model`'s estimating solve as the shear check's
    /// ([`TileDecoder::with_shear_check`]), and the solves they ran; no pilot at a whole
    /// disparity. Summed over a frame's pilots, they say whether its half-pixel shears alias
    /// ([`ShearTrial::aliases`]). `ws` is clobbered.
    ///
    /// # Errors
    /// The source's error.
    pub fn shear_trial<M: PatchModel<S>, Src: TileSource>(
        &self,
        model: &M,
        (row, col): (u16, u16),
        source: &mut Src,
        ws: &mut Workspace<S>,
    ) -> Result<ShearTrial, Src::Error> {
        let half = self.choose_disparity(row as usize, col as usize, source)?;
        if half.is_whole() {
            return Ok(ShearTrial::default());
        }
        let ([(_, at_half), (_, below), (_, above)], solves) =
            self.shear_errors(model, (row, col), half, source, ws)?;
        let whole = match (below, above) {
            (Some(b), Some(a)) => Some(b.min(a)),
            (b, a) => b.or(a),
        };
        let errors = match (at_half, whole) {
            (Some(h), Some(w)) => PairedErrors::one(h * h, w * w),
            _ => PairedErrors::default(),
        };
        Ok(ShearTrial { errors, solves })
    }
}
