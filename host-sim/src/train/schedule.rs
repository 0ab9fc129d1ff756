//! Training a schedule ([`slf_firmware::schedule`]): SL0 unrolled to `T` steps, its
//! per-step `sigma` and `mu` and the penalty's group weights learned by gradients through
//! the steps (LISTA / ALISTA-style: the operators stay the dictionaries).
//!
//! **The problem.** Patches of realistic training scenes (never test scenes, never data
//! under a non-commercial licence), white-balanced as the decoder balances a capture, each
//! measured through a random mask pattern of the families the camera ships (pixel at 1 and
//! 3 snapshots, lenslet at 3). A solve is the firmware's own steps: the weighted ascent
//! ([`slf_firmware::ascent::ascend_weighted`]) and the projection
//! ([`slf_firmware::projection::project_coefficients`]); the loss is the mean squared error
//! of the decoded patch after the last step.
//!
//! **The gradients.** A step maps the coefficients `s` to `P(A(s))`: the ascent
//! `A(s)_i = s_i - mu s_i exp(-w_i s_i^2 inv)` is elementwise, and the projection
//! `P(z) = z + D^T M^T (y - M D z)` is affine with a symmetric linear part, so its adjoint
//! is the same projection with the measurements set to zero. Backwards through the steps,
//! per coefficient:
//!
//! - `dA/ds = 1 - mu a (1 - 2 w s^2 inv)`, `a = exp(-w s^2 inv)`;
//! - `dA/dmu = -s a`, `dA/dinv = mu w s^3 a`, `dA/dw = mu inv s^3 a`.
//!
//! The parameters are trained in unconstrained forms: `log sigma_t` (a fraction of the
//! start's largest coefficient), `mu_t = 2 sigmoid(p_t)` (in (0, 2)), `log w` per mode
//! index; Adam on mini-batches. A test compares the gradients with finite differences.
//!
//! **Three schedules** ([`Schedules`]). The cold one is trained from the minimum-norm start
//! with the DCT (the screened choice's first solve); then, with the cold one fixed, the warm
//! one from each patch's cold solution, with the member the screen picks for it (the second
//! solve; a seeded solve starts from a like estimate); then the alone one, the DCT decoding
//! alone (the preview) from the band-gain fill.
//!
//! Deterministic: patches, masks and batches come from one seed, per-patch gradients are
//! summed in order, and every exponential and logarithm is `libm`'s (not the platform C
//! library's, which may differ between machines), so the same inputs give the same blob
//! bytes on any thread count and machine of the same build.

use crate::io::patch::{
    BANDS, HostDictionary, HostEnsemble, HostSchedule, HostSchedules, HostShape, HostWeights, LENSLETS,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use slf_firmware::Shape;
use slf_firmware::ascent::ascend_weighted;
use slf_firmware::ball::Ball;
use slf_firmware::choice::ChoiceRule;
use slf_firmware::projection::project_coefficients;
use slf_firmware::schedule::{MAX_STEPS, Schedule, Schedules, Weights};
use slf_firmware::shape::ValueCount;
use slf_firmware::transform::{analyze, analyze_preserving, synthesize};
use slf_firmware::workspace::Measurements;
use slf_firmware::{LensletSize, Mask};

/// The patch's mode sizes (5 x 5 lenslets, `PU x PV` views, 13 bands).
const fn dims<const PU: usize, const PV: usize>() -> [usize; 5] {
    [LENSLETS, LENSLETS, PU, PV, BANDS]
}

/// The floor of every step's sigma: the decoder's `Sl0Config::DEFAULT.sigma_min`.
const SIGMA_MIN: f32 = slf_firmware::Sl0Config::DEFAULT.sigma_min;

/// Added to a patch's squared error before its log: errors below it (PSNR above 70 dB) no
/// longer pull the schedule.
pub const LOSS_FLOOR: f64 = 1e-7;

/// Training parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScheduleConfig {
    /// Steps of the cold schedule.
    pub cold_steps: usize,
    /// Steps of the warm schedule.
    pub warm_steps: usize,
    /// Training patches.
    pub patches: usize,
    /// Adam iterations per schedule.
    pub iterations: usize,
    /// Patches per iteration.
    pub batch: usize,
    /// Adam's step size (on the log and logit parameters).
    pub rate: f32,
    pub seed: u64,
    /// Steps of the alone schedule (a dictionary decoding alone).
    pub alone_steps: usize,
    /// Show a progress bar.
    pub progress: bool,
}

