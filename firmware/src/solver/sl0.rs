//! nD smoothed-l0 (SL0): the paper's Algorithm 1 on one patch, orthonormal fast path.
//!
//! SL0 approximates the l0 norm by `N - sum exp(-s^2 / (2 sigma^2))` and follows its
//! maximiser as `sigma` falls: at each `sigma`, `L` times, a steepest-ascent step
//! `S <- S - mu * S * exp(-S^2 / (2 sigma^2))` followed by a projection back onto the
//! measurements; then `sigma <- sigma_f * sigma`, until `sigma <= sigma_min`.
//!
//! **Fast path.** With an orthonormal dictionary and one-hot (selection) measurements the
//! projection `S - A^+(A S - I)` is exactly: synthesise `X`, overwrite the measured entries
//! of `X` with the measurements, analyse back; [`crate::solver::projection`] computes the same in
//! coefficient space, `S + D^T P^T (I - P D S)`, with the band mode only where a band is
//! measured (197,600 instead of 322,400 multiply-adds a step at one measurement per pixel).
//! The start, the minimum-norm solution `A^+ I`, is the analysis of the measurements with
//! zeros elsewhere. This holds for every mask family; the paper's general pseudo-inverse
//! form is in [`crate::solver::pinv`], and a test shows the two agree on kronecker masks.
//!
//! **Noise-aware mode.** With a noise level `noise > 0` (standard deviation per
//! measurement, normalised units) the projection is onto the ball `||A S - I|| <= eps`,
//! `eps = noise * sqrt(m)` for `m` measurements, as SL0 does for noisy data: a point inside
//! the ball is left alone, one outside is moved to its surface. It stops fitting the noise.
//! With shot noise (`shot > 0`) each measurement's variance grows with its value and the
//! ball is weighted accordingly ([`crate::solver::ball`]).
//!
//! Every loop is bounded by [`Sl0Config::max_iterations`]; how a solve ended is in its
//! [`Outcome`], never a hang.

use crate::operators::dictionary::Dictionary;
use crate::operators::schedule::{Schedule, Weights};
use crate::operators::transform::{analyze, synthesize};
use crate::sensor::response::Response;
use crate::solver::ascent::{ascend, ascend_weighted};
use crate::solver::ball::{Ball, Move};
use crate::solver::fill::fill_bands;
use crate::solver::fractional::project_fractional;
use crate::solver::mixing::{BandModel, min_norm, project_mixed, project_signal};
use crate::solver::projection::{project_coefficients, set_flags, weigh};
use crate::solver::shares::{RowSums, project_shares};
use crate::solver::workspace::{Measurements, Workspace};

use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands};
/// Every solver path returns it; it lives below the workspace that checks measurements.
pub use crate::solver::error::SolveError;
/// SL0's parameters and how a solve ended, in their own file; named here, with the solve.
pub use crate::solver::sl0_config::{Ended, Outcome, Sl0Config};

/// The largest absolute value (NaN ignored, as `f32::max` does). A comparison, not
/// `f32::max`: on a Cortex-M4F (no `VMAXNM`) that is a call to `fmaxf`, measured at 5.6 %
/// of a screened patch's instructions with the ascent's clamp (`scripts/device-profile.sh`).
/// In eight lanes (the same value in any order): one running maximum is a serial chain of
/// comparisons, which took a quarter of a member score's time on the host.
pub(crate) fn max_abs(x: &[f32]) -> f32 {
    let above = |m: f32, v: &f32| if v.abs() > m { v.abs() } else { m };
    let mut maxes = [0.0f32; 8];
    let (lanes, tail) = x.as_chunks::<8>();
    for lane in lanes {
        for (m, v) in maxes.iter_mut().zip(lane) {
            *m = above(*m, v);
        }
    }
    tail.iter().chain(&maxes).fold(0.0, above)
}

