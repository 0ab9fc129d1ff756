//! The error estimate of the decode actually made: the frame decoded a second time by the
//! same plan (the trials' picks, the band gains, the disparity search, the seeds and the
//! overlap of every patch grid) from all but one sample in [`HoldOut::fold`], and that
//! decode's values at the samples it was not given, against them.
//!
//! Why not the patches' own estimates ([`slf_firmware::TileDecoder::with_error_estimate`]):
//! each is one cheap solve of one patch (the DCT's, without seeds or the overlapping
//! patches' average), not the decode the frame gets. Its PSNR read a median 2.5 to 3.5 dB
//! under the true one (`docs/results-error-map.md`), from -9.4 to +11.4 dB, and it gave a
//! DCT and an ensemble decode the same map. Cross-validation of the whole decode
//! (Boufounos, Duarte and Baraniuk 2007; Ward 2009) estimates the error of that decode from
//! seven eighths of the samples, whatever the model and the overlap do.
//!
//! What is held out must be like what nobody measured ([`slf_firmware::solver::holdout::Unit`]):
//! single samples on a pixel mask; on a lenslet mask, a lenslet's every view in a snapshot
//! (one (lenslet, band) group); on a kronecker mask, a block's every lenslet in a snapshot
//! (a band the block saw), by a hash of the snapshot and the group. Held out by lenslet, a
//! kronecker block's band was predicted by the block's other lenslets, which saw it too,
//! and the estimate read 6.5 dB over the true PSNR (median of 20 scenes at k = 3).
//! A held-out sample reads as not finite, so the decode leaves it out as it leaves out a
//! corrupt one.
//!
//! The estimate per lenslet is over the held-out samples of the lenslets around it (5 x 5,
//! a patch's reach; 21 x 21 on a kronecker mask, whose held-out groups are blocks of 5 x 5):
//! the unmeasured values at their prediction error, the noise's variance (the capture's
//! noise model) taken off; the measured ones at that or the noise's level, whichever is
//! lower. A held-out sample that saturated counts at the gap between the decode's value
//! and the top of the range (its value is at least the top): a lower bound, where the
//! speculars' estimate read 2.4 to 10.4 dB over the true PSNR without it. The decode does
//! not keep a measured value's noise: at the noise's level, the
//! estimate read 2.7 to 3.8 dB under the true PSNR on the dark and dim scenes at k = 3
//! (where 3 values in 13 are measured), within 0.4 dB at the lower one.
//! It is taken where the light field holds each sample's own value
//! ([`slf_firmware::TileDecoder::samples_are_values`]); elsewhere the patches' estimates
//! stand in. It costs a second decode of the frame.
//!
//! A held-out decode can hide folds that together cover the frame instead
//! ([`Hiding::Rotated`]), and tally a second prediction of the same samples beside its own
//! (a baseline's from the same samples, with the two errors' products): the baseline
//! blend's ([`crate::decode::blend`]), whose tallies then estimate the blended output.

use crate::io::frames::SensorFrame;
use crate::io::map::Map;
use anyhow::{Result, ensure};
use slf_firmware::holdout::noise_variance;
use slf_firmware::raw::Invalid;
use slf_firmware::{Frame, HoldOut, MaskFamily, RowSink};

use crate::decode::calibrate::DEAD_FLAT;
use crate::decode::plan::FramePlan;
use crate::decode::strip::{Pass, decode_rows};
use crate::io::lightfield::LightField;
use crate::io::patch::{HostDecoder, HostModel};
use crate::io::rows::{RowShape, whole_width};

/// The factor the held-out decode's error estimate is scaled by to be the full decode's
/// (RMS): measured, not derived. On the test scenes (smooth, texture, depth, saturated,
/// dark; 48 x 48 lenslets, `--seed 1`) at pixel k = 1 and 3 and lenslet k = 3, the
/// unscaled estimate read a median 1.63 dB under the true PSNR (-2.58 to -0.33 over the 15
/// decodes; 1.70 at kronecker k = 3): this factor is that median, 10^(-1.63 / 20). It is
/// not the eighth of the samples the held-out decode lost: holding out one in 16 or one in
/// 32 read as low (smooth at pixel k = 1: -2.06, -1.85, -2.71 dB at 8, 16, 32). The other
/// scenes and the real crops, not fitted on, are in `docs/results-error-map.md`.
pub const LEVEL: f64 = 0.829;