impl Default for ScheduleConfig {
    fn default() -> Self {
        Self {
            cold_steps: 24,
            warm_steps: 16,
            patches: 1024,
            iterations: 120,
            batch: 64,
            rate: 0.05,
            seed: 1,
            alone_steps: 24,
            progress: false,
        }
    }
}

/// One training patch: the truth's coefficients in the solving dictionary, its
/// measurements, and the same measurement pattern with zero values (the projection's
/// adjoint).
pub struct Problem<const N: usize> {
    /// The patch, in the patch layout.
    pub truth: Vec<f32>,
    pub measurements: Box<Measurements<ValueCount<N>>>,
    zero: Box<Measurements<ValueCount<N>>>,
}

impl<const N: usize> Problem<N> {
    /// The patch `truth` measured where `measured` says.
    pub fn new(truth: &[f32], measured: &[bool]) -> Self {
        let mut m = Box::new(Measurements::new());
        let mut zero = Box::new(Measurements::new());
        for (i, (&x, &k)) in truth.iter().zip(measured).enumerate() {
            if k {
                // In range and finite: the patch's own index and a rendered value.
                let _ = m.set(i, x);
                let _ = zero.set(i, 0.0);
            }
        }
        Self { truth: truth.to_vec(), measurements: m, zero }
    }
}

/// A random measurement pattern of patch `N` (5 x 5 lenslets of `PU x PV` views): pixel
/// k = 1 half of the time, pixel k = 3 or lenslet k = 3 a quarter each, from a random mask
/// seed and sensor position.
pub fn random_pattern<const PU: usize, const PV: usize, const N: usize>(rng: &mut ChaCha8Rng) -> Vec<bool> {
    let lenslet = LensletSize { rows: PU as u8, cols: PV as u8 };
    let seed = rng.random::<u64>();
    let mask = match rng.random_range(0..4) {
        0 | 1 => Mask::pixel(seed, 1, 13, lenslet),
        2 => Mask::pixel(seed, 3, 13, lenslet),
        _ => Mask::lenslet(seed, 3, 13, lenslet),
    };
    let Ok(mask) = mask else { return vec![true; N] };
    let (r0, c0) = (rng.random_range(0..200usize), rng.random_range(0..200usize));
    let mut measured = vec![false; N];
    for (i, m) in measured.iter_mut().enumerate() {
        let [s, t, u, v, b] = HostShape::<PU, PV, N>::coordinates(i);
        let (row, col) = ((r0 + s) * PU + u, (c0 + t) * PV + v);
        *m = mask.bands_at(row, col).iter().any(|&x| x as usize == b);
    }
    measured
}

/// Leaves out, a quarter of the time, the measurements of the patch's brightest values
/// (above a random quantile from 0.6 to 1 of its values) as a saturated capture does: the
/// decoder flags clipped samples and solves without them, so the schedule learns patches
/// with holes too. At least one measurement stays.
pub fn clip_bright(truth: &[f32], measured: &mut [bool], rng: &mut ChaCha8Rng) {
    if rng.random_range(0..4) != 0 {
        return;
    }
    let mut sorted: Vec<f32> = truth.to_vec();
    sorted.sort_by(f32::total_cmp);
    let q = rng.random_range(0.6f64..1.0);
    let limit = sorted[((sorted.len() - 1) as f64 * q) as usize];
    let kept = truth.iter().zip(measured.iter()).filter(|(x, m)| **m && **x <= limit).count();
    if kept > 0 {
        measured.iter_mut().zip(truth).filter(|(_, x)| **x > limit).for_each(|(m, _)| *m = false);
    }
}