/// Moves `x` onto the measurements (exactly, or to the noise ball); returns the residual
/// norm before the move.
///
/// Pixel by pixel, each measured band found from the pixel's flags as bits: the residual's
/// sums then run over the measurements alone, in index order as before (the same bits),
/// where a pass over every entry made one chain of `N` dependent additions and a branch an
/// entry on the mask's random pattern (3.8 % of a one-thread default decode at pixel k = 3,
/// `perf record`, for one call a solve).
fn project<S: Shape>(x: &mut PerValue<S, f32>, m: &Measurements<S::Values>, ball: &Ball) -> f32 {
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let weighted = ball.is_weighted();
    let measured = S::Bands::chunks(m.values.as_ref()).iter().zip(S::Bands::chunks(m.measured.as_ref()));
    for (xs, (ys, flags)) in S::Bands::chunks(x.as_ref()).iter().zip(measured) {
        for b in set_flags(flags.as_ref()) {
            let (Some(&x), Some(&y)) = (xs.get(b), ys.get(b)) else { continue };
            let r = y - x;
            r2 += r * r;
            if weighted {
                w2 += r * r * ball.weight(y, m.gains.get(b).copied().unwrap_or(1.0));
            }
        }
    }
    let scale = match ball.move_for(r2, w2) {
        Move::Scale(scale) => scale,
        Move::Stay => return libm::sqrtf(r2),
    };
    for ((xs, ys), flags) in S::Bands::chunks_mut(x.as_mut())
        .iter_mut()
        .zip(S::Bands::chunks(m.values.as_ref()))
        .zip(S::Bands::chunks(m.measured.as_ref()))
    {
        for b in set_flags(flags.as_ref()) {
            let (Some(x), Some(&y)) = (xs.get_mut(b), ys.get(b)) else { continue };
            // The exact projection (scale 1) puts the measured values back as they are.
            *x = if scale == 1.0 { y } else { *x + scale * (y - *x) };
        }
    }
    libm::sqrtf(r2)
}

/// The checks both projection paths start with; returns the noise ball (exact projection
/// without a noise description).
pub(crate) fn start<S: Shape>(cfg: &Sl0Config, m: &Measurements<S::Values>) -> Result<Ball, SolveError> {
    cfg.validate()?;
    if m.count == 0 {
        return Err(SolveError::NoMeasurements);
    }
    if cfg.noise == 0.0 && cfg.shot == 0.0 {
        return Ok(Ball::new(0.0, 0.0, m.count, 0));
    }
    // Pixels with at least one measured band (the band is the last axis).
    let pixels = S::Bands::chunks(m.measured.as_ref()).iter().filter(|p| p.contains(&true)).count();
    Ok(Ball::new(cfg.noise, cfg.shot, m.count, pixels as u32).balanced(m.balanced))
}

/// What one step (ascent + projection) reports to the schedule.
pub(crate) struct Step {
    /// Residual norm before the projection.
    pub residual: f32,
    /// How far the step moved the patch (l2 norm), or an upper bound of it.
    pub moved: f32,
}

/// The sigma schedule of Algorithm 1, shared by both projection paths: runs `step` (one
/// ascent + projection) `L` times per level until `sigma_min`, the iteration bound, sigma
/// underflow, or (with a tolerance) a level that moved the patch by less than
/// `tolerance * sqrt(values)` in all.
pub(crate) fn run_schedule(cfg: &Sl0Config, sigma0: f32, values: usize, mut step: impl FnMut(f32) -> Step) -> Outcome {
    let mut out = Outcome { iterations: 0, levels: 0, sigma0, residual: 0.0, ended: Ended::SigmaMin };
    let stop = cfg.tolerance * libm::sqrtf(values as f32);
    let mut sigma = sigma0;
    out.ended = 'levels: loop {
        if sigma.is_nan() || sigma <= cfg.sigma_min {
            break Ended::SigmaMin;
        }
        let inv = 1.0 / (2.0 * sigma * sigma);
        if !inv.is_finite() {
            break Ended::SigmaUnderflow;
        }
        // The level's movement, bounded by the sum of its steps' (triangle inequality).
        let mut moved = 0.0f32;
        for _ in 0..cfg.steps {
            if out.iterations >= cfg.max_iterations {
                break 'levels Ended::IterationBound;
            }
            let s = step(inv);
            out.residual = s.residual;
            moved += s.moved;
            out.iterations += 1;
        }
        out.levels += 1;
        sigma *= cfg.sigma_f;
        if moved < stop {
            break Ended::Converged;
        }
    };
    out
}

