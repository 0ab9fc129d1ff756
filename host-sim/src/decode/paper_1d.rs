//! The paper's "1D" method, host only: the same SL0 with the explicit `N x N` Kronecker
//! dictionary `D = D1 (x) .. (x) D5` and the dense sensing matrix, for the equivalence,
//! speed and memory claims (the paper: 106x time, 1/107,729 memory).
//!
//! Also a 5D SL0 in f64 (the fast path, mode products in f64) as the f64 reference: the
//! firmware is f32 only, as the device is.

use nalgebra::{DMatrix, RealField};
use slf_firmware::Shape;
use std::time::Instant;

use anyhow::Context;
use slf_firmware::{
    Dictionary, Ended, LensletSize, Mask, MaskFamily, PaperShape, PaperWorkspace, Sl0Config, blob, solve,
};

use crate::io::patch::HostDictionary;
use crate::sim::scene::{self, SceneSize};

/// A scalar for both paths: f32 or f64.
pub trait Real: RealField + Copy + From<f32> {
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Self;
}
impl Real for f32 {
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}
impl Real for f64 {
    fn to_f64(self) -> f64 {
        self
    }
    fn from_f64(x: f64) -> Self {
        x
    }
}

/// `m x`, each dot product accumulated in f64 and rounded once to `T`: the dense 1D
/// products sum thousands of terms, and plain f32 sums would make the 1D method's rounding
/// (not the method) dominate any comparison.
pub fn matvec<T: Real>(m: &DMatrix<T>, x: &[T]) -> Vec<T> {
    let mut acc = vec![0.0f64; m.nrows()];
    // Column-major storage: accumulate column by column.
    for (col, xc) in m.column_iter().zip(x) {
        let xc = xc.to_f64();
        for (a, v) in acc.iter_mut().zip(col.iter()) {
            *a += v.to_f64() * xc;
        }
    }
    acc.into_iter().map(<T as Real>::from_f64).collect()
}

/// The five synthesis matrices of a patch (`5 x 5 x 4 x 4 x 13`, or another shape), row-major,
/// in `T`.
#[derive(Clone, Debug)]
pub struct Factors<T: Real>(pub Vec<(usize, Vec<T>)>);

impl<T: Real> Factors<T> {
    /// A firmware dictionary's matrices (f32 values, widened to `T`).
    pub fn from_dictionary<const PU: usize, const PV: usize, const N: usize>(dict: &HostDictionary<PU, PV, N>) -> Self {
        let d = dict.synthesis();
        let conv = |m: &[f32], n: usize| (n, m.iter().map(|&x| T::from(x)).collect());
        Self(vec![
            conv(d.m1.as_flattened(), 5),
            conv(d.m2.as_flattened(), 5),
            conv(d.m3.as_flattened(), PU),
            conv(d.m4.as_flattened(), PV),
            conv(d.m5.as_flattened(), 13),
        ])
    }
}

impl Factors<f64> {
    /// The 5D DCT computed in f64, orthonormal to f64 precision (the f32 tables are
    /// orthonormal only to about 1e-7, which an f64 comparison would see).
    pub fn dct_f64() -> Self {
        Self::dct_f64_of(slf_firmware::PaperShape::DIMS)
    }

    /// [`Self::dct_f64`] for a patch of `dims` (e.g. the full-view patch's `[5, 5, 5, 5, 13]`).
    pub fn dct_f64_of(dims: [usize; 5]) -> Self {
        let dct = |n: usize| -> (usize, Vec<f64>) {
            let mut m = vec![0.0; n * n];
            for k in 0..n {
                let a = if k == 0 { (1.0 / n as f64).sqrt() } else { (2.0 / n as f64).sqrt() };
                for i in 0..n {
                    // Synthesis: columns are atoms, D[i][k] = C[k][i].
                    m[i * n + k] = a * (std::f64::consts::PI * (2 * i + 1) as f64 * k as f64 / (2 * n) as f64).cos();
                }
            }
            (n, m)
        };
        Self(dims.iter().map(|&n| dct(n)).collect())
    }
}