/// What is held out together: a sensor sample, or a group of pixels in a snapshot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Held {
    /// One sample (a pixel in a snapshot): the pixel mask.
    Sample,
    /// Every pixel of a `(rows, cols)` group in a snapshot: a lenslet's views on a lenslet
    /// mask, a block's lenslets on a kronecker mask, whose unmeasured values are bands no
    /// pixel of the group saw.
    Group((usize, usize)),
}

impl Held {
    /// What a decoder's mask holds out.
    pub fn of<const PU: usize, const PV: usize, const N: usize>(decoder: &HostDecoder<'_, PU, PV, N>) -> Self {
        let c = decoder.config();
        let (lu, lv) = (usize::from(c.sensor.lenslet.rows), usize::from(c.sensor.lenslet.cols));
        let (br, bc) = c.mask.block();
        match c.mask.family() {
            MaskFamily::Pixel => Self::Sample,
            MaskFamily::Lenslet => Self::Group((lu, lv)),
            MaskFamily::Kronecker => Self::Group((lu * usize::from(br), lv * usize::from(bc))),
        }
    }

    /// How many lenslets either side of a lenslet its estimate takes held-out samples
    /// from: a patch's 5 x 5, or two blocks either side of a kronecker block, where only
    /// one group in eight of those is held out.
    pub fn reach(self, views: (usize, usize)) -> usize {
        match self {
            Self::Sample => 2,
            Self::Group((r, c)) => 2.max(2 * (r / views.0.max(1)).max(c / views.1.max(1))),
        }
    }

    /// Whether sample `(row, col)` of `snapshot` (of a `rows x cols` frame) is held out.
    #[inline]
    pub fn holds(
        self,
        hold: &HoldOut,
        snapshot: usize,
        (row, col): (usize, usize),
        (rows, cols): (usize, usize),
    ) -> bool {
        let key = match self {
            Self::Sample => (snapshot * rows + row) * cols + col,
            Self::Group((gr, gc)) => {
                let (lr, lc) = (row / gr.max(1), col / gc.max(1));
                (snapshot * rows.div_ceil(gr.max(1)) + lr) * cols.div_ceil(gc.max(1)) + lc
            }
        };
        hold.holds(key)
    }
}

/// Which samples a held-out decode is not given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hiding {
    /// One sample (or group, [`Held`]) in [`HoldOut::fold`], by a hash: the error estimate's.
    Hashed(HoldOut, Held),
    /// Fold `fold` of [`Hiding::FOLDS`]: the group `(rows, cols)` of pixels at group
    /// `(gr, gc)` in `snapshot` when `(snapshot + gr + 2 gc) % FOLDS == fold`. The folds
    /// together hide every sample once; at three snapshots each fold hides one of every
    /// group's snapshots (the baseline blend's, [`crate::decode::blend`]).
    Rotated { group: (usize, usize), fold: usize },
}

impl Hiding {
    /// How many [`Hiding::Rotated`] folds cover the frame.
    pub const FOLDS: usize = 3;

    /// Whether sample `(row, col)` of `snapshot` (of a `rows x cols` frame) is hidden.
    #[inline]
    pub fn hides(self, snapshot: usize, at: (usize, usize), size: (usize, usize)) -> bool {
        match self {
            Self::Hashed(hold, held) => held.holds(&hold, snapshot, at, size),
            Self::Rotated { group: (gr, gc), fold } => {
                (snapshot + at.0 / gr.max(1) + 2 * (at.1 / gc.max(1))) % Self::FOLDS == fold
            }
        }
    }

    /// The lenslets either side of a lenslet whose held-out samples its map takes: as
    /// [`Held::reach`], or a patch's reach where the folds hide every sample.
    fn reach(self, views: (usize, usize)) -> usize {
        match self {
            Self::Hashed(_, held) => held.reach(views),
            Self::Rotated { .. } => 2,
        }
    }
}

/// A snapshot's raw frame with its held-out samples hidden (not finite: the decode leaves
/// them out).
pub struct HeldOutFrame<'a> {
    frame: &'a SensorFrame<'a>,
    snapshot: usize,
    hiding: Hiding,
}

impl<'a> HeldOutFrame<'a> {
    /// `frames` (one per snapshot) with the samples `hiding` names hidden.
    pub fn of(frames: &'a [SensorFrame<'a>], hiding: Hiding) -> Vec<Self> {
        frames.iter().enumerate().map(|(snapshot, frame)| Self { frame, snapshot, hiding }).collect()
    }
}