/// A schedule's trainable parameters, unconstrained.
#[derive(Clone, Debug, PartialEq)]
pub struct Params<const PU: usize, const PV: usize> {
    /// `log sigma_t` (fraction of the start's largest coefficient).
    pub log_sigma: Vec<f32>,
    /// `mu_t = 2 sigmoid(p_t)`.
    pub mu_logit: Vec<f32>,
    /// `log w` per mode index.
    pub log_weights: [Vec<f32>; 5],
}

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + libm::expf(-x))
}

impl<const PU: usize, const PV: usize> Params<PU, PV> {
    /// `steps` steps, sigma falling geometrically from `from` to `to` (fractions of the
    /// start's largest coefficient), `mu` 1, every weight 1.
    pub fn geometric(steps: usize, from: f32, to: f32) -> Self {
        let at = |t: usize| if steps > 1 { t as f32 / (steps - 1) as f32 } else { 0.0 };
        Self {
            log_sigma: (0..steps).map(|t| libm::logf(from) + at(t) * (libm::logf(to) - libm::logf(from))).collect(),
            mu_logit: vec![0.0; steps],
            log_weights: dims::<PU, PV>().map(|d| vec![0.0; d]),
        }
    }

    /// The parameters as one vector (Adam's view).
    fn flat(&self) -> Vec<f32> {
        let mut v = self.log_sigma.clone();
        v.extend(&self.mu_logit);
        self.log_weights.iter().for_each(|w| v.extend(w));
        v
    }

    fn set_flat(&mut self, v: &[f32]) {
        let mut it = v.iter().copied();
        self.log_sigma.iter_mut().chain(&mut self.mu_logit).for_each(|x| *x = it.next().unwrap_or(*x));
        self.log_weights.iter_mut().flatten().for_each(|x| *x = it.next().unwrap_or(*x));
    }

    /// Each step's sigma fraction, in (0, 1].
    pub fn sigma(&self) -> Vec<f32> {
        self.log_sigma.iter().map(|&l| libm::expf(l).clamp(1e-7, 1.0)).collect()
    }

    /// Each step's mu, in (0, 2).
    pub fn mu(&self) -> Vec<f32> {
        self.mu_logit.iter().map(|&p| (2.0 * sigmoid(p)).clamp(1e-6, 2.0)).collect()
    }

    /// The group weights, in [1/64, 64].
    pub fn weights<const N: usize>(&self) -> HostWeights<PU, PV, N> {
        let mut w = Weights::ONES;
        for (mode, logs) in w.modes_mut().into_iter().zip(&self.log_weights) {
            for (x, l) in mode.iter_mut().zip(logs) {
                *x = libm::expf(*l).clamp(1.0 / 64.0, 64.0);
            }
        }
        w
    }

    /// The firmware's schedule.
    ///
    /// # Errors
    /// More than [`MAX_STEPS`] steps.
    pub fn schedule<const N: usize>(&self) -> anyhow::Result<HostSchedule<PU, PV, N>> {
        Schedule::new(&self.sigma(), &self.mu(), self.weights()).map_err(|e| anyhow::anyhow!("{e}"))
    }
}

/// The coefficients after each step of a solve (index 0: the start), for the backward pass.
pub struct Trajectory {
    pub coeffs: Vec<Vec<f32>>,
    /// Each step's `inv = 1 / (2 sigma^2)`, and whether sigma sat at its floor.
    pub inv: Vec<(f32, bool)>,
}