/// A trained schedule's steps, shared by both projection paths: `step(inv, mu)` for each
/// step, `sigma = max(schedule.sigma[t] * sigma0, cfg.sigma_min)`, until the schedule's
/// end, the iteration bound or sigma underflow.
pub(crate) fn run_trained<S: Shape>(
    cfg: &Sl0Config,
    schedule: &Schedule<S>,
    sigma0: f32,
    mut step: impl FnMut(f32, f32) -> Step,
) -> Outcome {
    let mut out = Outcome { iterations: 0, levels: 0, sigma0, residual: 0.0, ended: Ended::Scheduled };
    for (&fraction, &mu) in schedule.sigma().iter().zip(schedule.mu()) {
        if out.iterations >= cfg.max_iterations {
            out.ended = Ended::IterationBound;
            break;
        }
        // A comparison, not `f32::max` (a call on the Cortex-M4F); a NaN `sigma0` takes
        // `sigma_min`.
        let sigma = fraction * sigma0;
        let sigma = if sigma > cfg.sigma_min { sigma } else { cfg.sigma_min };
        let inv = 1.0 / (2.0 * sigma * sigma);
        if !inv.is_finite() {
            out.ended = Ended::SigmaUnderflow;
            break;
        }
        out.residual = step(inv, mu).residual;
        out.iterations += 1;
        out.levels += 1;
    }
    out
}

/// Decodes the patch whose measurements are in `ws`, with an orthonormal dictionary (the
/// fast path). On success the patch is in [`Workspace::patch`]; it matches every
/// measurement (to the noise ball in noise-aware mode) and holds no NaN or infinity.
///
/// # Errors
/// [`SolveError::InvalidConfig`], [`SolveError::NoMeasurements`], or
/// [`SolveError::NonFiniteResult`] (then `ws.patch()` is not a decode).
pub fn solve<S: Shape>(dict: &Dictionary<S>, cfg: &Sl0Config, ws: &mut Workspace<S>) -> Result<Outcome, SolveError> {
    cold(dict, cfg, ws, cfg.cold_start < 1.0, Plan::Annealed { scale: cfg.cold_start })
}

/// A solve from the measurements alone ([`solve`], [`solve_scheduled`]): from the band-gain
/// fill (`fill`) or the minimum-norm start, down `plan`'s sigmas.
fn cold<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
    fill: bool,
    plan: Plan<'_, S>,
) -> Result<Outcome, SolveError> {
    let ball = start::<S>(cfg, &ws.measurements)?;
    let mixed = !ws.response.is_identity();
    if ws.measurements.interpolates() {
        if mixed {
            return Err(SolveError::MixedHalfViews);
        }
        // Interpolating measurements: the minimum-norm start `M^+ I` is the exact
        // projection of zero; the fill's start is the exact projection of the fill.
        let Workspace { coeffs, signal, measurements: m, .. } = ws;
        if fill {
            fill_bands::<S>(m, signal);
            analyze(dict, signal, coeffs);
        } else {
            coeffs.fill(0.0);
        }
        project_interpolating(dict, coeffs, signal, m, &Ball::new(0.0, 0.0, m.count, 0), None, None);
        synthesize(dict, coeffs, signal);
        return descend(&Descent { dict, cfg, ball: &ball, plan }, ws);
    }
    if let Some(outcome) = short_path(cfg, ws) {
        return Ok(outcome);
    }
    let Workspace { signal, measurements: m, response, .. } = ws;
    if mixed {
        mixed_start(dict, response, m, signal, fill);
    } else if fill {
        fill_bands::<S>(m, signal);
    } else {
        // Minimum-norm start: S0 = analysis of the measurements, zeros elsewhere.
        for ((x, &y), &k) in signal.iter_mut().zip(m.values.iter()).zip(m.measured.iter()) {
            *x = if k { y } else { 0.0 };
        }
    }
    descend(&Descent { dict, cfg, ball: &ball, plan }, ws)
}

