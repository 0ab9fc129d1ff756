//! Member choice: decoding a patch with a learned ensemble without paying K full solves.
//!
//! An [`EnsembleModel`] holds the ensemble (a validated blob in flash), the DCT to screen
//! with, and a [`MemberChoice`]:
//!
//! - **Exhaustive**: solve with every member, score each solution by a [`ChoiceRule`], then
//!   solve once more with the best member (K + 1 solves; the workspace holds one patch).
//! - **Screened**: solve once with the DCT, score that solution in every member (an
//!   analysis each, no solve), then solve again with the best member, warm-started from
//!   the DCT's solution ([`solve_warm`]: it skips the levels that found the large
//!   coefficients, and measured better than a cold start). A member that is the DCT itself
//!   is not screened (a solution computed with the DCT is always sparsest in the DCT, which
//!   would bias the screen); instead the DCT's own solution competes with the chosen
//!   member's by the same rule, and unless the member's scores [`DCT_MARGIN`] times
//!   sparser the patch is a mean of the two solutions, each weighted by the other's score.
//! - **Screened, re-solved**: as screened, but a DCT win solves the DCT again, warm from
//!   the member's solution (3 solves).
//!
//! Why a mean: both solutions meet the measurements, so any weighted mean does too, and it
//! averages two estimates whose errors differ. Weighted by the other's score, the sparser
//! solution weighs more, and one that is exactly sparse (score 0, e.g. a patch made of
//! fewer DCT atoms than the rule keeps) is kept whole: an equal mean with a member that
//! cannot represent it would halve its error only to add half of the member's. The DCT's
//! solution waits in the unmeasured slots of the measurement buffer while the member
//! solves ([`Measurements`]), so the mean costs no solve and no RAM. The weights measured
//! the same as an equal mean on the scenes. Against the third solve in the same run (`slf
//! bench`, five scenes, `docs/bench/README.md`), k = 1 / 3: pixel mask -0.04 / -0.01 dB,
//! lenslet -0.04 / -0.05 dB, kronecker within 0.01 dB, for 2.0 solves a patch instead of
//! 2.1-2.7 (2-13 % less time); at paper scale (`slf bench --paper-scale`), where the DCT
//! wins 70 % of the patches, +0.01 dB and 0.65 instead of 0.68 degrees SA for 11-14 % less
//! time.
//!
//! [`Measurements`]: crate::solver::workspace::Measurements
//!
//! The raw SL0 residual is near zero for every member (each solution meets the
//! measurements), so it cannot rank them; the rules look at how sparse the solution is in
//! the member instead. Scoring analyses the solution into the coefficient buffer (the last
//! four modes a spatial slice at a time, through a slice on the stack), so no buffer is
//! added to the [`Workspace`].

use crate::operators::blob::Ensemble;
use crate::operators::dictionary::Dictionary;
use crate::operators::mode::{Mode, ModeMatrix};
use crate::operators::schedule::Schedules;
use crate::operators::shape::Shape;
use crate::operators::transform::analyze_preserving;
use crate::sensor::extent::Array;
use crate::solver::sl0::{
    Ended, Outcome, Sl0Config, SolveError, max_abs, put_back, seed, solve, solve_scheduled, solve_seeded, solve_warm,
    solve_warm_scheduled,
};
use crate::solver::workspace::Workspace;

