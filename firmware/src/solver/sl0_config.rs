//! SL0's parameters ([`Sl0Config`], checked once where a decoder is built) and how a solve
//! ended ([`Outcome`], [`Ended`]): the configuration apart from the solve that runs on it
//! ([`crate::solver::sl0`]).

use crate::solver::error::SolveError;

/// Parameters of SL0 (Algorithm 1). Defaults in [`Sl0Config::DEFAULT`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sl0Config {
    /// `sigma_f`: factor by which sigma falls per level, in (0, 1).
    pub sigma_f: f32,
    /// `L`: steepest-ascent + projection steps per sigma level, >= 1.
    pub steps: u16,
    /// `mu`: step size, in (0, 2] (2 as in Mohimani et al.'s reference code; above 2 the
    /// ascent grows small coefficients).
    pub mu: f32,
    /// `sigma_min`: the last sigma, in (0, 1], in normalised units (white = 1).
    pub sigma_min: f32,
    /// Hard bound on steps (ascent + projection) per solve, >= 1.
    pub max_iterations: u32,
    /// Noise standard deviation per measurement (normalised units), in [0, 1]: read and
    /// quantisation noise. With `shot` 0 too, the solution equals the measurements.
    pub noise: f32,
    /// Shot noise: a measurement's variance per unit of its value (normalised units), in [0, 1];
    /// `1 / electrons at white` for a sensor whose white level collects that many
    /// electrons. A measurement `y` has variance `noise^2 + shot * max(y, 0)`.
    pub shot: f32,
    /// Early stop: the solve ends once a whole sigma level moves the patch by less than
    /// this, as an RMS per value (normalised units), in [0, 1]; 0 never stops early.
    pub tolerance: f32,
    /// Where a solve starts from another dictionary's patch ([`solve_warm`](crate::solver::sl0::solve_warm): the ensemble's
    /// second solve), sigma starts at `warm_start * max |S|`, in (0, 1]; 1 is a cold start.
    pub warm_start: f32,
    /// `sigma_f` of a warm solve, in (0, 1): it starts from a patch that has found its
    /// large coefficients and only refines it, so a slower fall with fewer steps per level
    /// ([`Sl0Config::warm_steps`]) does as well as the full schedule in fewer steps.
    pub warm_sigma_f: f32,
    /// `L` of a warm solve, >= 1.
    pub warm_steps: u16,
    /// `sigma_f` of a seeded solve ([`solve_seeded`](crate::solver::sl0::solve_seeded): a patch started from its
    /// overlapping neighbours' decode), in (0, 1). It starts where a warm solve does but
    /// from an estimate, not a solution: slower than the warm fall, so it reworks what the
    /// estimate carries from the neighbours' borders (measured: at 0.85 the realistic set
    /// lost 0.1-0.2 dB against a cold decode of the same patches, at 0.9 it gains up to
    /// 0.2 dB, `docs/bench/README.md`).
    pub seed_sigma_f: f32,
    /// Where a cold solve starts, in (0, 1]. 1: the paper's minimum-norm solution (the
    /// measurements, zeros elsewhere) at `sigma0 = max |S0|`. Below 1: the band-gain fill
    /// ([`crate::solver::fill`]) at `cold_start * max |S|` of its coefficients (the fill's
    /// largest is its DC, about 13 times the zero-filled start's at one measurement per
    /// pixel: 0.01 starts about 6 levels lower, and above about 0.08 the fill starts
    /// higher than the minimum-norm start).
    pub cold_start: f32,
    /// The short path: a patch whose measurements of each band all lie within `flat` of
    /// each other (normalised units, in [0, 1]) is flat in space and view, and is decoded as
    /// each band's mean with no solve. Dark patches are flat (their spread is at most their
    /// brightness); with 0 only exactly flat patches (black, clipped) take it.
    pub flat: f32,
    /// A patch whose measurements cover fewer than this many distinct bands (and at least
    /// one) is decoded by per-pixel spectral interpolation ([`crate::solver::interpolate`]) instead of SL0, and ends
    /// as [`Ended::Interpolated`]; 0 solves every patch. Read by the tile decoder.
    pub min_bands: u8,
}