/// The Kronecker product of the five matrices (row-major patch layout): `N x N`.
pub fn kronecker<T: Real>(f: &Factors<T>) -> DMatrix<T> {
    let mut k = DMatrix::<T>::identity(1, 1);
    for (n, m) in &f.0 {
        k = k.kronecker(&DMatrix::from_row_slice(*n, *n, m));
    }
    k
}

/// The sigma schedule of Algorithm 1, the same as the firmware's (`sl0::run_schedule`):
/// `step` returns how far it moved the patch (l2), measured directly here; a level that
/// moves it by less than `tolerance * sqrt(values)` in all ends the solve.
fn schedule<T: Real>(cfg: &Sl0Config, sigma0: T, values: usize, mut step: impl FnMut(T) -> T) -> (u32, Ended) {
    let (sigma_min, sigma_f) = (T::from(cfg.sigma_min), T::from(cfg.sigma_f));
    let stop = T::from(cfg.tolerance) * T::from(values as f32).sqrt();
    let mut sigma = sigma0;
    let mut iterations = 0u32;
    loop {
        if sigma <= sigma_min {
            return (iterations, Ended::SigmaMin);
        }
        let inv = T::one() / (T::from(2.0) * sigma * sigma);
        if !inv.is_finite() {
            return (iterations, Ended::SigmaUnderflow);
        }
        let mut moved = T::zero();
        for _ in 0..cfg.steps {
            if iterations >= cfg.max_iterations {
                return (iterations, Ended::IterationBound);
            }
            moved += step(inv);
            iterations += 1;
        }
        sigma *= sigma_f;
        if moved < stop {
            return (iterations, Ended::Converged);
        }
    }
}

/// The l2 distance between two vectors.
fn distance<T: Real>(a: &[T], b: &[T]) -> T {
    a.iter().zip(b).map(|(&x, &y)| (x - y) * (x - y)).fold(T::zero(), |acc, v| acc + v).sqrt()
}

fn ascend<T: Real>(s: &mut [T], mu: T, inv: T) {
    for x in s {
        *x -= mu * *x * (-(*x * *x) * inv).exp();
    }
}

fn max_abs<T: Real>(s: &[T]) -> T {
    s.iter().fold(T::zero(), |m, x| m.max(x.abs()))
}

/// The 1D method on one patch: dense `N x N` dictionary, sensing matrix `A` (the rows of
/// `D` the measurements select) and its pseudo-inverse, all precomputed.
pub struct Dense1D<T: Real> {
    pub d: DMatrix<T>,
    pub a: DMatrix<T>,
    pub a_pinv: DMatrix<T>,
    measured: Vec<usize>,
}

impl<T: Real> Dense1D<T> {
    /// Builds `D`, `A = Phi D` for the measured entries, and `A^+ = A^T (A A^T)^-1`.
    pub fn new(factors: &Factors<T>, measured: &[usize]) -> Option<Self> {
        let d = kronecker(factors);
        let a = d.select_rows(measured);
        let gram = &a * a.transpose();
        let a_pinv = a.transpose() * gram.cholesky()?.inverse();
        Some(Self { d, a, a_pinv, measured: measured.to_vec() })
    }

    /// Bytes of the dense matrices (D, A, A^+).
    pub fn memory_bytes(&self) -> usize {
        (self.d.len() + self.a.len() + self.a_pinv.len()) * std::mem::size_of::<T>()
    }

    /// SL0 with the 1D operators; returns the patch `x = D s`.
    pub fn solve(&self, y: &[T], cfg: &Sl0Config) -> (Vec<T>, u32) {
        let mut s = matvec(&self.a_pinv, y);
        let mu = T::from(cfg.mu);
        let (iterations, _) = schedule(cfg, max_abs(&s), s.len(), |inv| {
            let before = s.clone();
            ascend(&mut s, mu, inv);
            let r: Vec<T> = matvec(&self.a, &s).iter().zip(y).map(|(&a, &b)| a - b).collect();
            for (x, c) in s.iter_mut().zip(matvec(&self.a_pinv, &r)) {
                *x -= c;
            }
            // D is orthonormal: the patch moves as far as its coefficients.
            distance(&before, &s)
        });
        (matvec(&self.d, &s), iterations)
    }

