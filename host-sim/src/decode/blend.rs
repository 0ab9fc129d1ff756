//! The baseline blend: on a kronecker mask, each block's values mixed from the CS decode
//! and the PPID baseline ([`crate::decode::baselines::ppid`]) by how well each predicted the
//! samples it was not given.
//!
//! Why: a kronecker block measures `k` of the 13 bands in every pixel, so the CS decode
//! fills the others from the dictionary's prior and the patches that cross into the next
//! blocks, while PPID takes them from the neighbouring blocks that measured them, guided by
//! the pseudo-panchromatic image. Neither wins everywhere: at kronecker k = 3 on 21 scenes
//! (18 synthetic at 48 x 48 lenslets, 3 real crops), PPID decoded canopy 5.4 dB and
//! canopy-dim 7.1 dB above the CS default, the CS default the rest 0.1 to 17 dB above PPID,
//! and the better of the two per block (from the truth) stood 0.1 to 1.9 dB above the better
//! of them per frame.
//!
//! How: three held-out decodes of the frame by the same plan ([`HeldOutDecode`]), each
//! without one fold of [`Hiding::Rotated`] (a block's every pixel in one snapshot, so the
//! block keeps two of its three bands at k = 3; together the folds hide every sample once),
//! and PPID from the same samples; their squared errors at the hidden samples summed per
//! block and over the 3 x 3 blocks around it (one block's sum was too noisy: picking by it
//! lost up to 1.9 dB), and PPID's weight `c^2 / (c^2 + p^2)` for the decode's error `c` and
//! PPID's `p`: about one half where they tie, the better one's where they do not (the
//! aggregation of estimators by their errors; picking the better one lost up to 0.9 dB where
//! the weights lost 0.34, `docs/results-baseline-blend.md`). The rule was chosen on the 18
//! synthetic scenes at kronecker k = 3 (the real crops' figures printed beside them);
//! kronecker k = 1 was not looked at before.
//!
//! The held-out decodes give the error estimate of the blended output too, exactly (the
//! weight is one number per lenslet): [`HeldOutDecode::blended`].
//!
//! Cost: three decodes and four PPIDs of the frame more, and PPID's light field held whole
//! (13 values a pixel) while the decode writes: not the band of rows the decode alone holds.
//! Checked against the memory cap before it starts; the decode goes on without a blend that
//! cannot be made ([`crate::decode::report::DecodeReport::blend_skipped`]).

use crate::io::frames::SensorFrame;
use anyhow::{Result, ensure};
use slf_firmware::{MaskFamily, RowSink};

use crate::decode::baselines::{PpidConfig, ppid};
use crate::decode::held_out::{Held, HeldOutDecode, Hiding};
use crate::decode::plan::FramePlan;
use crate::io::capture::Capture;
use crate::io::lightfield::LightField;
use crate::io::patch::HostModel;
use crate::io::rows::{RowShape, Rows, whole_width};

/// Blocks either side of a block whose held-out errors its weight takes (3 x 3 blocks).
pub const REACH: usize = 1;

/// What the blend measured: PPID's light field, its weight per lenslet and the held-out
/// decodes' tallies of the blended output.
pub struct BaselineBlend {
    /// PPID's decode of the whole capture.
    pub baseline: LightField,
    /// PPID's weight per lenslet (row-major, in 0..=1; the decode's is one less).
    pub weights: Vec<f32>,
    /// The held-out decodes of the blended output, every sample held out once.
    pub held_out: HeldOutDecode,
}

/// Whether the blend applies to a decode by `plan`: a kronecker mask whose light field
/// holds each sample's own value ([`slf_firmware::TileDecoder::samples_are_values`]).
pub fn applies<const PU: usize, const PV: usize, const N: usize>(plan: &FramePlan<'_, PU, PV, N>) -> bool {
    plan.decoder.config().mask.family() == MaskFamily::Kronecker && plan.decoder.samples_are_values()
}