/// The short path for a flat patch: if every band is measured and each band's
/// measurements lie within `cfg.flat` of each other, `ws.patch()` becomes each band's
/// mean (measured entries keep their values, so the patch meets the measurements).
/// Otherwise `ws.patch()` is left as it was.
fn short_path<S: Shape>(cfg: &Sl0Config, ws: &mut Workspace<S>) -> Option<Outcome> {
    let Workspace { signal, measurements: m, response, .. } = ws;
    let (mut lo, mut hi, mut sum, mut count) = (
        <PerBand<S, _>>::splat(f32::INFINITY),
        <PerBand<S, _>>::splat(f32::NEG_INFINITY),
        <PerBand<S, _>>::splat(0.0f32),
        <PerBand<S, _>>::splat(0u32),
    );
    // The band is the last (contiguous) axis of the patch layout. Pixel by pixel, each
    // measured band from the pixel's flags as bits (each band's sum in the same order as a
    // pass over every entry), and out at the first band whose spread passes `flat`: a
    // spread only grows, so the answer is already no (on a noisy patch within a few pixels;
    // the whole pass was 2 % of a one-thread default decode, `perf record`).
    for (values, measured) in S::Bands::chunks(m.values.as_ref()).iter().zip(S::Bands::chunks(m.measured.as_ref())) {
        for b in set_flags(measured.as_ref()) {
            let (Some(&y), Some(l), Some(h), Some(s), Some(n)) =
                (values.get(b), lo.get_mut(b), hi.get_mut(b), sum.get_mut(b), count.get_mut(b))
            else {
                continue;
            };
            (*l, *h, *s, *n) = (l.min(y), h.max(y), *s + y, *n + 1);
            if *h - *l > cfg.flat {
                return None;
            }
        }
    }
    if (0..S::B).any(|b| count[b] == 0 || hi[b] - lo[b] > cfg.flat) {
        return None;
    }
    let mut mean = sum;
    for (m, &n) in mean.iter_mut().zip(count.iter()) {
        *m /= n as f32;
    }
    if mean.iter().any(|v| !v.is_finite()) {
        return None; // a sum past f32's range: the solve reports it
    }
    if !response.is_identity() {
        // The means are `R x` of the patch's one spectrum: every value is `R^-1` of them.
        response.balanced(&m.gains).unmix(&mut mean);
        for x in S::Bands::chunks_mut(signal.as_mut()) {
            *x = mean;
        }
        return Some(Outcome { iterations: 0, levels: 0, sigma0: 0.0, residual: 0.0, ended: Ended::Flat });
    }
    for ((x, values), measured) in S::Bands::chunks_mut(signal.as_mut())
        .iter_mut()
        .zip(S::Bands::chunks(m.values.as_ref()))
        .zip(S::Bands::chunks(m.measured.as_ref()))
    {
        for b in 0..S::B {
            x[b] = if measured[b] { values[b] } else { mean[b] };
        }
    }
    Some(Outcome { iterations: 0, levels: 0, sigma0: 0.0, residual: 0.0, ended: Ended::Flat })
}

/// Decodes the patch again with `dict`, starting from the patch now in `ws.patch()`
/// (another dictionary's solution, which meets the measurements) at
/// `sigma = cfg.warm_start * max |S|` of its coefficients `S` in `dict`, falling by
/// `cfg.warm_sigma_f` with `cfg.warm_steps` steps per level.
///
/// A cold start's first levels find the patch's large coefficients; a patch solved with
/// another dictionary has found them, so its re-solve starts lower and takes fewer levels,
/// and it only refines them, so it anneals with one step per level where a cold solve
/// needs three.
/// The patch in `ws.patch()` is only read; if it does not meet the measurements the first
/// projection moves it onto them.
///
/// # Errors
/// As [`solve`].
pub fn solve_warm<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    descend_from(dict, cfg, cfg.warm_sigma_f, ws)
}