    /// The measured entries.
    pub fn measured(&self) -> &[usize] {
        &self.measured
    }
}

/// `x x_i M_i` (or `M_i^T`) for all five modes (out of place, one mode at a time).
fn modes<T: Real>(f: &[(usize, Vec<T>)], x: &[T], transpose: bool) -> Vec<T> {
    let dims: Vec<usize> = f.iter().map(|(n, _)| *n).collect();
    let mut cur = x.to_vec();
    for (i, (n, m)) in f.iter().enumerate() {
        let inner: usize = dims[i + 1..].iter().product();
        let outer: usize = dims[..i].iter().product();
        let mut next = vec![T::zero(); cur.len()];
        for o in 0..outer {
            for a in 0..*n {
                for c in 0..*n {
                    let w = if transpose { m[c * n + a] } else { m[a * n + c] };
                    for j in 0..inner {
                        next[(o * n + a) * inner + j] += w * cur[(o * n + c) * inner + j];
                    }
                }
            }
        }
        cur = next;
    }
    cur
}

/// The 5D analysis `x x_i D_i^T` in `T` (mode products one at a time, in mode order).
pub fn analyze_5d<T: Real>(factors: &Factors<T>, x: &[T]) -> Vec<T> {
    modes(&factors.0, x, true)
}

/// The 5D synthesis `c x_i D_i` in `T` (mode products one at a time, in mode order).
pub fn synthesize_5d<T: Real>(factors: &Factors<T>, c: &[T]) -> Vec<T> {
    modes(&factors.0, c, false)
}

/// 5D SL0 (fast path) in `T`: the reference for the firmware's f32 decoder and for the
/// 1D method. `measured[i]` is `Some(y)` for a measured entry.
pub fn solve_5d<T: Real>(factors: &Factors<T>, measured: &[Option<T>], cfg: &Sl0Config) -> (Vec<T>, u32) {
    let x: Vec<T> = measured.iter().map(|y| y.unwrap_or(T::zero())).collect();
    let s = modes(&factors.0, &x, true);
    let sigma0 = max_abs(&s);
    descend_5d(factors, measured, x, s, cfg, sigma0)
}

/// Algorithm 1's schedule from the patch `x` (meeting the measurements) and its
/// coefficients `s`, from `sigma0`: the patch and the steps taken.
fn descend_5d<T: Real>(
    factors: &Factors<T>,
    measured: &[Option<T>],
    mut x: Vec<T>,
    mut s: Vec<T>,
    cfg: &Sl0Config,
    sigma0: T,
) -> (Vec<T>, u32) {
    let f = &factors.0;
    let project = |x: &mut [T]| {
        for (x, y) in x.iter_mut().zip(measured) {
            if let Some(y) = y {
                *x = *y;
            }
        }
    };
    let mu = T::from(cfg.mu);
    let (iterations, _) = schedule(cfg, sigma0, x.len(), |inv| {
        ascend(&mut s, mu, inv);
        let before = std::mem::replace(&mut x, modes(f, &s, false));
        project(&mut x);
        s = modes(f, &x, true);
        distance(&before, &x)
    });
    x = modes(f, &s, false);
    project(&mut x);
    (x, iterations)
}

/// [`solve_5d`] started from the estimate `start` (its measured entries replaced by the
/// measurements) at `cfg.warm_start` of its largest coefficient, falling by
/// `cfg.seed_sigma_f` with `cfg.warm_steps` steps a level: the seeded solve
/// (`slf_firmware::sl0::solve_seeded`) in `T`.
pub fn solve_5d_seeded<T: Real>(
    factors: &Factors<T>,
    measured: &[Option<T>],
    start: &[T],
    cfg: &Sl0Config,
) -> (Vec<T>, u32) {
    let x: Vec<T> = start.iter().zip(measured).map(|(&x, y)| y.unwrap_or(x)).collect();
    let s = modes(&factors.0, &x, true);
    let sigma0 = T::from(cfg.warm_start) * max_abs(&s);
    let seeded = Sl0Config { sigma_f: cfg.seed_sigma_f, steps: cfg.warm_steps, ..*cfg };
    descend_5d(factors, measured, x, s, &seeded, sigma0)
}