impl BaselineBlend {
    /// Measures the blend of the decode `plan` makes with `model` from `capture`'s `raw`
    /// frames and PPID's.
    ///
    /// # Errors
    /// A mask the blend does not apply to ([`applies`]), or what a held-out decode or PPID
    /// reports.
    pub fn measure<const PU: usize, const PV: usize, const N: usize, M>(
        plan: &FramePlan<'_, PU, PV, N>,
        model: &M,
        capture: &Capture,
        raw: &[SensorFrame<'_>],
        batch: usize,
    ) -> Result<Self>
    where
        M: HostModel<PU, PV, N>,
    {
        ensure!(applies(plan), "the baseline blend is for a kronecker mask without a lenslet grid or leaky filters");
        let Held::Group(group) = Held::of(&plan.decoder) else {
            anyhow::bail!("a kronecker mask holds out whole blocks");
        };
        // Two PPID light fields at once (the whole capture's, kept, and a fold's) and PPID's
        // own tables (about 150 bytes a sensor position): checked before any is made.
        let s = plan.shape;
        let positions = (s.views.0 * s.views.1 * s.rows * s.cols) as u64;
        crate::io::budget::check(
            positions * (2 * 4 * s.bands as u64 + 150),
            "the baseline blend (two PPID light fields held whole)",
            "--baseline-blend false, which decodes in a band of rows",
        )?;
        let cfg = PpidConfig::default();
        let mut total: Option<HeldOutDecode> = None;
        for fold in 0..Hiding::FOLDS {
            let hiding = Hiding::Rotated { group, fold };
            let (other, _) = ppid(&hidden(capture, hiding)?, &cfg)?;
            let fold = HeldOutDecode::run_hiding(plan, model, raw, hiding, Some(&other), batch)?;
            match total.as_mut() {
                Some(t) => t.add(&fold),
                None => total = Some(fold),
            }
        }
        let Some(total) = total else { anyhow::bail!("no held-out decode") };
        let (br, bc) = plan.decoder.config().mask.block();
        let weights = weights(&total.squared_per_lenslet(), plan.shape, (usize::from(br), usize::from(bc)));
        let held_out = total.blended(&weights);
        let (baseline, _) = ppid(capture, &cfg)?;
        Ok(Self { baseline, weights, held_out })
    }

    /// A sink that blends each row the decode puts with PPID's and passes it to `inner`.
    pub fn rows<'a>(&'a self, inner: &'a mut Rows<'a>, shape: RowShape) -> BlendRows<'a> {
        BlendRows { inner, blend: self, shape, row: Vec::new() }
    }
}

/// `capture` with the samples `hiding` names made saturated: not measurements to a
/// baseline, which reads its samples as the decoder does.
fn hidden(capture: &Capture, hiding: Hiding) -> Result<Capture> {
    let (rows, cols) = capture.frame_size();
    let mut frames = capture.frames.held((rows, cols))?.into_owned();
    for (snapshot, frame) in frames.iter_mut().enumerate() {
        for (i, x) in frame.iter_mut().enumerate() {
            if hiding.hides(snapshot, (i / cols.max(1), i % cols.max(1)), (rows, cols)) {
                *x = u16::MAX;
            }
        }
    }
    let mut d = capture.description.clone();
    // Saturated at the top code whatever the capture's level.
    d.saturation_level = d.saturation_level.min(f32::from(u16::MAX));
    Capture::new(d, frames)
}

/// PPID's weight per lenslet from the held-out squared errors per lenslet (the decode's,
/// PPID's): each `block` of lenslets summed, then over the blocks within [`REACH`], and
/// `c^2 / (c^2 + p^2)`; 0 (the decode) where neither erred.
pub fn weights(squared: &[(f64, f64)], shape: RowShape, (br, bc): (usize, usize)) -> Vec<f32> {
    let (br, bc) = (br.max(1), bc.max(1));
    let (nr, nc) = (shape.rows.div_ceil(br), shape.cols.div_ceil(bc));
    let mut blocks = vec![(0.0f64, 0.0f64); nr * nc];
    for y in 0..shape.rows {
        for x in 0..shape.cols {
            if let (Some(b), Some(&(c, p))) = (blocks.get_mut((y / br) * nc + x / bc), squared.get(y * shape.cols + x))
            {
                b.0 += c;
                b.1 += p;
            }
        }
    }
    let mut per_block = vec![0.0f32; nr * nc];
    for gy in 0..nr {
        for gx in 0..nc {
            let (mut c, mut p) = (0.0, 0.0);
            for yy in gy.saturating_sub(REACH)..(gy + REACH + 1).min(nr) {
                for xx in gx.saturating_sub(REACH)..(gx + REACH + 1).min(nc) {
                    if let Some(&(a, b)) = blocks.get(yy * nc + xx) {
                        c += a;
                        p += b;
                    }
                }
            }
            let w = if c * c + p * p > 0.0 { c * c / (c * c + p * p) } else { 0.0 };
            if let Some(o) = per_block.get_mut(gy * nc + gx) {
                *o = w as f32;
            }
        }
    }
    (0..shape.rows * shape.cols).map(|i| per_block[(i / shape.cols / br) * nc + (i % shape.cols) / bc]).collect()
}