/// The start of a solve from `signal` (a patch estimate; zeros in the unmeasured entries
/// for the cold start): analysed in `dict`, projected onto the measurements.
pub fn start<const PU: usize, const PV: usize, const N: usize>(
    dict: &HostDictionary<PU, PV, N>,
    problem: &Problem<N>,
    signal: &[f32],
) -> Vec<f32> {
    let mut x: Box<[f32; N]> = Box::new([0.0; N]);
    x.copy_from_slice(signal);
    let mut c: Box<[f32; N]> = Box::new([0.0; N]);
    analyze(dict, &mut x, &mut c);
    let exact = Ball::new(0.0, 0.0, problem.measurements.count() as u32, 0);
    project_coefficients(dict, &mut c, &mut x, &problem.measurements, &exact, None);
    c.to_vec()
}

/// A cold solve's start as a patch: the band-gain fill ([`slf_firmware::solver::fill`]), or
/// the measurements with zeros elsewhere.
pub fn cold_start<const PU: usize, const PV: usize, const N: usize>(problem: &Problem<N>, fill: bool) -> Vec<f32> {
    if fill {
        let mut x: Box<[f32; N]> = Box::new([0.0; N]);
        slf_firmware::solver::fill::fill_bands::<HostShape<PU, PV, N>>(&problem.measurements, &mut x);
        x.to_vec()
    } else {
        (0..N).map(|i| problem.measurements.get(i).unwrap_or(0.0)).collect()
    }
}

/// The solve from `start` (coefficients in `dict`), keeping every step's coefficients.
pub fn unroll<const PU: usize, const PV: usize, const N: usize>(
    dict: &HostDictionary<PU, PV, N>,
    schedule: &HostSchedule<PU, PV, N>,
    problem: &Problem<N>,
    start: &[f32],
) -> Trajectory {
    let exact = Ball::new(0.0, 0.0, problem.measurements.count() as u32, 0);
    let sigma0 = start.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let mut c: Box<[f32; N]> = Box::new([0.0; N]);
    c.copy_from_slice(start);
    let mut scratch: Box<[f32; N]> = Box::new([0.0; N]);
    let mut out = Trajectory { coeffs: vec![start.to_vec()], inv: Vec::new() };
    for (&fraction, &mu) in schedule.sigma().iter().zip(schedule.mu()) {
        let sigma = fraction * sigma0;
        let floored = sigma <= SIGMA_MIN;
        let sigma = if floored { SIGMA_MIN } else { sigma };
        let inv = 1.0 / (2.0 * sigma * sigma);
        ascend_weighted(&mut c[..], mu, inv, schedule.weights());
        project_coefficients(dict, &mut c, &mut scratch, &problem.measurements, &exact, None);
        out.coeffs.push(c.to_vec());
        out.inv.push((inv, floored));
    }
    out
}

/// The decoded patch of a solve's last coefficients.
pub fn patch_of<const PU: usize, const PV: usize, const N: usize>(
    dict: &HostDictionary<PU, PV, N>,
    coeffs: &[f32],
) -> Vec<f32> {
    let mut c: Box<[f32; N]> = Box::new([0.0; N]);
    c.copy_from_slice(coeffs);
    let mut x: Box<[f32; N]> = Box::new([0.0; N]);
    synthesize(dict, &mut c, &mut x);
    x.to_vec()
}