/// How much sparser than the DCT's own solution a member's must score to replace it
/// (screened choice): below this factor the patch is the two solutions' weighted mean.
/// A learned member's solution can score sparser without being nearer the truth (oracle
/// choice on held-out scenes: the members recover worse than the DCT on most blocks at
/// pixel k = 3, `docs/results-ensemble-validation.md`, round 2). Measured with the shipped
/// ensemble against a margin of 1 (`docs/results-ensemble.md`, and round 2 of
/// `docs/results-ensemble-validation.md`): at pixel k = 3 -0.08 to +0.88 dB over the
/// realistic and synthetic scenes (the smooth scene from 0.78 dB below the DCT to 0.10
/// above), pixel k = 1 -0.17 to +0.16, lenslet k = 3 -0.15 to +0.42; 4 gave the same
/// within 0.03 dB.
pub const DCT_MARGIN: f32 = 2.0;

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
    /// The default: the relative residual after keeping the 100 largest coefficients (2 %
    /// of the paper's patch), the sparsity the shipped ensemble was trained at. Measured
    /// (`slf compare --masks pixel --k 3`): tau 100 keeps screened choice within 0.1 dB of
    /// exhaustive; 260 within 0.2 dB; l1 within 0.3 dB.
    pub const DEFAULT: Self = Self::Residual { tau: 100 };

    /// The rule's score of coefficients `s` (lower is sparser).
    pub fn score(&self, s: &[f32]) -> f32 {
        match *self {
            Self::L1 => lane_sum(s, |x| x.abs()),
            Self::Count { threshold } => count_above(s, threshold) as f32,
            Self::Residual { tau } => residual_outside_top(s, tau as usize),
        }
    }
}

/// `sum f(x)` over `s` in eight running sums, one per lane, added at the end: one running
/// sum is a serial chain of additions the compiler may not reorder (f32 addition is not
/// associative), which kept every pass of the scoring scalar (13 us a score, 7 % of a
/// screened decode, against about 6 us in lanes: `perf record` on the screened criterion
/// bench).
#[inline(always)]
fn lane_sum(s: &[f32], f: impl Fn(f32) -> f32) -> f32 {
    let mut sums = [0.0f32; 8];
    let (lanes, tail) = s.as_chunks::<8>();
    for lane in lanes {
        for (sum, &x) in sums.iter_mut().zip(lane) {
            *sum += f(x);
        }
    }
    for &x in tail {
        sums[0] += f(x);
    }
    sums.iter().sum()
}

/// How many magnitudes of `s` exceed `t`, counted as f32 ones in 32 lanes (exact below
/// `2^24` per lane, so in any order): the compiler's vectorisation of an integer count
/// widened and shuffled its lanes, and [`lane_sum`]'s eight lanes are one vector register
/// whose additions wait on each other (a pass took four times its loads' time); four
/// registers of lanes run at the loads' pace: a member score 2.4 times faster, the
/// default decode 7 % (`perf record` of a one-thread decode, the same bits).
#[cfg(not(target_arch = "arm"))]
#[inline(always)]
fn count_above(s: &[f32], t: f32) -> usize {
    let mut counts = [0.0f32; 32];
    let (lanes, tail) = s.as_chunks::<32>();
    for lane in lanes {
        for (c, &x) in counts.iter_mut().zip(lane) {
            *c += if x.abs() > t { 1.0 } else { 0.0 };
        }
    }
    let above = tail.iter().filter(|x| x.abs() > t).count();
    counts.iter().map(|&c| c as usize).sum::<usize>() + above
}

/// [`count_above`] on a scalar core (Cortex-M): 32 running counts do not fit its 32 single
/// registers, and spilling them took 1.5 % more instructions a screened patch
/// (`scripts/budgets.sh`); eight do.
#[cfg(target_arch = "arm")]
#[inline(always)]
fn count_above(s: &[f32], t: f32) -> usize {
    lane_sum(s, |x| if x.abs() > t { 1.0 } else { 0.0 }) as usize
}

/// Energy of `s` outside its `tau` largest magnitudes, relative to the total (0 for a zero
/// `s`); magnitudes tied with the `tau + 1`-th largest count as outside, so at most `tau`
/// are kept. The threshold is found by bisection on the magnitude (bounded: 40 halvings,
/// and it stops as soon as exactly `tau` magnitudes lie above it; about 16 passes on the
/// realistic scenes), so no sort and no buffer. Ranking the last 64 candidates on the
/// stack instead of bisecting down to them saved 6 passes but measured slower: gathering
/// them is a scalar pass, and a count runs at the loads' pace.
fn residual_outside_top(s: &[f32], tau: usize) -> f32 {
    let total = lane_sum(s, |x| x * x);
    if total.is_nan() || total <= 0.0 || tau >= s.len() {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f32, max_abs(s));
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        match count_above(s, mid) {
            // Exactly the `tau` largest are above `mid`: the set kept is the one the
            // bisection converges to.
            n if n == tau => {
                hi = mid;
                break;
            }
            n if n > tau => lo = mid,
            _ => hi = mid,
        }
    }
    lane_sum(s, |x| if x.abs() <= hi { x * x } else { 0.0 }) / total
}