/// The schedule from the patch in `ws.patch()` at `cfg.warm_start * max |S|`, falling by
/// `sigma_f` with `cfg.warm_steps` steps a level: [`solve_warm`] and [`solve_seeded`].
fn descend_from<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    sigma_f: f32,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    let ball = start::<S>(cfg, &ws.measurements)?;
    let from = Sl0Config { sigma_f, steps: cfg.warm_steps, ..*cfg };
    descend(&Descent { dict, cfg: &from, ball: &ball, plan: Plan::Annealed { scale: cfg.warm_start } }, ws)
}

/// Decodes the patch from the estimate in `ws.patch()` ([`seed`] must have prepared it):
/// [`solve_warm`]'s start (`cfg.warm_start * max |S|`) and steps per level, falling by
/// `cfg.seed_sigma_f`.
///
/// # Errors
/// As [`solve`].
pub fn solve_seeded<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    descend_from(dict, cfg, cfg.seed_sigma_f, ws)
}

/// Prepares a seeded solve: the patch in `ws.signal` is an estimate of the patch (its
/// overlapping neighbours' decode, as the tile decoder's seed gives it), not a solution.
/// A flat patch is decoded by the short path as [`solve`] does (`Some`); otherwise the
/// estimate is moved onto the measurements exactly (measured entries take their values;
/// interpolating measurements: the exact projection) and `None` says a warm solve
/// ([`solve_seeded`]) may start from it.
///
/// # Errors
/// As [`solve`].
pub fn seed<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
) -> Result<Option<Outcome>, SolveError> {
    start::<S>(cfg, &ws.measurements)?;
    let exact = Ball::new(0.0, 0.0, ws.measurements.count, 0);
    let mixed = !ws.response.is_identity();
    if ws.measurements.interpolates() {
        if mixed {
            return Err(SolveError::MixedHalfViews);
        }
        let Workspace { coeffs, signal, measurements: m, .. } = ws;
        analyze(dict, signal, coeffs);
        project_interpolating(dict, coeffs, signal, m, &exact, None, None);
        synthesize(dict, coeffs, signal);
        return Ok(None);
    }
    if let Some(outcome) = short_path(cfg, ws) {
        return Ok(Some(outcome));
    }
    if mixed {
        put_back_onto(dict, ws, &exact);
    } else {
        project::<S>(&mut ws.signal, &ws.measurements, &exact);
    }
    Ok(None)
}

/// The projection onto measurements that interpolate the patch: shares of view cells
/// behind a lenslet grid ([`project_shares`]) or a half-pixel shear ([`project_fractional`]).
fn project_interpolating<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
    rows: Option<&mut RowSums<S>>,
    weights: Option<&PerValue<S, f32>>,
) -> f32 {
    if m.shares.is_none() {
        return project_fractional(dict, coeffs, scratch, m, ball, weights);
    }
    match rows {
        Some(rows) => project_shares(dict, coeffs, scratch, m, ball, rows, weights),
        None => project_shares_once(dict, coeffs, scratch, m, ball),
    }
}

/// One projection behind a lenslet grid outside a descent (a start, a seed): its
/// [`RowSums`] (32 KB for the full-view patch) in a frame of its own, only behind a grid.
#[inline(never)]
fn project_shares_once<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
) -> f32 {
    project_shares(dict, coeffs, scratch, m, ball, &mut RowSums::new(), None)
}

/// How a descent walks sigma down: the hand-set schedule of the config from `scale` times
/// the start's largest coefficient, or a trained [`Schedule`].
#[derive(Clone, Copy)]
enum Plan<'s, S: Shape> {
    Annealed { scale: f32 },
    Trained(&'s Schedule<S>),
}