impl Sl0Config {
    /// The defaults: `sigma_f = 0.7`, `L = 3`, `mu = 2`, `sigma_min = 1e-3`, at most 300
    /// steps, exact projection. The start is `sigma0 = max |S0|` of the minimum-norm
    /// solution `S0`; from a patch of mean brightness 0.5 that is about 20 levels (60 steps).
    /// No early stop (`tolerance` 0: measured, it only pays where it costs PSNR); warm
    /// start at 1e-2 (`slf bench`, pixel mask, five scenes: +1.2 dB at k = 1 and +0.2 dB at
    /// k = 3 over a cold second solve, and a third less time), annealed at `sigma_f` 0.85
    /// with one step per level (against the main schedule 0.7 x 3: PSNR within 0.02-0.08
    /// dB on the pixel and lenslet masks, 8-13 % less time a screened patch, 14 % fewer
    /// device instructions); the short path for exactly flat patches only (`flat` 0).
    pub const DEFAULT: Self = Self {
        sigma_f: 0.7,
        steps: 3,
        mu: 2.0,
        sigma_min: 1e-3,
        max_iterations: 300,
        noise: 0.0,
        shot: 0.0,
        tolerance: 0.0,
        warm_start: 1e-2,
        warm_sigma_f: 0.85,
        warm_steps: 1,
        seed_sigma_f: 0.9,
        cold_start: 1.0,
        flat: 0.0,
        min_bands: 5,
    };

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`SolveError::InvalidConfig`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |field| Err(SolveError::InvalidConfig { field });
        if !(self.sigma_f > 0.0 && self.sigma_f < 1.0) {
            return bad("sigma_f");
        }
        if self.steps == 0 {
            return bad("steps");
        }
        // Above 2 the ascent's step `s -> s (1 - mu e^(-s^2 / 2 sigma^2))` grows a small
        // coefficient instead of shrinking it (2 reflects it): the solve diverges.
        if !(self.mu > 0.0 && self.mu <= 2.0) {
            return bad("mu");
        }
        // Values are in normalised units (white = 1): a sigma, a noise, a tolerance or a
        // flatness above 1 is larger than the signal, and the solve would return its start.
        if !(self.sigma_min > 0.0 && self.sigma_min <= 1.0) {
            return bad("sigma_min");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations");
        }
        if !(self.noise >= 0.0 && self.noise <= 1.0) {
            return bad("noise");
        }
        // `1 / electrons at white`: a sensor collects at least one electron at white.
        if !(self.shot >= 0.0 && self.shot <= 1.0) {
            return bad("shot");
        }
        if !(self.tolerance >= 0.0 && self.tolerance <= 1.0) {
            return bad("tolerance");
        }
        if !(self.warm_start > 0.0 && self.warm_start <= 1.0) {
            return bad("warm_start");
        }
        if !(self.warm_sigma_f > 0.0 && self.warm_sigma_f < 1.0) {
            return bad("warm_sigma_f");
        }
        if self.warm_steps == 0 {
            return bad("warm_steps");
        }
        if !(self.seed_sigma_f > 0.0 && self.seed_sigma_f < 1.0) {
            return bad("seed_sigma_f");
        }
        if !(self.cold_start > 0.0 && self.cold_start <= 1.0) {
            return bad("cold_start");
        }
        if !(self.flat >= 0.0 && self.flat <= 1.0) {
            return bad("flat");
        }
        Ok(())
    }
}

impl Default for Sl0Config {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Why a solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Ended {
    /// `sigma` reached `sigma_min`: the normal end.
    SigmaMin,
    /// `max_iterations` steps were taken first.
    IterationBound,
    /// `sigma` fell so far that `1 / sigma^2` is not an f32 (only with a `sigma_min`
    /// below f32 resolution); the solution is as good as it gets.
    SigmaUnderflow,
    /// A whole level moved the patch by less than [`Sl0Config::tolerance`] (RMS per
    /// value): the solution stopped changing.
    Converged,
    /// The patch was flat within [`Sl0Config::flat`]: decoded by the short path, no solve.
    Flat,
    /// Too few bands measured: decoded by per-pixel spectral interpolation, no
    /// solve ([`Sl0Config::min_bands`]).
    Interpolated,
    /// Every step of a trained [`Schedule`](crate::operators::schedule::Schedule) was taken: the normal end of a scheduled solve.
    Scheduled,
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outcome {
    /// Steps (ascent + projection) taken.
    pub iterations: u32,
    /// Sigma levels completed.
    pub levels: u32,
    /// `sigma0 = max |S0|` of the minimum-norm solution.
    pub sigma0: f32,
    /// l2 norm of measurements minus synthesis before the last projection (normalised
    /// units): how far the last ascent step moved off the data.
    pub residual: f32,
    /// Why it stopped.
    pub ended: Ended,
}

impl Outcome {
    /// A patch decoded by interpolation: no step, no level.
    pub const fn interpolated() -> Self {
        Self { iterations: 0, levels: 0, sigma0: 0.0, residual: 0.0, ended: Ended::Interpolated }
    }

    /// Whether the hard iteration bound stopped the solve.
    pub fn hit_bound(&self) -> bool {
        self.ended == Ended::IterationBound
    }
}