/// Which members are solved.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MemberChoice {
    /// Solve with every member, keep the best by the rule (K + 1 solves).
    Exhaustive(ChoiceRule),
    /// Solve with the DCT, pick the member that best represents that solution, solve again
    /// with it from the DCT's solution (2 solves, the second shorter); unless the member's
    /// solution scores [`DCT_MARGIN`] times sparser than the DCT's own, the patch is the two
    /// solutions' mean, each weighted by the other's score.
    Screened(ChoiceRule),
    /// As [`MemberChoice::Screened`], but a DCT win solves the DCT again from the member's
    /// solution (3 solves): the default before the mean, kept to compare with.
    ScreenedResolve(ChoiceRule),
}

/// What a model did with one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelOutcome {
    /// The final solve.
    pub outcome: Outcome,
    /// The ensemble member the rule chose, if the model is an ensemble (the DCT's when its
    /// own solution won, also where the patch is a mean of its solution and the chosen
    /// member's: [`MemberChoice::Screened`]).
    pub member: Option<u16>,
    /// Solves this patch cost.
    pub solves: u16,
}

/// Something that decodes the patch in a workspace: a single [`Dictionary`] (with the
/// hand-set schedule, or trained ones: [`ScheduledDictionary`]) or an [`EnsembleModel`].
/// The tile decoder takes any.
pub trait PatchModel<S: Shape> {
    /// Decodes the patch whose measurements are in `ws` into `ws.patch()`.
    ///
    /// # Errors
    /// As [`solve`].
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError>;

    /// Decodes the patch whose measurements are in `ws`, starting from the estimate of it
    /// in `ws.patch()` (its overlapping neighbours' decode, in the solve's balanced units):
    /// one seeded solve ([`seed`], [`solve_seeded`]) where [`decode`](Self::decode) starts
    /// cold. A model without a seeded path decodes from nothing.
    ///
    /// # Errors
    /// As [`solve`].
    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        self.decode(cfg, ws)
    }

    /// The solve whose predictions of held-out measurements estimate the patch's error
    /// ([`crate::solver::holdout`]): one solve from the measurements in `ws` alone, the
    /// cheapest the model has (an ensemble's: its DCT with the alone schedule). The default
    /// is [`decode`](Self::decode).
    ///
    /// # Errors
    /// As [`solve`].
    fn estimating_solve(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<u16, SolveError> {
        self.decode(cfg, ws).map(|d| d.solves)
    }
}

impl<S: Shape> PatchModel<S> for Dictionary<S> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        let outcome = solve(self, cfg, ws)?;
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }

    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        if let Some(outcome) = seed(self, cfg, ws)? {
            return Ok(ModelOutcome { outcome, member: None, solves: 0 });
        }
        let outcome = solve_seeded(self, cfg, ws)?;
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }
}

/// One dictionary solved with trained schedules: the alone one from the measurements, the
/// warm one from a seed. The DCT with the schedules of a blob that screens with it (its
/// alone schedule is trained on the DCT's solves).
#[derive(Clone, Debug)]
pub struct ScheduledDictionary<S: Shape> {
    pub dictionary: Dictionary<S>,
    pub schedules: Schedules<S>,
}

impl<S: Shape> PatchModel<S> for ScheduledDictionary<S> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        let outcome = solve_scheduled(&self.dictionary, cfg, &self.schedules.alone, ws)?;
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }

    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        if let Some(outcome) = seed(&self.dictionary, cfg, ws)? {
            return Ok(ModelOutcome { outcome, member: None, solves: 0 });
        }
        let outcome = solve_warm_scheduled(&self.dictionary, cfg, &self.schedules.warm, ws)?;
        Ok(ModelOutcome { outcome, member: None, solves: 1 })
    }
}

