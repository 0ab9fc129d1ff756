//! Member choice: decoding a patch with a learned ensemble without paying K full solves.
//!
//! An [`EnsembleModel`] holds the ensemble (a validated blob in flash), the DCT to screen
//! with, and a [`MemberChoice`]:
//!
//! - **Exhaustive**: solve with every member, score each solution by a [`ChoiceRule`], then
//!   solve once more with the best member (K + 1 solves; the workspace holds one patch).
//! - **Screened**: solve once with the DCT, score that solution in every member (an
//!   analysis each, no solve), then solve once with the best member (2 solves).
//!
//! The raw SL0 residual is near zero for every member (each solution meets the
//! measurements), so it cannot rank them; the rules look at how sparse the solution is in
//! the member instead. Scoring analyses the solution in place, one fibre at a time, so no
//! buffer is added to the [`Workspace`].

use crate::blob::Ensemble;
use crate::dictionary::Dictionary;
use crate::shape::PatchShape;
use crate::sl0::{Outcome, Sl0Config, SolveError, solve};
use crate::transform::apply_in_place;
use crate::workspace::Workspace;

/// How sparse a solution is in a member; lower is sparser.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChoiceRule {
    /// Energy outside the `tau` largest coefficients, over the total energy.
    Residual { tau: u16 },
    /// The l1 norm of the coefficients.
    L1,
    /// How many coefficients exceed `threshold` in magnitude.
    Count { threshold: f32 },
}

impl ChoiceRule {
    /// The default: the relative residual after keeping the 5 % largest coefficients of
    /// the paper's patch (260 of 5200).
    pub const DEFAULT: Self = Self::Residual { tau: 260 };

    /// The rule's score of coefficients `s` (lower is sparser).
    pub fn score(&self, s: &[f32]) -> f32 {
        match *self {
            Self::L1 => s.iter().map(|x| x.abs()).sum(),
            Self::Count { threshold } => s.iter().filter(|x| x.abs() > threshold).count() as f32,
            Self::Residual { tau } => residual_outside_top(s, tau as usize),
        }
    }
}

/// Energy of `s` outside its `tau` largest magnitudes, relative to the total (0 for a zero
/// `s`). The threshold is found by bisection on the magnitude (bounded: 40 halvings), so
/// no sort and no buffer; ties at the threshold count as kept.
fn residual_outside_top(s: &[f32], tau: usize) -> f32 {
    let total: f32 = s.iter().map(|x| x * x).sum();
    if !(total > 0.0) || tau >= s.len() {
        return 0.0;
    }
    let count_above = |t: f32| s.iter().filter(|x| x.abs() > t).count();
    let (mut lo, mut hi) = (0.0f32, s.iter().fold(0.0f32, |m, x| m.max(x.abs())));
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if count_above(mid) > tau {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let outside: f32 = s.iter().filter(|x| x.abs() <= hi).map(|x| x * x).sum();
    outside / total
}

/// Which members are solved.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MemberChoice {
    /// Solve with every member, keep the best by the rule (K + 1 solves).
    Exhaustive(ChoiceRule),
    /// Solve with the DCT, pick the member that best represents that solution, solve once
    /// with it (2 solves).
    Screened(ChoiceRule),
}

/// What a model did with one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelOutcome {
    /// The final solve.
    pub outcome: Outcome,
    /// The ensemble member used, if the model is an ensemble.
    pub member: Option<u16>,
    /// Solves this patch cost.
    pub solves: u16,
}

/// Something that decodes the patch in a workspace: a single [`Dictionary`] or an
/// [`EnsembleModel`]. The tile decoder takes either.
pub trait PatchModel<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
{
    /// Decodes the patch whose measurements are in `ws` into `ws.patch()`.
    ///
    /// # Errors
    /// As [`solve`].
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<PS, PT, PU, PV, B, N>) -> Result<ModelOutcome, SolveError>;
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    PatchModel<PS, PT, PU, PV, B, N> for Dictionary<PS, PT, PU, PV, B>
{
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<PS, PT, PU, PV, B, N>) -> Result<ModelOutcome, SolveError> {
        let outcome = solve(self, cfg, ws)?;
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }
}

/// An ensemble with its member choice. Config: immutable, the blob stays in flash.
#[derive(Clone, Debug)]
pub struct EnsembleModel<'a, const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize> {
    ensemble: Ensemble<'a, PS, PT, PU, PV, B>,
    screen: Dictionary<PS, PT, PU, PV, B>,
    choice: MemberChoice,
}

impl<'a, const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize>
    EnsembleModel<'a, PS, PT, PU, PV, B>
{
    /// An ensemble that screens with the 5D DCT.
    pub fn new(ensemble: Ensemble<'a, PS, PT, PU, PV, B>, choice: MemberChoice) -> Self {
        Self { ensemble, screen: Dictionary::dct(), choice }
    }

    /// The ensemble.
    pub fn ensemble(&self) -> &Ensemble<'a, PS, PT, PU, PV, B> {
        &self.ensemble
    }

    /// The member choice.
    pub fn choice(&self) -> MemberChoice {
        self.choice
    }

    /// Scores the solution in `ws.patch()` in member `m` by `rule`, analysing a copy in the
    /// coefficient buffer in place.
    fn score<const N: usize>(
        &self,
        member: &Dictionary<PS, PT, PU, PV, B>,
        rule: &ChoiceRule,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> f32 {
        const { PatchShape::<PS, PT, PU, PV, B, N>::CHECK };
        ws.coeffs.copy_from_slice(&ws.signal);
        apply_in_place(member.analysis(), &mut ws.coeffs);
        rule.score(&ws.coeffs)
    }

    /// The best-scoring member for the solution in `ws.patch()`, over the members
    /// `solve_each` is given the chance to produce.
    fn best<const N: usize>(
        &self,
        rule: &ChoiceRule,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
        mut solve_each: impl FnMut(
            &Dictionary<PS, PT, PU, PV, B>,
            &mut Workspace<PS, PT, PU, PV, B, N>,
        ) -> Result<(), SolveError>,
    ) -> Result<u16, SolveError> {
        let mut best = (f32::INFINITY, 0u16);
        for k in 0..self.ensemble.len() {
            let member = self.ensemble.member(k).map_err(|_| SolveError::NoSuchMember)?;
            solve_each(&member, ws)?;
            let s = self.score(&member, rule, ws);
            if s < best.0 || k == 0 {
                best = (s, k as u16);
            }
        }
        Ok(best.1)
    }
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    PatchModel<PS, PT, PU, PV, B, N> for EnsembleModel<'_, PS, PT, PU, PV, B>
{
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<PS, PT, PU, PV, B, N>) -> Result<ModelOutcome, SolveError> {
        let k = self.ensemble.len() as u16;
        let (member, solves) = match self.choice {
            MemberChoice::Exhaustive(rule) => (self.best(&rule, ws, |m, ws| solve(m, cfg, ws).map(|_| ()))?, k + 1),
            MemberChoice::Screened(rule) => {
                solve(&self.screen, cfg, ws)?;
                (self.best(&rule, ws, |_, _| Ok(()))?, 2)
            }
        };
        let dict = self.ensemble.member(member as usize).map_err(|_| SolveError::NoSuchMember)?;
        let outcome = solve(&dict, cfg, ws)?;
        Ok(ModelOutcome { outcome, member: Some(member), solves })
    }
}