/// `slf baseline`: the 5D decoder against the 1D method on `patches` patches of the
/// texture scene (4 x 4 views): time, memory and the largest difference, printed.
///
/// # Errors
/// A mask that cannot be built, or a singular `A A^T`.
pub fn compare_1d(patches: usize, family: MaskFamily, k: u8) -> anyhow::Result<()> {
    let dict: crate::decode::cs::PaperDictionary = Dictionary::dct();
    let cfg = Sl0Config::DEFAULT;
    let truth =
        scene::named("texture").context("scene")?.render(SceneSize { views: (4, 4), rows: 5 * patches, cols: 5 });
    let lenslet = LensletSize { rows: 4, cols: 4 };
    let mask = match family {
        MaskFamily::Pixel => Mask::pixel(3, k, 13, lenslet),
        MaskFamily::Lenslet => Mask::lenslet(3, k, 13, lenslet),
        MaskFamily::Kronecker => Mask::kronecker(3, k, 13, lenslet, (5, 5)),
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (mut t5, mut t1, mut mem1) = (0.0, 0.0, 0usize);
    let mut worst = 0.0f32;
    for p in 0..patches {
        let mut ws = Box::new(PaperWorkspace::new());
        let mut measured = Vec::new();
        for i in 0..5200 {
            let [s, t, u, v, b] = PaperShape::coordinates(i);
            if mask.bands_at((5 * p + s) * 4 + u, t * 4 + v).contains(&(b as u8)) {
                let y = truth.get(u, v, 5 * p + s, t, b);
                ws.measurements_mut().set(i, y).map_err(|e| anyhow::anyhow!("{e}"))?;
                measured.push((i, y));
            }
        }
        let start = Instant::now();
        solve(&dict, &cfg, &mut ws).map_err(|e| anyhow::anyhow!("{e}"))?;
        t5 += start.elapsed().as_secs_f64();
        let idx: Vec<usize> = measured.iter().map(|m| m.0).collect();
        let y: Vec<f32> = measured.iter().map(|m| m.1).collect();
        let start = Instant::now();
        let one = Dense1D::<f32>::new(&Factors::from_dictionary(&dict), &idx).context("A A^T is singular")?;
        let setup = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let (x1, _) = one.solve(&y, &cfg);
        t1 += start.elapsed().as_secs_f64();
        mem1 = mem1.max(one.memory_bytes());
        worst = worst.max(x1.iter().zip(ws.patch()).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max));
        if p == 0 {
            outln!("1D set-up (D, A, A^+ for one mask): {setup:.2} s")?;
        }
    }
    // 5D: the five matrices (as stored in a blob) and the workspace; 1D: D, A and A^+.
    let dict5 = blob::member_len(PaperShape::DIMS);
    let ws5 = std::mem::size_of::<PaperWorkspace>();
    outln!("{patches} patches, {family:?} mask, k = {k}, default SL0; 1D vs 5D max abs difference {worst:.2e}")?;
    outln!("| method | time per patch | memory |\n| --- | --- | --- |")?;
    outln!("| 5D (firmware, f32) | {:.2} ms | {dict5} B dictionary + {ws5} B workspace |", 1e3 * t5 / patches as f64)?;
    outln!("| 1D (dense f32, f64 sums) | {:.2} ms | {mem1} B (D, A, A^+) |", 1e3 * t1 / patches as f64)?;
    outln!("time ratio 1D/5D {:.1}x (paper: 106x)", t1 / t5)?;
    outln!(
        "memory ratio 1D/5D: dictionaries {:.0} (paper: 107,729), everything {:.0}",
        (5200.0f64 * 5200.0 * 4.0) / dict5 as f64,
        mem1 as f64 / (dict5 + ws5) as f64
    )?;
    Ok(())
}