/// Where a member's solve starts, which says its schedule ([`EnsembleModel`]'s solves).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Start {
    /// From the measurements alone.
    Cold,
    /// From another member's solution.
    Warm,
    /// From a seed: the overlapping neighbours' decode.
    Seeded,
}

/// An ensemble with its member choice. Config: immutable, the blob stays in flash.
#[derive(Clone, Debug)]
pub struct EnsembleModel<'a, S: Shape> {
    ensemble: Ensemble<'a, S>,
    screen: Dictionary<S>,
    /// The member that is the screening DCT, if one is (to f32 rounding).
    screen_member: Option<u16>,
    choice: MemberChoice,
    /// The trained schedules its solves take; `None`: the hand-set schedule.
    schedules: Option<Schedules<S>>,
}

/// Whether two dictionaries hold the same matrices to `1e-6`.
fn same<S: Shape>(a: &Dictionary<S>, b: &Dictionary<S>) -> bool {
    fn close<E: Mode>(x: &ModeMatrix<E>, y: &ModeMatrix<E>) -> bool {
        x.iter().zip(y.iter()).all(|(x, y)| x.iter().zip(y.iter()).all(|(p, q)| (p - q).abs() <= 1e-6))
    }
    let (a, b) = (a.synthesis(), b.synthesis());
    close::<S::S>(&a.m1, &b.m1)
        && close::<S::T>(&a.m2, &b.m2)
        && close::<S::U>(&a.m3, &b.m3)
        && close::<S::V>(&a.m4, &b.m4)
        && close::<S::Bands>(&a.m5, &b.m5)
}

type Ws<S> = Workspace<S>;

impl<'a, S: Shape> EnsembleModel<'a, S> {
    /// An ensemble that screens with the 5D DCT, solving with the blob's trained schedules
    /// if it has them ([`Ensemble::schedules`]), else with the hand-set schedule.
    pub fn new(ensemble: Ensemble<'a, S>, choice: MemberChoice) -> Self {
        let screen = Dictionary::dct();
        let screen_member =
            (0..ensemble.len()).find(|&k| ensemble.member(k).is_ok_and(|m| same(&m, &screen))).map(|k| k as u16);
        Self { ensemble, screen, screen_member, choice, schedules: ensemble.schedules() }
    }

    /// The model with these schedules for its solves (`None`: the hand-set schedule).
    pub fn with_schedules(self, schedules: Option<Schedules<S>>) -> Self {
        Self { schedules, ..self }
    }

    /// The trained schedules its solves take, if any.
    pub fn schedules(&self) -> Option<&Schedules<S>> {
        self.schedules.as_ref()
    }

    /// The DCT it screens with, on its trained schedules (`None` without them): the model
    /// trial's other model ([`crate::decode::trial`]), which decodes as the DCT alone does.
    pub fn scheduled_screen(&self) -> Option<ScheduledDictionary<S>> {
        self.schedules.map(|schedules| ScheduledDictionary { dictionary: self.screen.clone(), schedules })
    }

    /// A solve of `ws` by `dict` from `start`: the trained schedule for it ([`Start::Cold`]:
    /// the cold one; otherwise the warm one), or without schedules the hand-set solve
    /// ([`solve`], [`solve_warm`], [`solve_seeded`]).
    fn solve_from(
        &self,
        start: Start,
        dict: &Dictionary<S>,
        cfg: &Sl0Config,
        ws: &mut Ws<S>,
    ) -> Result<Outcome, SolveError> {
        match (&self.schedules, start) {
            (Some(s), Start::Cold) => solve_scheduled(dict, cfg, &s.cold, ws),
            (Some(s), Start::Warm | Start::Seeded) => solve_warm_scheduled(dict, cfg, &s.warm, ws),
            (None, Start::Cold) => solve(dict, cfg, ws),
            (None, Start::Warm) => solve_warm(dict, cfg, ws),
            (None, Start::Seeded) => solve_seeded(dict, cfg, ws),
        }
    }

