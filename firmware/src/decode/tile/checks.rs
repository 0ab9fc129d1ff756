//! The checks on a decoded patch (the shear check, plausibility, the held-out error
//! estimate) and the disparity a block is sheared to.

use super::*;
use crate::operators::shape::{PerBand, Shape};
use crate::sensor::extent::Array;

/// A block's held-out error estimates at a half-pixel disparity and at the whole ones beside
/// it (`None` where none), in that order.
pub(crate) type ShearEstimates = [(Disparity, Option<f32>); 3];

impl<'a, S: Shape> TileDecoder<'a, S> {
    /// [`Self::with_shear_check`]: `half`, or the whole disparity next to it whose first
    /// window's patch at block `(row, col)` estimates a held-out error below
    /// [`SHEAR_MARGIN`] times `half`'s (the smaller of the two).
    ///
    /// # Errors
    /// The source's error.
    #[inline(never)]
    pub(super) fn check_shear<M: PatchModel<S>, Src: TileSource>(
        &self,
        model: &M,
        row: u16,
        col: u16,
        half: Disparity,
        source: &mut Src,
        ws: &mut Workspace<S>,
    ) -> Result<Disparity, Src::Error> {
        let mut best = (f32::INFINITY, half);
        // The check's estimating solves are the block's: a patch's report counts its own.
        for (d, error) in self.shear_errors(model, (row, col), half, source, ws)?.0 {
            // A whole disparity must estimate clearly better than the half one.
            let error = if d == half { error } else { error.map(|e| e / SHEAR_MARGIN) };
            if let Some(e) = error.filter(|e| *e < best.0) {
                best = (e, d);
            }
        }
        Ok(best.1)
    }

    /// The held-out error estimates of the first window's patch of the block at lenslet
    /// `(row, col)` sheared to `half` and to the whole disparities beside it (`None` where
    /// no estimate: no window, too few measurements), and the solves they ran.
    ///
    /// # Errors
    /// The source's error.
    pub(crate) fn shear_errors<M: PatchModel<S>, Src: TileSource>(
        &self,
        model: &M,
        (row, col): (u16, u16),
        half: Disparity,
        source: &mut Src,
        ws: &mut Workspace<S>,
    ) -> Result<(ShearEstimates, u32), Src::Error> {
        let h = half.in_halves();
        let mut out =
            [half, Disparity::halves(h.saturating_sub(1)), Disparity::halves(h.saturating_add(1))].map(|d| (d, None));
        let mut solves = 0;
        let Some((view_row, view_col)) = self.windows().next() else { return Ok((out, solves)) };
        for (d, error) in &mut out {
            let origin = PatchOrigin { lenslet_row: row, lenslet_col: col, view_row, view_col, disparity: *d };
            self.read_patch(origin, source, ws)?;
            let (e, n) =
                self.estimate_error::<_, _, NoSeed>(model, &HoldOut::DEFAULT, (origin, None), source, ws, false)?;
            (*error, solves) = (e, solves + u32::from(n));
        }
        Ok((out, solves))
    }

    /// The held-out measurements the error estimate takes, if the decoder estimates.
    pub fn error_estimate(&self) -> Option<HoldOut> {
        self.holdout
    }

    /// The plausibility check on the solved patch in `ws` (the solve's units and frame):
    /// within the bounds it is left as it is; otherwise decoded again by the safe path, and
    /// clipped to the bounds if that breaks them too (or fails). `done` counts the solve.
    /// Out of line: the safe path's DCT (2 KB) stays off the decode's stack.
    #[inline(never)]
    pub(super) fn check_plausible(
        &self,
        cfg: &Sl0Config,
        flags: PatchFlags,
        ws: &mut Workspace<S>,
        done: &mut ModelOutcome,
    ) -> Checked {
        // A patch with saturated samples left out is brighter than it measured: no bound.
        if self.plausibility.is_off()
            || flags.contains(PatchFlags::OVER_RANGE)
            || matches!(done.outcome.ended, Ended::Interpolated | Ended::Flat)
        {
            return Checked::Plausible;
        }
        let bounds = self.plausibility.bounds::<S>(ws.measurements());
        if implausible::<S>(&bounds, ws.patch()) == 0 {
            return Checked::Plausible;
        }
        let safe = Sl0Config { cold_start: 1.0, ..*cfg };
        done.solves = done.solves.saturating_add(1);
        match solve(&crate::operators::dictionary::Dictionary::dct(), &safe, ws) {
            Ok(outcome) => {
                done.outcome = outcome;
                if implausible::<S>(&bounds, ws.patch()) == 0 {
                    return Checked::Redecoded;
                }
            }
            Err(_) => {
                // Nothing finite to keep: the band-gain fill holds the measurements.
                let Workspace { signal, measurements, .. } = ws;
                crate::solver::fill::fill_bands::<S>(measurements, signal);
            }
        }
        clip::<S>(&bounds, &mut ws.signal);
        Checked::Clipped
    }

    /// The disparity of `range` whose shear best aligns the views of the `PS x PT` block
    /// at lenslet `(row, col)`: every view of each of its lenslets (not only a window's),
    /// scored by [`Consistency`]. 0 when the range is off (nothing is read).
    ///
    /// # Errors
    /// The source's error.
    pub fn choose_disparity<Src: TileSource>(
        &self,
        row: usize,
        col: usize,
        source: &mut Src,
    ) -> Result<Disparity, Src::Error> {
        if self.disparities.is_off() {
            return Ok(Disparity::ZERO);
        }
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let k = c.mask.snapshots();
        let mut best = Best::default();
        let mut one = <PerBand<S, [f32; 1]>>::splat([0.0]);
        for d in self.disparities.candidates() {
            let mut score = Consistency::new();
            for s in 0..S::PS {
                for t in 0..S::PT {
                    for u in 0..lu {
                        let lr = (row + s) as isize + rounded_shift(d, u, lu);
                        for v in 0..lv {
                            let lc = (col + t) as isize + rounded_shift(d, v, lv);
                            let Some((r, cc)) = self.sensor_pixel((lr, lc), u, v) else { continue };
                            if c.defects.contains(r, cc) {
                                continue;
                            }
                            for (j, o) in one.iter_mut().enumerate().take(k) {
                                source.read(j, r, cc, o)?;
                            }
                            for (band, o) in c.mask.bands_at(r, cc).iter().zip(one.iter()) {
                                if let Ok(y) = self.balanced(*band, o[0], (r, cc)) {
                                    score.add(*band as usize, y);
                                }
                            }
                        }
                    }
                    score.end_point();
                }
            }
            best.offer(d, &score);
        }
        Ok(best.disparity())
    }

    /// Whether a block at lenslet `(row, col)` sheared to `d` reaches past the sensor's edge.
    pub(super) fn near_edge(&self, row: usize, col: usize, d: Disparity) -> bool {
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let (rows, cols) = (c.sensor.lenslets.0 as usize, c.sensor.lenslets.1 as usize);
        let (hr, hc) = (reach(d, lu), reach(d, lv));
        row < hr || col < hc || row + S::PS + hr > rows || col + S::PT + hc > cols
    }
}