impl Frame for HeldOutFrame<'_> {
    fn size(&self) -> (usize, usize) {
        self.frame.size()
    }

    #[inline]
    fn sample(&self, i: usize) -> Option<f32> {
        let (rows, cols) = self.frame.size();
        let at = (i.checked_div(cols)?, i.checked_rem(cols)?);
        if self.hiding.hides(self.snapshot, at, (rows, cols)) {
            return Some(f32::NAN);
        }
        self.frame.sample(i)
    }

    /// The run as read, then its hidden samples hidden: a paged frame's band is found once
    /// a run.
    #[inline]
    fn read_run(&self, start: usize, out: &mut [f32]) -> Option<()> {
        self.frame.read_run(start, out)?;
        let (rows, cols) = self.frame.size();
        for (i, o) in out.iter_mut().enumerate() {
            let at = start + i;
            if self.hiding.hides(self.snapshot, (at.checked_div(cols)?, at.checked_rem(cols)?), (rows, cols)) {
                *o = f32::NAN;
            }
        }
        Some(())
    }
}

/// Per lenslet: the held-out samples' squared prediction errors and noise variances
/// summed, how many, and the valid samples in all (the light field's units); with a second
/// prediction (a baseline's), its squared errors and the two errors' products.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Tally {
    squared: f64,
    variance: f64,
    held: u32,
    measured: f64,
    other: f64,
    cross: f64,
}

impl Tally {
    fn add(&mut self, o: &Self) {
        self.squared += o.squared;
        self.variance += o.variance;
        self.held += o.held;
        self.measured += o.measured;
        self.other += o.other;
        self.cross += o.cross;
    }

    /// The tally of `(1 - w) x decode + w x other`: its squared errors from the two
    /// predictions' (exact, as `w` is one number for the lenslet).
    fn blended(&self, w: f64) -> Self {
        let squared = (1.0 - w) * (1.0 - w) * self.squared + w * w * self.other + 2.0 * w * (1.0 - w) * self.cross;
        Self { squared, other: 0.0, cross: 0.0, ..*self }
    }
}

/// The row sink of the held-out decode: each finished lenslet row's values at the held-out
/// samples under it, against the samples, tallied per lenslet.
struct Tallies<'a, const PU: usize, const PV: usize, const N: usize> {
    decoder: &'a HostDecoder<'a, PU, PV, N>,
    raw: &'a [SensorFrame<'a>],
    hiding: Hiding,
    shape: RowShape,
    tallies: Vec<Tally>,
    /// A second prediction of the held-out samples, from the same samples (a baseline's).
    other: Option<&'a LightField>,
    /// The per-pixel flat the frames were divided by ([`FramePlan::flat`]).
    flat: Option<&'a Map>,
}

impl<const PU: usize, const PV: usize, const N: usize> RowSink for Tallies<'_, PU, PV, N> {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, values: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let (s, y) = (self.shape, usize::from(y));
        ensure!(y < s.rows && values.len() == s.row_len(), "held-out row {y} of {} values does not fit", values.len());
        let c = self.decoder.config();
        let (noise, shot) = (c.sl0.noise, c.sl0.shot);
        let top = f64::from(c.raw.range().1);
        let frame = self.decoder.frame_size();
        let (lu, lv) = s.views;
        // The lenslet row's rows of the flat: a corrected value's noise is the raw value's
        // over its pixel's flat.
        let mut flats = Vec::new();
        if let Some(map) = self.flat {
            flats = vec![1.0f32; lu * map.cols()];
            map.read_rows(y * lu, &mut flats)?;
        }
        let pixel_flat = |u: usize, cc: usize| match self.flat {
            Some(map) => flats.get(u * map.cols() + cc).map_or(1.0, |&f| f.max(DEAD_FLAT)),
            None => 1.0,
        };
        for x in 0..s.cols {
            let mut t = Tally::default();
            for u in 0..lu {
                for v in 0..lv {
                    let (r, cc) = (y * lu + u, x * lv + v);
                    if c.defects.contains(r, cc) {
                        continue;
                    }
                    for (j, &band) in c.mask.bands_at(r, cc).iter().enumerate() {
                        let Some(sample) = self.raw.get(j).and_then(|f| f.sample(r * frame.1 + cc)) else { continue };
                        let seen = self.decoder.light_field_value(sample, (r, cc));
                        t.measured += f64::from(u8::from(seen.is_ok()));
                        if !self.hiding.hides(j, (r, cc), frame) {
                            continue;
                        }
                        let Some(&predicted) = values.get(s.at(u, v, x, usize::from(band))) else { continue };
                        let (predicted, band) = (f64::from(predicted), usize::from(band));
                        let other = self.other.map_or(predicted, |lf| f64::from(lf.get(u, v, y, x, band)));
                        // A saturated sample's value is at least the top of the range: a
                        // value under it errs by the gap at least.
                        let (d, e) = match seen {
                            Ok(seen) => {
                                let flat = self.decoder.view_gain(r, cc) * pixel_flat(u, cc);
                                t.variance += f64::from(noise_variance(noise, shot, seen, flat));
                                (predicted - f64::from(seen), other - f64::from(seen))
                            }
                            Err(Invalid::OverRange) => ((top - predicted).max(0.0), (top - other).max(0.0)),
                            Err(_) => continue,
                        };
                        t.squared += d * d;
                        t.other += e * e;
                        t.cross += d * e;
                        t.held += 1;
                    }
                }
            }
            if let Some(slot) = self.tallies.get_mut(y * s.cols + x) {
                *slot = t;
            }
        }
        Ok(())
    }
}