    /// The ensemble.
    pub fn ensemble(&self) -> &Ensemble<'a, S> {
        &self.ensemble
    }

    /// The member choice.
    pub fn choice(&self) -> MemberChoice {
        self.choice
    }

    /// The member that is the 5D DCT, if any.
    pub fn dct_member(&self) -> Option<u16> {
        self.screen_member
    }

    /// Scores the solution in `ws.patch()` in `member` by `rule`, analysing a copy in the
    /// coefficient buffer (the solution is only read).
    fn score(&self, member: &Dictionary<S>, rule: &ChoiceRule, ws: &mut Ws<S>) -> f32 {
        analyze_preserving(member, &ws.signal, &mut ws.coeffs);
        rule.score(ws.coeffs.as_ref())
    }

    /// The member other than the DCT whose analysis of `ws.patch()` scores sparsest by
    /// `rule`, with its score (`None`: the ensemble has no other member).
    fn screen_members(&self, rule: &ChoiceRule, ws: &mut Ws<S>) -> Result<(f32, Option<u16>), SolveError> {
        let mut best = (f32::INFINITY, None);
        for k in (0..self.ensemble.len() as u16).filter(|&k| Some(k) != self.screen_member) {
            let s = self.score(&self.member(k)?, rule, ws);
            if s < best.0 || best.1.is_none() {
                best = (s, Some(k));
            }
        }
        Ok(best)
    }

    fn member(&self, k: u16) -> Result<Dictionary<S>, SolveError> {
        self.ensemble.member(k as usize).map_err(|_| SolveError::NoSuchMember)
    }

    /// Exhaustive: every member solved and scored; the best solved again.
    fn exhaustive(&self, rule: &ChoiceRule, cfg: &Sl0Config, ws: &mut Ws<S>) -> Result<ModelOutcome, SolveError> {
        let mut best = (f32::INFINITY, 0u16);
        for k in 0..self.ensemble.len() as u16 {
            let member = self.member(k)?;
            let outcome = self.solve_from(Start::Cold, &member, cfg, ws)?;
            if outcome.ended == Ended::Flat {
                // Flat patches decode the same with every member (no solve).
                return Ok(ModelOutcome { outcome, member: Some(k), solves: 1 });
            }
            let s = self.score(&member, rule, ws);
            if s < best.0 || best.0.is_infinite() {
                best = (s, k);
            }
        }
        let outcome = self.solve_from(Start::Cold, &self.member(best.1)?, cfg, ws)?;
        Ok(ModelOutcome { outcome, member: Some(best.1), solves: self.ensemble.len() as u16 + 1 })
    }

    /// Screened: one DCT solve scored in every other member; the best solved from it. If
    /// the ensemble holds the DCT and the member's solution does not score [`DCT_MARGIN`]
    /// times sparser than the DCT's own, the patch becomes the two solutions' mean, each weighted by the other's
    /// score, or (`resolve`) the DCT solves again from the member's.
    fn screened(
        &self,
        rule: &ChoiceRule,
        cfg: &Sl0Config,
        ws: &mut Ws<S>,
        resolve: bool,
    ) -> Result<ModelOutcome, SolveError> {
        let first = self.solve_from(Start::Cold, &self.screen, cfg, ws)?;
        if first.ended == Ended::Flat {
            return Ok(ModelOutcome { outcome: first, member: self.screen_member, solves: 1 });
        }
        let dct_score = self.score(&self.screen, rule, ws);
        let best = self.screen_members(rule, ws)?;
        let (Some(chosen), Some(dct)) = (best.1, self.screen_member) else {
            // No other member, or no DCT member to compete: solve with the screen's pick.
            let k = best.1.or(self.screen_member).unwrap_or(0);
            let outcome = self.solve_from(Start::Warm, &self.member(k)?, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(k), solves: 2 });
        };
        let member = self.member(chosen)?;
        ws.measurements.stash(&ws.signal);
        let solved =
            self.solve_from(Start::Warm, &member, cfg, ws).map(|outcome| (outcome, self.score(&member, rule, ws)));
        let (outcome, member_score) = solved.inspect_err(|_| ws.measurements.drop_stash())?;
        let dct_wins = dct_score < DCT_MARGIN * member_score;
        // The stash keeps the DCT's solution in the unmeasured entries only, which is all
        // of it for selections; interpolating measurements re-solve instead.
        let resolve = resolve || ws.measurements.interpolates();
        if dct_wins && !resolve {
            // Both meet the measurements (the member's to its noise ball: the measured
            // entries stay the member's), and so does their mean, each weighted by the
            // other's score: all of the DCT's where its score is 0.
            let Workspace { signal, measurements, .. } = ws;
            measurements.blend_stash(signal, member_score / (member_score + dct_score));
            put_back(&self.screen, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(dct), solves: 2 });
        }
        ws.measurements.drop_stash();
        if dct_wins {
            let outcome = self.solve_from(Start::Warm, &self.screen, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(dct), solves: 3 });
        }
        Ok(ModelOutcome { outcome, member: Some(chosen), solves: 2 })
    }

    /// Seeded: [`Self::screened`] with the estimate in `ws.patch()` (its overlapping
    /// neighbours' decode, moved onto the measurements by [`seed`]) in place of the DCT's
    /// cold solution: scored in every member, the best solved from it
    /// ([`solve_seeded`]), and unless the member's solution scores [`DCT_MARGIN`] times
    /// sparser than the estimate does in the DCT, the patch is the two's weighted mean as
    /// in the screened choice. One solve where the screened choice takes two, the first
    /// cold. Interpolating measurements (half-pixel shears) keep the member's solution:
    /// the stash holds unmeasured entries only.
    fn seeded(&self, rule: &ChoiceRule, cfg: &Sl0Config, ws: &mut Ws<S>) -> Result<ModelOutcome, SolveError> {
        if let Some(outcome) = seed(&self.screen, cfg, ws)? {
            return Ok(ModelOutcome { outcome, member: self.screen_member, solves: 0 });
        }
        let dct_score = self.score(&self.screen, rule, ws);
        let best = self.screen_members(rule, ws)?;
        let (Some(chosen), Some(dct)) = (best.1, self.screen_member) else {
            let k = best.1.or(self.screen_member).unwrap_or(0);
            let outcome = self.solve_from(Start::Seeded, &self.member(k)?, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(k), solves: 1 });
        };
        let member = self.member(chosen)?;
        let selection = !ws.measurements.interpolates();
        if !selection {
            let outcome = self.solve_from(Start::Seeded, &member, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(chosen), solves: 1 });
        }
        ws.measurements.stash(&ws.signal);
        let solved =
            self.solve_from(Start::Seeded, &member, cfg, ws).map(|outcome| (outcome, self.score(&member, rule, ws)));
        let (outcome, member_score) = solved.inspect_err(|_| ws.measurements.drop_stash())?;
        if dct_score < DCT_MARGIN * member_score {
            let Workspace { signal, measurements, .. } = ws;
            measurements.blend_stash(signal, member_score / (member_score + dct_score));
            put_back(&self.screen, cfg, ws)?;
            return Ok(ModelOutcome { outcome, member: Some(dct), solves: 1 });
        }
        ws.measurements.drop_stash();
        Ok(ModelOutcome { outcome, member: Some(chosen), solves: 1 })
    }
}

impl<S: Shape> PatchModel<S> for EnsembleModel<'_, S> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        // One call site for both screened choices: two kept `screened` out of line, and its
        // frame on top of the caller's took 4 KiB more stack on the device.
        let (rule, resolve) = match self.choice {
            MemberChoice::Exhaustive(rule) => return self.exhaustive(&rule, cfg, ws),
            MemberChoice::Screened(rule) => (rule, false),
            MemberChoice::ScreenedResolve(rule) => (rule, true),
        };
        self.screened(&rule, cfg, ws, resolve)
    }

    fn estimating_solve(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<u16, SolveError> {
        match &self.schedules {
            Some(s) => solve_scheduled(&self.screen, cfg, &s.alone, ws),
            None => solve(&self.screen, cfg, ws),
        }
        .map(|_| 1)
    }

    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<ModelOutcome, SolveError> {
        let rule = match self.choice {
            MemberChoice::Exhaustive(rule) => return self.exhaustive(&rule, cfg, ws),
            MemberChoice::Screened(rule) | MemberChoice::ScreenedResolve(rule) => rule,
        };
        self.seeded(&rule, cfg, ws)
    }
}