/// The log of the squared error per value of the solve's end against the truth (plus
/// [`LOSS_FLOOR`]), and its gradient with respect to every parameter (in [`Params::flat`]'s
/// order).
pub fn loss_and_gradient<const PU: usize, const PV: usize, const N: usize>(
    dict: &HostDictionary<PU, PV, N>,
    params: &Params<PU, PV>,
    schedule: &HostSchedule<PU, PV, N>,
    problem: &Problem<N>,
    start: &[f32],
) -> (f64, Vec<f64>) {
    let path = unroll(dict, schedule, problem, start);
    let Some(last) = path.coeffs.last() else { return (0.0, vec![0.0; params.flat().len()]) };
    // Orthonormal D: ||D s - x||^2 = ||s - D^T x||^2.
    let mut truth: Box<[f32; N]> = Box::new([0.0; N]);
    truth.copy_from_slice(&problem.truth);
    let mut truth_c: Box<[f32; N]> = Box::new([0.0; N]);
    analyze(dict, &mut truth, &mut truth_c);
    let n = N as f64;
    let mse = last.iter().zip(truth_c.iter()).map(|(s, t)| f64::from(s - t).powi(2)).sum::<f64>() / n;
    // The loss is the log of the patch's error: each patch counts by its PSNR, so the
    // smooth patches a decode makes nearly exact weigh as much as the textured ones whose
    // squared error is a thousand times theirs (on the squared error the schedule learned
    // the textured patches and lost 4 dB on a smooth real scene).
    let loss = libm::log(mse + LOSS_FLOOR);
    let mut g: Box<[f32; N]> = Box::new([0.0; N]);
    for ((g, s), t) in g.iter_mut().zip(last).zip(truth_c.iter()) {
        *g = (2.0 * f64::from(s - t) / n / (mse + LOSS_FLOOR)) as f32;
    }
    let steps = schedule.len();
    let (mut d_sigma, mut d_mu) = (vec![0.0f64; steps], vec![0.0f64; steps]);
    let mut d_w: [Vec<f64>; 5] = dims::<PU, PV>().map(|d| vec![0.0; d]);
    let exact = Ball::new(0.0, 0.0, problem.zero.count() as u32, 0);
    let mut scratch: Box<[f32; N]> = Box::new([0.0; N]);
    let weights = schedule.weights();
    let mu_all = schedule.mu();
    for t in (0..steps).rev() {
        // Through the projection: its linear part is its own adjoint.
        project_coefficients(dict, &mut g, &mut scratch, &problem.zero, &exact, None);
        let (inv, floored) = path.inv[t];
        let mu = mu_all[t];
        let (mut dmu, mut dinv) = (0.0f64, 0.0f64);
        for (i, (g, &s)) in g.iter_mut().zip(&path.coeffs[t]).enumerate() {
            let idx = HostShape::<PU, PV, N>::coordinates(i);
            let w = weights.at(idx);
            let x = w * s * s * inv;
            let a = libm::expf(-x);
            let gz = *g;
            dmu += f64::from(gz * (-s * a));
            dinv += f64::from(gz * mu * w * s * s * s * a);
            let dw = f64::from(gz * mu * inv * s * s * s * a * w);
            for (mode, &j) in idx.iter().enumerate() {
                d_w[mode][j] += dw;
            }
            *g = gz * (1.0 - mu * a * (1.0 - 2.0 * x));
        }
        // inv = 1 / (2 (f sigma0)^2): d inv / d log f = -2 inv, unless sigma sat at its floor.
        d_sigma[t] = if floored { 0.0 } else { dinv * -2.0 * f64::from(inv) };
        // mu = 2 sigmoid(p): d mu / d p = mu (1 - mu / 2).
        d_mu[t] = dmu * f64::from(mu * (1.0 - mu / 2.0));
    }
    let mut grad = d_sigma;
    grad.extend(d_mu);
    d_w.iter().for_each(|w| grad.extend(w));
    (loss, grad)
}

/// Adam's state.
struct Adam {
    m: Vec<f64>,
    v: Vec<f64>,
    t: i32,
}

impl Adam {
    fn new(n: usize) -> Self {
        Self { m: vec![0.0; n], v: vec![0.0; n], t: 0 }
    }