/// What a held-out decode found: its tallies per lenslet.
pub struct HeldOutDecode {
    tallies: Vec<Tally>,
    shape: RowShape,
    hiding: Hiding,
}

impl HeldOutDecode {
    /// The decode `plan` makes with `model` from `raw`, made again from all but the samples
    /// `hold` names, and its values at those against them.
    ///
    /// # Errors
    /// What the held-out decode reports.
    pub fn run<const PU: usize, const PV: usize, const N: usize, M>(
        plan: &FramePlan<'_, PU, PV, N>,
        model: &M,
        raw: &[SensorFrame<'_>],
        hold: HoldOut,
        batch: usize,
    ) -> Result<Self>
    where
        M: HostModel<PU, PV, N>,
    {
        Self::run_hiding(plan, model, raw, Hiding::Hashed(hold, Held::of(&plan.decoder)), None, batch)
    }

    /// [`Self::run`] without the samples `hiding` names, and `other` (a light field made
    /// from the same samples, a baseline's) tallied at them too, for [`Self::blended`].
    ///
    /// # Errors
    /// What the held-out decode reports, or `other` of another shape.
    pub fn run_hiding<const PU: usize, const PV: usize, const N: usize, M>(
        plan: &FramePlan<'_, PU, PV, N>,
        model: &M,
        raw: &[SensorFrame<'_>],
        hiding: Hiding,
        other: Option<&LightField>,
        batch: usize,
    ) -> Result<Self>
    where
        M: HostModel<PU, PV, N>,
    {
        let hidden = HeldOutFrame::of(raw, hiding);
        let shape = plan.shape;
        if let Some(lf) = other {
            ensure!(
                [lf.views.0, lf.views.1, lf.rows, lf.cols, lf.bands] == shape.shape(),
                "the second prediction's shape differs from the decode's"
            );
        }
        let mut sink = Tallies {
            decoder: &plan.decoder,
            flat: plan.flat.as_ref(),
            raw,
            hiding,
            shape,
            tallies: vec![Tally::default(); shape.rows * shape.cols],
            other,
        };
        decode_rows(plan, model, &hidden, Pass { batch, ..Pass::default() }, &|_, _| {}, &mut sink)?;
        Ok(Self { tallies: sink.tallies, shape, hiding })
    }

    /// Held-out decodes of the same plan added up: the folds of [`Hiding::Rotated`] into
    /// one that held out every sample once.
    pub fn add(&mut self, o: &Self) {
        for (t, x) in self.tallies.iter_mut().zip(&o.tallies) {
            // The valid samples are the frame's, the same in every fold: counted once.
            let measured = t.measured;
            t.add(x);
            t.measured = measured;
        }
    }

    /// Per lenslet, the held-out samples' summed squared errors of the decode and of the
    /// second prediction (zero without one).
    pub fn squared_per_lenslet(&self) -> Vec<(f64, f64)> {
        self.tallies.iter().map(|t| (t.squared, t.other)).collect()
    }

    /// This held-out decode as the tallies of the blend `(1 - w) x decode + w x other`, `w`
    /// per lenslet (row-major): the estimate of the blended output.
    pub fn blended(&self, weights: &[f32]) -> Self {
        let tallies = self.tallies.iter().zip(weights).map(|(t, &w)| t.blended(f64::from(w))).collect();
        Self { tallies, shape: self.shape, hiding: self.hiding }
    }

    /// The error estimate of the frame's values nobody measured (RMS, the output's units,
    /// scaled by [`LEVEL`]): every held-out sample's squared error, less the noise's
    /// variance; `None` without a held-out sample.
    pub fn frame_error(&self) -> Option<f64> {
        let mut all = Tally::default();
        for t in &self.tallies {
            all.add(t);
        }
        (all.held > 0).then(|| LEVEL * ((all.squared - all.variance) / f64::from(all.held)).max(0.0).sqrt())
    }

    /// The error estimate per lenslet (row-major, RMS per value in the output's units, NaN
    /// where no held-out sample is within reach), over the lenslets around each
    /// ([`Held::reach`]).
    pub fn map(&self) -> Vec<f32> {
        let shape = self.shape;
        let values = (shape.views.0 * shape.views.1 * shape.bands) as f64;
        boxed(&self.tallies, (shape.rows, shape.cols), self.hiding.reach(shape.views))
            .iter()
            .map(|t| {
                if t.held == 0 {
                    return f32::NAN;
                }
                let (r2, var) = (t.squared / f64::from(t.held), t.variance / f64::from(t.held));
                let measured = (t.measured / values).min(1.0);
                let unmeasured = (r2 - var).max(0.0);
                (LEVEL * (unmeasured * (1.0 - measured) + unmeasured.min(var) * measured).sqrt()) as f32
            })
            .collect()
    }
}

/// Each lenslet's tally summed with its neighbours' within `reach` lenslets (a box clipped
/// at the frame's edges; the lenslets a 5 x 5 patch around it holds for `reach` 2), with
/// `measured` per lenslet of the box.
fn boxed(t: &[Tally], (rows, cols): (usize, usize), reach: usize) -> Vec<Tally> {
    let mut out = vec![Tally::default(); t.len()];
    for y in 0..rows {
        for x in 0..cols {
            let (mut sum, mut lenslets) = (Tally::default(), 0u32);
            for yy in y.saturating_sub(reach)..(y + reach + 1).min(rows) {
                for xx in x.saturating_sub(reach)..(x + reach + 1).min(cols) {
                    if let Some(o) = t.get(yy * cols + xx) {
                        sum.add(o);
                        lenslets += 1;
                    }
                }
            }
            // The measured fraction is per lenslet: the box's count over its lenslets.
            sum.measured /= f64::from(lenslets.max(1));
            if let Some(o) = out.get_mut(y * cols + x) {
                *o = sum;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn about_one_sample_in_the_fold_is_held_and_a_lenslet_is_held_whole() {
        let hold = HoldOut::DEFAULT;
        let size = (60, 60);
        let mut n = 0;
        for r in 0..60 {
            for c in 0..60 {
                n += usize::from(Held::Sample.holds(&hold, 0, (r, c), size));
            }
        }
        // 3600 samples, one in 8 expected (450); a hash within 20 % of it.
        assert!((360..=540).contains(&n), "{n} of 3600 held");
        let lenslet = Held::Group((5, 5));
        for lr in 0..12 {
            for lc in 0..12 {
                let first = lenslet.holds(&hold, 1, (lr * 5, lc * 5), size);
                for (u, v) in [(0, 4), (4, 0), (2, 3), (4, 4)] {
                    assert_eq!(lenslet.holds(&hold, 1, (lr * 5 + u, lc * 5 + v), size), first);
                }
            }
        }
    }

    #[test]
    fn a_box_sums_its_neighbours_and_clips_at_the_edges() {
        let one = Tally { squared: 1.0, variance: 0.5, held: 1, measured: 2.0, ..Tally::default() };
        let b = boxed(&vec![one; 36], (6, 6), 2);
        // A corner's box holds 3 x 3 lenslets, the middle's 5 x 5.
        assert_eq!(b[0].held, 9);
        assert_eq!(b[2 * 6 + 2].held, 25);
        assert!((b[0].squared - 9.0).abs() < 1e-12 && (b[0].variance - 4.5).abs() < 1e-12);
        // The measured count per lenslet of the box: 2.
        assert!((b[0].measured - 2.0).abs() < 1e-12);
    }
}