/// One descent's configuration, apart from the workspace it runs in: the dictionary, the
/// solver's config, the ball its projections move onto and its [`Plan`].
struct Descent<'a, S: Shape> {
    dict: &'a Dictionary<S>,
    cfg: &'a Sl0Config,
    ball: &'a Ball,
    plan: Plan<'a, S>,
}

/// Decodes the patch whose measurements are in `ws` with a trained schedule's steps
/// ([`crate::operators::schedule`]), from the start the schedule names: the minimum-norm
/// solution or the band-gain fill (the config's `cold_start` is the hand-set schedule's).
/// As [`solve`] otherwise: the flat short path, half-pixel shears, the noise ball.
///
/// # Errors
/// As [`solve`].
pub fn solve_scheduled<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    schedule: &Schedule<S>,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    cold(dict, cfg, ws, schedule.fill_start(), Plan::Trained(schedule))
}

/// Decodes the patch again with `dict` and a trained schedule, starting from the estimate
/// in `ws.patch()`: another member's solution (the screened choice's second solve), or a
/// seed that [`seed`] prepared. `sigma0` is the estimate's largest coefficient in `dict`.
///
/// # Errors
/// As [`solve`].
pub fn solve_warm_scheduled<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    schedule: &Schedule<S>,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    let ball = start::<S>(cfg, &ws.measurements)?;
    descend(&Descent { dict, cfg, ball: &ball, plan: Plan::Trained(schedule) }, ws)
}

/// The descent `d` from the patch in `ws.signal`.
fn descend<S: Shape>(d: &Descent<'_, S>, ws: &mut Workspace<S>) -> Result<Outcome, SolveError> {
    if !ws.response.is_identity() {
        return descend_mixed(d, ws);
    }
    if ws.measurements.shares.is_some() {
        return descend_shared(d, ws);
    }
    descend_with(d, ws, None, None)
}

/// [`descend`] behind a lenslet grid: the solve's [`RowSums`] (32 KB for the full-view
/// patch) in a frame of its own, so the other solves' stacks do not carry them.
#[inline(never)]
fn descend_shared<S: Shape>(d: &Descent<'_, S>, ws: &mut Workspace<S>) -> Result<Outcome, SolveError> {
    let mut rows = RowSums::new();
    descend_with(d, ws, None, Some(&mut rows))
}

/// [`descend`] with a response that mixes bands: its [`BandModel`] (2 KB) in a frame of its
/// own, so the one-hot solve's stack does not carry it.
#[inline(never)]
fn descend_mixed<S: Shape>(d: &Descent<'_, S>, ws: &mut Workspace<S>) -> Result<Outcome, SolveError> {
    if ws.measurements.interpolates() {
        return Err(SolveError::MixedHalfViews);
    }
    let model = BandModel::new(&ws.response.balanced(&ws.measurements.gains), &d.dict.d.m5);
    descend_with(d, ws, Some(&model), None)
}