    fn step(&mut self, x: &mut [f32], g: &[f64], rate: f64) {
        const B1: f64 = 0.9;
        const B2: f64 = 0.999;
        self.t += 1;
        for (((x, g), m), v) in x.iter_mut().zip(g).zip(&mut self.m).zip(&mut self.v) {
            *m = B1 * *m + (1.0 - B1) * g;
            *v = B2 * *v + (1.0 - B2) * g * g;
            let mh = *m / (1.0 - B1.powi(self.t));
            let vh = *v / (1.0 - B2.powi(self.t));
            *x -= (rate * mh / (vh.sqrt() + 1e-12)) as f32;
        }
    }
}

/// One training report line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The loss (mean over the batch of the log squared error) of the first and the last
    /// iteration.
    pub first: f64,
    pub last: f64,
}

impl Fit {
    /// A loss as the mean PSNR (dB, peak 1) it stands for.
    pub fn psnr(loss: f64) -> f64 {
        -10.0 * loss / core::f64::consts::LN_10
    }
}

/// Trains `params` on `problems`, each with its dictionary index into `dicts` and its start.
fn fit<const PU: usize, const PV: usize, const N: usize>(
    params: &mut Params<PU, PV>,
    dicts: &[HostDictionary<PU, PV, N>],
    problems: &[(usize, Problem<N>, Vec<f32>)],
    cfg: &ScheduleConfig,
    seed: u64,
) -> anyhow::Result<Fit> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut x = params.flat();
    let mut adam = Adam::new(x.len());
    let mut fit = Fit { first: f64::NAN, last: f64::NAN };
    let bar = crate::train::ensemble::progress_bar(cfg.iterations as u64, cfg.progress);
    for _ in 0..cfg.iterations {
        let batch: Vec<usize> =
            (0..cfg.batch.min(problems.len())).map(|_| rng.random_range(0..problems.len())).collect();
        let schedule = params.schedule()?;
        let parts: Vec<(f64, Vec<f64>)> = batch
            .par_iter()
            .map(|&i| {
                let (d, p, s) = &problems[i];
                loss_and_gradient(&dicts[*d], params, &schedule, p, s)
            })
            .collect();
        let mut grad = vec![0.0f64; x.len()];
        let mut loss = 0.0;
        for (l, g) in &parts {
            loss += l;
            grad.iter_mut().zip(g).for_each(|(a, b)| *a += b);
        }
        let k = parts.len().max(1) as f64;
        grad.iter_mut().for_each(|g| *g /= k);
        if fit.first.is_nan() {
            fit.first = loss / k;
        }
        fit.last = loss / k;
        adam.step(&mut x, &grad, f64::from(cfg.rate));
        params.set_flat(&x);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(fit)
}

/// Mean squared error per value of solving every problem with `schedule`.
pub fn mean_error<const PU: usize, const PV: usize, const N: usize>(
    dicts: &[HostDictionary<PU, PV, N>],
    schedule: &HostSchedule<PU, PV, N>,
    problems: &[(usize, Problem<N>, Vec<f32>)],
) -> f64 {
    let errors: Vec<f64> = problems
        .par_iter()
        .map(|(d, p, s)| {
            let path = unroll(&dicts[*d], schedule, p, s);
            let x = patch_of::<PU, PV, N>(&dicts[*d], path.coeffs.last().map_or(&[][..], |c| c));
            x.iter().zip(&p.truth).map(|(a, b)| f64::from(a - b).powi(2)).sum::<f64>() / N as f64
        })
        .collect();
    errors.iter().sum::<f64>() / errors.len().max(1) as f64
}

/// What training did, for the command's table.
#[derive(Clone, Debug, PartialEq)]
pub struct ScheduleReport {
    pub cold: Fit,
    pub warm: Fit,
    pub alone: Fit,
}

