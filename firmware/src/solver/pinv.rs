//! The paper's general projection path: per-mode pseudo-inverses, for kronecker masks.
//!
//! Algorithm 1 as the paper writes it, with `A_i = Phi_i D_i`:
//! `S0 = I x_i A_i^+`, and each step `S <- S - (S x_i A_i - I) x_i A_i^+`. It does not need
//! orthonormal matrices, which is why it is kept; with orthonormal ones it equals the fast
//! path of [`crate::solver::sl0`] (a test shows it). The pseudo-inverses are computed once, in
//! [`PinvOperator::new`] (an SVD each, in f64, via nalgebra), never per patch.
//!
//! `Phi5` is `k x B`; here it is padded to `B x B` with zero rows (and `I` with zero
//! slices), which keeps every mode square and leaves the algebra unchanged: the
//! pseudo-inverse of `[A; 0]` is `[A^+, 0]`. The mode products run in place one fibre at a
//! time, so this path needs the same [`Workspace`] as the fast path; it is slower, being
//! the reference and not the product.

use nalgebra::{SMatrix, SVD};

use crate::operators::dictionary::{Dictionary, Factors};
use crate::operators::mode::{Mode, ModeMatrix};
use crate::operators::shape::{PerValue, Shape};
use crate::operators::transform::{apply_in_place, synthesize};
use crate::sensor::extent::{Array, Bands};
use crate::sensor::mask::KroneckerPhi;
use crate::solver::ascent::ascend;
use crate::solver::ball::Move;
use crate::solver::sl0::{Outcome, Sl0Config, SolveError, Step, max_abs, run_schedule, start};
use crate::solver::workspace::{Measurements, Workspace};

/// Largest mode size the general path handles (its SVDs run at this fixed size).
pub const PINV_MAX_DIM: usize = 16;

type Padded = SMatrix<f64, PINV_MAX_DIM, PINV_MAX_DIM>;

/// The Moore-Penrose pseudo-inverse of a `D x D` matrix, via an f64 SVD.
fn pseudo_inverse<E: Mode>(a: &ModeMatrix<E>, mode: u8) -> Result<ModeMatrix<E>, SolveError> {
    const { assert!(E::D <= PINV_MAX_DIM, "mode larger than PINV_MAX_DIM") };
    let fail = SolveError::PseudoInverse { mode };
    // Zero padding: pinv(diag(A, 0)) = diag(pinv(A), 0).
    let mut m = Padded::zeros();
    for (i, row) in a.iter().enumerate() {
        for (j, &x) in row.iter().enumerate() {
            m[(i, j)] = f64::from(x);
        }
    }
    // Set-up only, once per kronecker block. nalgebra's SVD has panic paths of its own
    // (bounds and shape checks, and `try_new`'s `expect` on a NaN singular value): a finite
    // input of bounded size reaches none of them, so non-finite input is refused first, and
    // the unordered SVD is used (the pseudo-inverse needs no ordering, and it skips the sort
    // whose `expect` a NaN would reach).
    if m.iter().any(|x| !x.is_finite()) {
        return Err(fail);
    }
    let svd = SVD::try_new_unordered(m, true, true, f64::EPSILON, 10_000).ok_or(fail)?;
    let tol = svd.singular_values.max() * 1e-9;
    let p = svd.pseudo_inverse(tol).map_err(|_| fail)?;
    let mut out = E::ZERO_MATRIX;
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = p[(i, j)] as f32;
        }
    }
    Ok(out)
}

/// `Phi D` for a row-shuffled identity `Phi`: row `r` is row `shuffle[r]` of `D`.
fn shuffled_rows<E: Mode>(d: &ModeMatrix<E>, shuffle: &E::Per<u8>) -> ModeMatrix<E> {
    let mut a = E::ZERO_MATRIX;
    for (row, &p) in a.iter_mut().zip(shuffle.iter()) {
        *row = d[p as usize % E::D];
    }
    a
}

/// The operators `A_i = Phi_i D_i` and their pseudo-inverses for one kronecker block.
/// Config: built once, used for every patch the block's `Phi` describes.
#[derive(Clone, Debug)]
pub struct PinvOperator<S: Shape> {
    a: Factors<S>,
    a_pinv: Factors<S>,
    phi: KroneckerPhi<S::S, S::T, S::U, S::V>,
    dict: Dictionary<S>,
}

impl<S: Shape> PinvOperator<S> {
    /// Forms `A_i = Phi_i D_i` and computes each `A_i^+` once.
    ///
    /// Set-up only: call it once per kronecker block, before decoding, never per patch. It
    /// is the one place the decoder runs code with panic paths of its own (nalgebra's SVD:
    /// its matrix index and shape checks, 17 call sites in a release device image, counted
    /// by `scripts/panic-sites.py` on `slf-surface`). Their inputs here are fixed-size
    /// (`PINV_MAX_DIM` square) and checked finite first, which none of those paths can fail
    /// on; the decode path itself ([`solve_pinv`] and everything in the tile decoder) has
    /// no panic call at all.
    ///
    /// # Errors
    /// [`SolveError::PseudoInverse`] if an SVD does not converge or an input is not finite.
    pub fn new(dict: &Dictionary<S>, phi: &KroneckerPhi<S::S, S::T, S::U, S::V>) -> Result<Self, SolveError> {
        let d = &dict.d;
        let mut a5 = S::Bands::ZERO_MATRIX;
        for (row, &band) in a5.iter_mut().zip(phi.bands.iter()) {
            *row = d.m5[band as usize % S::B];
        }
        let a = Factors {
            m1: shuffled_rows::<S::S>(&d.m1, &phi.shuffle1),
            m2: shuffled_rows::<S::T>(&d.m2, &phi.shuffle2),
            m3: shuffled_rows::<S::U>(&d.m3, &phi.shuffle3),
            m4: shuffled_rows::<S::V>(&d.m4, &phi.shuffle4),
            m5: a5,
        };
        let a_pinv = Factors {
            m1: pseudo_inverse::<S::S>(&a.m1, 1)?,
            m2: pseudo_inverse::<S::T>(&a.m2, 2)?,
            m3: pseudo_inverse::<S::U>(&a.m3, 3)?,
            m4: pseudo_inverse::<S::V>(&a.m4, 4)?,
            m5: pseudo_inverse::<S::Bands>(&a.m5, 5)?,
        };
        Ok(Self { a, a_pinv, phi: phi.clone(), dict: dict.clone() })
    }

