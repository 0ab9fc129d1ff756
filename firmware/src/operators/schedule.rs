//! The trained schedule: SL0 unrolled to a fixed number of steps, each with its own
//! learned parameters (DESIGN.md section 10, "a trained solve").
//!
//! The hand-set schedule of [`crate::solver::sl0`] anneals `sigma` by a fixed factor with `L`
//! steps a level from the start's largest coefficient down to `sigma_min`: 60 steps or more
//! a cold solve, whatever the patch. A [`Schedule`] names every step instead:
//!
//! - `sigma[t]`, as a fraction of the start's largest coefficient `sigma0 = max |S0|` (so
//!   one schedule serves a bright and a dark patch alike), never below the config's
//!   `sigma_min`;
//! - `mu[t]`, the step size, in (0, 2];
//! - the penalty's weights per coefficient group, separable: one number per index of each
//!   mode ([`Weights`], `PS + PT + PU + PV + B` numbers). The smoothed-l0 penalty of a
//!   coefficient `s` in group `i` is `1 - exp(-w_i s^2 / (2 sigma^2))`, `w_i` the product of
//!   its indices' weights: a group with a larger weight is pulled to zero from a larger
//!   magnitude (a threshold `sigma / sqrt(w_i)`), as ALISTA learns a threshold per layer.
//!   All ones is SL0's penalty.
//!
//! The step itself is SL0's: the ascent `s <- s - mu s exp(-w s^2 / (2 sigma^2))`
//! (the solver's `ascent::ascend_weighted`) and the projection onto the measurements, whose
//! adjoint is itself; this is what makes the parameters trainable by gradients through the
//! steps (the host's `train::schedule`). The operators stay the dictionaries: only these
//! few scalars are learned, so the device keeps its kernels.
//!
//! A blob carries three ([`Schedules`]): the screened choice's first solve from the
//! measurements alone, a solve from an estimate (another member's solution, or a seed from
//! the neighbours' decode), and a dictionary decoding alone.

use crate::operators::dictionary::DictionaryError;
use crate::operators::shape::{PerBand, Shape};
use crate::sensor::extent::{Extent, Per};

/// The most steps a schedule may hold: bounds every trained solve.
pub const MAX_STEPS: usize = 64;

/// The penalty's weights per coefficient group: one per index of each mode. A coefficient
/// at `[s, t, u, v, b]` weighs `s[s] * t[t] * u[u] * v[v] * b[b]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Weights<S: Shape> {
    pub s: Per<S::S, f32>,
    pub t: Per<S::T, f32>,
    pub u: Per<S::U, f32>,
    pub v: Per<S::V, f32>,
    pub b: PerBand<S, f32>,
}

impl<S: Shape> Weights<S> {
    /// Every weight 1: SL0's own penalty.
    pub const ONES: Self = Self { s: S::S::ONES, t: S::T::ONES, u: S::U::ONES, v: S::V::ONES, b: S::Bands::ONES };

    /// The weights mode by mode (`s`, `t`, `u`, `v`, `b`).
    pub fn modes(&self) -> [&[f32]; 5] {
        [self.s.as_ref(), self.t.as_ref(), self.u.as_ref(), self.v.as_ref(), self.b.as_ref()]
    }

    /// The weights mode by mode, to write.
    pub fn modes_mut(&mut self) -> [&mut [f32]; 5] {
        [self.s.as_mut(), self.t.as_mut(), self.u.as_mut(), self.v.as_mut(), self.b.as_mut()]
    }

    /// The weight of the coefficient at `[s, t, u, v, b]` (0 outside the patch).
    pub fn at(&self, [s, t, u, v, b]: [usize; 5]) -> f32 {
        let get = |w: &[f32], i: usize| w.get(i).copied().unwrap_or(0.0);
        get(self.s.as_ref(), s)
            * get(self.t.as_ref(), t)
            * get(self.u.as_ref(), u)
            * get(self.v.as_ref(), v)
            * get(self.b.as_ref(), b)
    }
}

/// One solve's schedule: `len` steps, each a `sigma` (fraction of `sigma0`) and a `mu`,
/// and the penalty's group weights.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Schedule<S: Shape> {
    len: u8,
    /// A cold solve's start: the band-gain fill (each unmeasured value from its pixel's
    /// measured bands and the patch's band means) instead of the minimum-norm solution.
    fill_start: bool,
    sigma: [f32; MAX_STEPS],
    mu: [f32; MAX_STEPS],
    weights: Weights<S>,
}