/// The sink of [`BaselineBlend::rows`].
pub struct BlendRows<'a> {
    inner: &'a mut Rows<'a>,
    blend: &'a BaselineBlend,
    shape: RowShape,
    row: Vec<f32>,
}

impl RowSink for BlendRows<'_> {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, values: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let (s, yy) = (self.shape, usize::from(y));
        ensure!(yy < s.rows && values.len() == s.row_len(), "blended row {yy} of {} values does not fit", values.len());
        self.row.clear();
        self.row.extend_from_slice(values);
        let lf = &self.blend.baseline;
        for u in 0..s.views.0 {
            for v in 0..s.views.1 {
                for x in 0..s.cols {
                    let w = self.blend.weights.get(yy * s.cols + x).copied().unwrap_or(0.0);
                    if w == 0.0 {
                        continue;
                    }
                    for b in 0..s.bands {
                        let i = s.at(u, v, x, b);
                        if let Some(o) = self.row.get_mut(i) {
                            *o = (1.0 - w) * *o + w * lf.get(u, v, yy, x, b);
                        }
                    }
                }
            }
        }
        self.inner.row(y, first_col, &self.row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights against a slow reading of their rule: blocks of 2 x 2 lenslets, each
    /// block's weight from the 3 x 3 blocks around it, by brute force over lenslets.
    #[test]
    fn the_weights_are_the_squared_errors_of_the_blocks_around() {
        let shape = RowShape { views: (1, 1), rows: 7, cols: 5, bands: 1 };
        let squared: Vec<(f64, f64)> =
            (0..35).map(|i| (((i * 7) % 11) as f64 + 0.5, ((i * 5) % 13) as f64 * 0.7)).collect();
        let w = weights(&squared, shape, (2, 2));
        for y in 0..7 {
            for x in 0..5 {
                let (gy, gx) = ((y / 2) as isize, (x / 2) as isize);
                let (mut c, mut p) = (0.0, 0.0);
                for yy in 0..7 {
                    for xx in 0..5 {
                        let (hy, hx) = ((yy / 2) as isize, (xx / 2) as isize);
                        if (hy - gy).abs() <= 1 && (hx - gx).abs() <= 1 {
                            c += squared[yy * 5 + xx].0;
                            p += squared[yy * 5 + xx].1;
                        }
                    }
                }
                let want = c * c / (c * c + p * p);
                assert!((f64::from(w[y * 5 + x]) - want).abs() < 1e-6, "({y}, {x}): {} against {want}", w[y * 5 + x]);
            }
        }
        // Neither erred: the decode's own values.
        assert_eq!(weights(&[(0.0, 0.0); 4], RowShape { views: (1, 1), rows: 2, cols: 2, bands: 1 }, (5, 5)), [0.0; 4]);
    }

    /// The folds hide every sample of a block in exactly one snapshot each at k = 3, and
    /// every sample once over the folds.
    #[test]
    fn the_folds_hide_each_sample_once_and_a_block_keeps_two_snapshots() {
        let size = (50, 40);
        for snapshot in 0..3 {
            for r in 0..50 {
                for c in 0..40 {
                    let n = (0..Hiding::FOLDS)
                        .filter(|&fold| Hiding::Rotated { group: (10, 10), fold }.hides(snapshot, (r, c), size))
                        .count();
                    assert_eq!(n, 1);
                }
            }
        }
        for fold in 0..Hiding::FOLDS {
            let h = Hiding::Rotated { group: (10, 10), fold };
            for (gr, gc) in [(0, 0), (2, 3), (4, 1)] {
                let hidden: Vec<bool> = (0..3).map(|j| h.hides(j, (gr * 10 + 3, gc * 10 + 9), size)).collect();
                assert_eq!(hidden.iter().filter(|&&x| x).count(), 1, "block ({gr}, {gc}) fold {fold}");
                assert!((0..10).all(|d| h.hides(0, (gr * 10 + d, gc * 10 + 9 - d), size) == hidden[0]));
            }
        }
    }
}