    /// [`PatchShape::index`] (which does not depend on `N`).
    fn index(s: usize, t: usize, u: usize, v: usize, b: usize) -> usize {
        S::index(s, t, u, v, b)
    }

    /// For every entry of the padded measurement tensor `I` (in the patch layout, with the
    /// snapshot `j` in place of the band), the patch entry it measures: `f(i_index, entry)`.
    fn for_each_selected(&self, mut f: impl FnMut(usize, usize)) {
        let p = &self.phi;
        for (s, &ps) in p.shuffle1.iter().enumerate() {
            for (t, &pt) in p.shuffle2.iter().enumerate() {
                for (u, &pu) in p.shuffle3.iter().enumerate() {
                    for (v, &pv) in p.shuffle4.iter().enumerate() {
                        for (j, &band) in p.bands.iter().enumerate() {
                            let (ps, pt, pu, pv) = (ps as usize, pt as usize, pu as usize, pv as usize);
                            f(Self::index(s, t, u, v, j), Self::index(ps, pt, pu, pv, band as usize));
                        }
                    }
                }
            }
        }
    }

    /// `t -= I` (or `t = I` with `assign`); `I` read from the measurements.
    fn subtract_measurements(&self, m: &Measurements<S::Values>, t: &mut PerValue<S, f32>, assign: bool) {
        self.for_each_selected(|i, e| {
            let y = m.values.get(e).copied().unwrap_or(0.0);
            if let Some(x) = t.get_mut(i) {
                *x = if assign { y } else { *x - y };
            }
        });
    }
}

/// Decodes the patch whose measurements are in `ws` by the paper's general path. The
/// measurements must be exactly the entries `op`'s `Phi` selects (no defects).
///
/// This is the paper's method as a reference: of [`Sl0Config`]'s additions it honours the
/// early stop (`tolerance`, with the ascent step's length as the movement, an upper bound)
/// but not the flat short path (`flat`) or the warm solve (`warm_start`, `warm_sigma_f`,
/// `warm_steps`), which belong to the fast path ([`crate::solve`], [`crate::solver::sl0::solve_warm`]).
///
/// # Errors
/// [`SolveError::InvalidConfig`], [`SolveError::NoMeasurements`],
/// [`SolveError::IncompleteKronecker`], [`SolveError::NonFiniteResult`].
pub fn solve_pinv<S: Shape>(
    op: &PinvOperator<S>,
    cfg: &Sl0Config,
    ws: &mut Workspace<S>,
) -> Result<Outcome, SolveError> {
    let Workspace { coeffs, signal, measurements: m, response, .. } = ws;
    if !response.is_identity() {
        // The paper's operator is a selection of the patch's entries: no mixed filters.
        return Err(SolveError::InvalidConfig { field: "response" });
    }
    let ball = start::<S>(cfg, m)?;
    let mut complete = true;
    op.for_each_selected(|_, e| complete &= m.measured.get(e).copied().unwrap_or(false));
    if !complete || m.count() != S::PIXELS * op.phi.bands.len() {
        return Err(SolveError::IncompleteKronecker);
    }

    // S0 = I x_i A_i^+ (zero-padded I).
    coeffs.fill(0.0);
    op.subtract_measurements(m, coeffs, true);
    apply_in_place(&op.a_pinv, coeffs);
    let sigma0 = max_abs(coeffs.as_ref());

    let outcome = run_schedule(cfg, sigma0, S::N, |inv| {
        // The step's own length bounds how far the projected step moves the patch.
        let moved = libm::sqrtf(ascend(coeffs.as_mut(), cfg.mu, inv));
        // R = S x_i A_i - I
        signal.copy_from_slice(coeffs.as_ref());
        apply_in_place(&op.a, signal);
        op.subtract_measurements(m, signal, false);
        let r2: f32 = signal.iter().map(|r| r * r).sum();
        // Each residual over its measurement's variance.
        let mut w2 = 0.0f32;
        if ball.is_weighted() {
            op.for_each_selected(|i, e| {
                let (r, y) = (signal.get(i).copied().unwrap_or(0.0), m.values.get(e).copied().unwrap_or(0.0));
                w2 += r * r * ball.weight(y, m.gains.get(e % S::B).copied().unwrap_or(1.0));
            });
        }
        let norm = libm::sqrtf(r2);
        if let Move::Scale(scale) = ball.move_for(r2, w2) {
            // S <- S - R' x_i A_i^+, R' = R, or R shrunk to the noise ball's surface.
            apply_in_place(&op.a_pinv, signal);
            for (s, r) in coeffs.iter_mut().zip(signal.iter()) {
                *s -= scale * r;
            }
        }
        Step { residual: norm, moved }
    });

    synthesize(&op.dict, coeffs, signal);
    if signal.iter().any(|x| !x.is_finite()) {
        return Err(SolveError::NonFiniteResult);
    }
    Ok(outcome)
}