impl<S: Shape> Schedule<S> {
    /// A checked schedule: 1 to [`MAX_STEPS`] steps (`sigma` and `mu` of the same length),
    /// every `sigma` in (0, 1], every `mu` in (0, 2] (above 2 the ascent grows a small
    /// coefficient: see the solver's `Sl0Config::mu`), every weight finite in
    /// [1/64, 64] (a coefficient group's threshold moved at most 8 times either way).
    ///
    /// # Errors
    /// [`DictionaryError::BadSchedule`] naming the first bad part (`steps`, `sigma`, `mu`,
    /// `weights`).
    pub fn new(sigma: &[f32], mu: &[f32], weights: Weights<S>) -> Result<Self, DictionaryError> {
        let bad = |part| Err(DictionaryError::BadSchedule { part });
        if sigma.is_empty() || sigma.len() > MAX_STEPS || sigma.len() != mu.len() {
            return bad("steps");
        }
        if !sigma.iter().all(|s| *s > 0.0 && *s <= 1.0) {
            return bad("sigma");
        }
        if !mu.iter().all(|m| *m > 0.0 && *m <= 2.0) {
            return bad("mu");
        }
        if !weights.modes().iter().all(|w| w.iter().all(|x| (1.0 / 64.0..=64.0).contains(x))) {
            return bad("weights");
        }
        let mut out =
            Self { len: sigma.len() as u8, fill_start: false, sigma: [0.0; MAX_STEPS], mu: [0.0; MAX_STEPS], weights };
        out.sigma.iter_mut().zip(sigma).for_each(|(d, s)| *d = *s);
        out.mu.iter_mut().zip(mu).for_each(|(d, m)| *d = *m);
        Ok(out)
    }

    /// The schedule with its cold start from the band-gain fill (`true`) or the minimum-norm
    /// solution (`false`, as built). A warm solve starts from its estimate either way.
    pub fn with_fill_start(self, fill_start: bool) -> Self {
        Self { fill_start, ..self }
    }

    /// Whether a cold solve starts from the band-gain fill.
    pub fn fill_start(&self) -> bool {
        self.fill_start
    }

    /// Steps.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// Always false: a checked schedule has a step.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Each step's `sigma` (fraction of `sigma0`).
    pub fn sigma(&self) -> &[f32] {
        self.sigma.get(..self.len()).unwrap_or(&[])
    }

    /// Each step's `mu`.
    pub fn mu(&self) -> &[f32] {
        self.mu.get(..self.len()).unwrap_or(&[])
    }

    /// The penalty's group weights.
    pub fn weights(&self) -> &Weights<S> {
        &self.weights
    }
}

/// The three schedules a blob carries.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Schedules<S: Shape> {
    /// The screened choice's first solve, the DCT's from the measurements alone: its
    /// solution is scored in every member and starts the member's warm solve.
    pub cold: Schedule<S>,
    /// A warm solve: from another member's solution or a seed.
    pub warm: Schedule<S>,
    /// A dictionary decoding alone from the measurements (the DCT of the preview): its
    /// solution is the decode, with no member's solve after it. Trained apart from the cold
    /// one because the two ends differ: measured, the band-gain fill start made this
    /// solve 1.2-2.8 dB better on the realistic set and the screened choice after the cold
    /// one 0.2-1.8 dB worse.
    pub alone: Schedule<S>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_schedule_out_of_range_is_refused_by_name() {
        let w = Weights::<crate::operators::shape::PatchShape<5, 5, 5, 5, 13, 8125>>::ONES;
        let field =
            |r: Result<Schedule<crate::operators::shape::PatchShape<5, 5, 5, 5, 13, 8125>>, DictionaryError>| match r {
                Err(DictionaryError::BadSchedule { part }) => part,
                _ => "accepted",
            };
        assert_eq!(field(Schedule::new(&[], &[], w)), "steps");
        assert_eq!(field(Schedule::new(&[0.5; 65], &[1.0; 65], w)), "steps");
        assert_eq!(field(Schedule::new(&[0.5, 0.2], &[1.0], w)), "steps");
        assert_eq!(field(Schedule::new(&[0.5, 0.0], &[1.0, 1.0], w)), "sigma");
        assert_eq!(field(Schedule::new(&[0.5, f32::NAN], &[1.0, 1.0], w)), "sigma");
        assert_eq!(field(Schedule::new(&[0.5, 0.1], &[1.0, 2.5], w)), "mu");
        let mut heavy = w;
        heavy.b[12] = 100.0;
        assert_eq!(field(Schedule::new(&[0.5], &[1.0], heavy)), "weights");
        heavy.b[12] = f32::NAN;
        assert_eq!(field(Schedule::new(&[0.5], &[1.0], heavy)), "weights");
        let ok = Schedule::new(&[0.5, 0.1], &[1.0, 2.0], w).unwrap();
        assert_eq!((ok.len(), ok.sigma(), ok.mu()), (2, &[0.5, 0.1][..], &[1.0, 2.0][..]));
    }

    #[test]
    fn a_weight_is_the_product_of_its_indices_weights() {
        let mut w = Weights::<crate::operators::shape::PatchShape<2, 2, 2, 2, 3, 48>>::ONES;
        (w.s[1], w.t[0], w.u[1], w.v[1], w.b[2]) = (2.0, 3.0, 0.5, 4.0, 0.25);
        assert_eq!(w.at([1, 0, 1, 1, 2]), 2.0 * 3.0 * 0.5 * 4.0 * 0.25);
        assert_eq!(w.at([0, 1, 0, 0, 0]), 1.0);
        assert_eq!(w.at([2, 0, 0, 0, 0]), 0.0);
    }
}