/// [`descend`]'s body: projections onto the mixed measurements of `mixing` if given, and
/// behind a lenslet grid with the solve's `rows`.
fn descend_with<S: Shape>(
    d: &Descent<'_, S>,
    ws: &mut Workspace<S>,
    mixing: Option<&BandModel<S::Bands>>,
    mut rows: Option<&mut RowSums<S>>,
) -> Result<Outcome, SolveError> {
    let Descent { dict, cfg, ball, plan } = *d;
    let Workspace { coeffs, signal, measurements: m, weights, .. } = ws;
    let selection = !m.interpolates();
    analyze(dict, signal, coeffs);
    let top = max_abs(coeffs.as_ref());
    // The measurements' weights once a solve, not once a step (every projection but the
    // mixed one, whose measurements are not the patch's entries).
    let table = if mixing.is_none() && ball.is_weighted() {
        weigh::<S>(m, ball, weights);
        Some(&*weights)
    } else {
        None
    };
    let mut step = |inv: f32, mu: f32, weights: Option<&Weights<S>>| {
        let step2 = match weights {
            Some(w) => ascend_weighted(coeffs.as_mut(), mu, inv, w),
            None => ascend(coeffs.as_mut(), mu, inv),
        };
        let residual = if let Some(model) = mixing {
            project_mixed(dict, model, coeffs, signal, m, ball)
        } else if selection {
            project_coefficients(dict, coeffs, signal, m, ball, table)
        } else {
            project_interpolating(dict, coeffs, signal, m, ball, rows.as_deref_mut(), table)
        };
        // From a point that meets the measurements, the step d moves the patch by D d on
        // the unmeasured values only (the projection puts the measured ones back), and D
        // is orthonormal: |moved|^2 = |d|^2 - residual^2, with no extra pass. With a noise
        // ball, or measurements that interpolate (their residual is not the step's part
        // the projection removes), |d| bounds it.
        // Mixed measurements' rows are not orthonormal either: |d| bounds it.
        let moved2 = if ball.is_exact() && selection && mixing.is_none() { step2 - residual * residual } else { step2 };
        Step { residual, moved: libm::sqrtf(moved2.max(0.0)) }
    };
    let outcome = match plan {
        Plan::Annealed { scale } => run_schedule(cfg, scale * top, S::N, |inv| step(inv, cfg.mu, None)),
        Plan::Trained(schedule) => run_trained(cfg, schedule, top, |inv, mu| step(inv, mu, Some(schedule.weights()))),
    };

    synthesize(dict, coeffs, signal);
    if let Some(model) = mixing {
        // A measured entry is not its measurement: the per-pixel projection puts them back.
        project_signal::<S>(model, signal, m, ball);
    } else if selection {
        // Rounding of the transforms aside the patch meets the measurements; put them back
        // exactly (interpolating ones: the last step's projection is the last word).
        project::<S>(signal, m, ball);
    }
    if signal.iter().any(|x| !x.is_finite()) {
        return Err(SolveError::NonFiniteResult);
    }
    Ok(outcome)
}

/// The cold start with a response that mixes bands: the minimum-norm start `R_F^+ y` per
/// pixel, or the fill moved onto the measurements by the same per-pixel projection
/// (unmixing the fill by `R^-1` instead amplifies its errors: balanced, `R`'s leaks scale
/// by the bands' gain ratios). Out of line: its [`BandModel`] stays off the one-hot
/// solve's stack.
#[inline(never)]
fn mixed_start<S: Shape>(
    dict: &Dictionary<S>,
    response: &Response<S::Bands>,
    m: &Measurements<S::Values>,
    signal: &mut PerValue<S, f32>,
    fill: bool,
) {
    let model = BandModel::new(&response.balanced(&m.gains), &dict.d.m5);
    if fill {
        fill_bands::<S>(m, signal);
        project_signal::<S>(&model, signal, m, &Ball::new(0.0, 0.0, m.count, 0));
    } else {
        min_norm::<S>(&model, m, signal);
    }
}

/// After a blend of two solutions' unmeasured entries ([`crate::solver::choice`]'s weighted
/// mean): with mixed measurements the measured entries are the second solution's, not the
/// measurements, so the blend is moved back onto them (onto `cfg`'s ball) by the per-pixel
/// projection. With one-hot filters the blend meets them already and nothing is done.
pub(crate) fn put_back<S: Shape>(
    dict: &Dictionary<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
) -> Result<(), SolveError> {
    if ws.response.is_identity() {
        return Ok(());
    }
    let ball = start::<S>(cfg, &ws.measurements)?;
    put_back_onto(dict, ws, &ball);
    Ok(())
}

/// The patch in `ws.signal` moved onto its mixed measurements (onto `ball`) by the
/// per-pixel projection. Out of line: its [`BandModel`] stays off the callers' stack.
#[inline(never)]
fn put_back_onto<S: Shape>(dict: &Dictionary<S>, ws: &mut Workspace<S>, ball: &Ball) {
    let model = BandModel::new(&ws.response.balanced(&ws.measurements.gains), &dict.d.m5);
    project_signal::<S>(&model, &mut ws.signal, &ws.measurements, ball);
}