/// Trains the cold and the warm schedule for `members` (member `dct`, if any, is the DCT
/// the screen solves with; without one the DCT is used anyway) on `patches` (flat, the
/// patch layout, white-balanced), one random mask pattern each.
///
/// # Errors
/// More steps than [`MAX_STEPS`], or no patch.
pub fn train<const PU: usize, const PV: usize, const N: usize>(
    members: &[HostDictionary<PU, PV, N>],
    dct: Option<usize>,
    patches: &[f32],
    cfg: &ScheduleConfig,
) -> anyhow::Result<(HostSchedules<PU, PV, N>, ScheduleReport)> {
    anyhow::ensure!(
        [cfg.cold_steps, cfg.warm_steps, cfg.alone_steps].iter().all(|s| (1..=MAX_STEPS).contains(s)),
        "schedule steps: 1 to {MAX_STEPS} each (cold {}, warm {}, alone {})",
        cfg.cold_steps,
        cfg.warm_steps,
        cfg.alone_steps
    );
    anyhow::ensure!(patches.len() >= N, "no training patch");
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let screen = HostDictionary::<PU, PV, N>::dct();
    let mut dicts = vec![screen];
    dicts.extend_from_slice(members);
    let problems: Vec<Problem<N>> = patches
        .chunks_exact(N)
        .map(|truth| {
            let mut pattern = random_pattern::<PU, PV, N>(&mut rng);
            clip_bright(truth, &mut pattern, &mut rng);
            Problem::new(truth, &pattern)
        })
        .collect();
    // The screened choice's first solve: the DCT from the minimum-norm start.
    let cold_problems: Vec<(usize, Problem<N>, Vec<f32>)> = problems
        .into_par_iter()
        .map(|p| {
            let s = start(&dicts[0], &p, &cold_start::<PU, PV, N>(&p, false));
            (0, p, s)
        })
        .collect();
    let mut cold = Params::<PU, PV>::geometric(cfg.cold_steps, 1.0, 1e-4);
    let cold_fit = fit(&mut cold, &dicts, &cold_problems, cfg, cfg.seed + 1)?;
    let cold_schedule = cold.schedule()?;
    // The warm solve: each patch's cold solution, in the member the screen picks for it.
    let rule = ChoiceRule::DEFAULT;
    let learned: Vec<usize> = (0..members.len()).filter(|&k| Some(k) != dct).collect();
    let warm_starts: Vec<(usize, Vec<f32>)> = cold_problems
        .par_iter()
        .map(|(_, p, s)| {
            let path = unroll(&dicts[0], &cold_schedule, p, s);
            let x = patch_of::<PU, PV, N>(&dicts[0], path.coeffs.last().map_or(&[][..], |c| c));
            let mut signal: Box<[f32; N]> = Box::new([0.0; N]);
            signal.copy_from_slice(&x);
            let mut c: Box<[f32; N]> = Box::new([0.0; N]);
            let pick = learned
                .iter()
                .map(|&k| {
                    analyze_preserving(&members[k], &signal, &mut c);
                    (rule.score(&c[..]), k)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map_or(0, |(_, k)| k + 1);
            (pick, start(&dicts[pick], p, &x))
        })
        .collect();
    let mut warm_problems: Vec<(usize, Problem<N>, Vec<f32>)> =
        cold_problems.into_iter().zip(warm_starts).map(|((_, p, _), (pick, s))| (pick, p, s)).collect();
    let mut warm = Params::<PU, PV>::geometric(cfg.warm_steps, 1e-2, 1e-4);
    let warm_fit = fit(&mut warm, &dicts, &warm_problems, cfg, cfg.seed + 2)?;
    // A dictionary alone (the DCT of the preview): from the band-gain fill (measured: 1.2-2.8
    // dB over the minimum-norm start on the realistic set with nothing solved after it).
    for (d, p, s) in &mut warm_problems {
        *d = 0;
        *s = start(&dicts[0], p, &cold_start::<PU, PV, N>(p, true));
    }
    let mut alone = Params::<PU, PV>::geometric(cfg.alone_steps, 1.0, 1e-4);
    let alone_fit = fit(&mut alone, &dicts, &warm_problems, cfg, cfg.seed + 3)?;
    let schedules =
        Schedules { cold: cold_schedule, warm: warm.schedule()?, alone: alone.schedule()?.with_fill_start(true) };
    Ok((schedules, ScheduleReport { cold: cold_fit, warm: warm_fit, alone: alone_fit }))
}

/// `slf train-schedule`: trains the cold and the warm schedule for the ensemble in `blob` on
/// `patches` patches of `fields` (white-balanced), prints what training did as a markdown
/// table, and writes the ensemble with its schedules (a version 2 blob) to `output`.
///
/// # Errors
/// A blob that does not validate, a light field too small for its patch, bad steps, or an
/// unwritable `output`.
pub fn train_schedule_blob(
    blob: &[u8],
    fields: &[crate::io::lightfield::LightField],
    cfg: &ScheduleConfig,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    use crate::decode::cs::PatchViews;
    match PatchViews::of_blob(blob) {
        Some(PatchViews::Four) => train_schedule_blob_of::<4, 4, 5200>(blob, fields, cfg, output),
        Some(PatchViews::Five) => train_schedule_blob_of::<5, 5, 8125>(blob, fields, cfg, output),
        None => anyhow::bail!("the blob is for neither the 5x5x4x4x13 nor the 5x5x5x5x13 patch"),
    }
}

fn train_schedule_blob_of<const PU: usize, const PV: usize, const N: usize>(
    blob: &[u8],
    fields: &[crate::io::lightfield::LightField],
    cfg: &ScheduleConfig,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    let start_time = std::time::Instant::now();
    let ensemble = HostEnsemble::<PU, PV, N>::new(blob).map_err(|e| anyhow::anyhow!("{e}"))?;
    let members: Vec<_> = (0..ensemble.len())
        .map(|k| ensemble.member(k).map_err(|e| anyhow::anyhow!("{e}")))
        .collect::<anyhow::Result<_>>()?;
    let dct = slf_firmware::EnsembleModel::new(ensemble, slf_firmware::MemberChoice::Screened(ChoiceRule::DEFAULT))
        .dct_member()
        .map(usize::from);
    for (i, f) in fields.iter().enumerate() {
        anyhow::ensure!(
            f.bands == 13 && f.views.0 >= PU && f.views.1 >= PV && f.rows >= 5 && f.cols >= 5,
            "training light field {i} is too small for 5x5x{PU}x{PV}x13 patches: {:?}",
            f.shape()
        );
    }
    let patches = crate::train::ensemble::sample_patches::<PU, PV, N>(fields, cfg.patches, cfg.seed);
    let (schedules, report) = train::<PU, PV, N>(&members, dct, &patches, cfg)?;
    outln!("| schedule | steps | first batch mean PSNR | last batch mean PSNR |\n| --- | --- | --- | --- |")?;
    let all = [
        ("cold", &schedules.cold, report.cold),
        ("warm", &schedules.warm, report.warm),
        ("alone", &schedules.alone, report.alone),
    ];
    for (name, s, f) in all {
        outln!("| {name} | {} | {:.2} dB | {:.2} dB |", s.len(), Fit::psnr(f.first), Fit::psnr(f.last))?;
    }
    for (name, s, _) in all {
        let list = |v: &[f32]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(" ");
        outln!("{name} sigma: {}\n{name} mu: {}", list(s.sigma()), list(s.mu()))?;
    }
    let dims = dims::<PU, PV>();
    let steps = [schedules.cold.len(), schedules.warm.len(), schedules.alone.len()];
    let len = slf_firmware::blob::scheduled_blob_len(dims, members.len(), steps);
    let mut out = vec![0u8; len];
    slf_firmware::blob::write_blob_scheduled(&members, Some(&schedules), &mut out)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    crate::io::output::write_bytes(output, &out)?;
    outln!("wrote {} ({} bytes) in {:.1} s", output.display(), out.len(), start_time.elapsed().as_secs_f64())?;
    Ok(())
}
