//! Where the disjoint grid's borders show in its decode ([`seam_score`]): the adaptive
//! rule's test of whether a shifted patch is worth decoding ([`DecodeOptions::adaptive`]).
//!
//! [`DecodeOptions::adaptive`]: crate::decode::cs::DecodeOptions::adaptive

use crate::io::lightfield::LightField;

/// Spectra of a decoded light field by `(u, v, y, x)`: a whole one, or the rows of one a
/// streamed decode holds.
pub trait Spectra {
    /// Views per axis.
    fn views(&self) -> (usize, usize);
    /// Spatial rows and columns.
    fn size(&self) -> (usize, usize);
    /// The bands at `(u, v, y, x)` (`y` a row the holder has).
    fn spectrum(&self, u: usize, v: usize, y: usize, x: usize) -> &[f32];
}

impl Spectra for LightField {
    fn views(&self) -> (usize, usize) {
        self.views
    }

    fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    fn spectrum(&self, u: usize, v: usize, y: usize, x: usize) -> &[f32] {
        LightField::spectrum(self, u, v, y, x)
    }
}

/// The step between lenslets `a` and `b` of `lf`: the mean absolute difference over views
/// and bands.
fn step(lf: &impl Spectra, (y0, x0): (usize, usize), (y1, x1): (usize, usize)) -> f32 {
    let views = lf.views();
    let mut total = 0.0f32;
    let mut bands = 0;
    for u in 0..views.0 {
        for v in 0..views.1 {
            let (a, b) = (lf.spectrum(u, v, y0, x0), lf.spectrum(u, v, y1, x1));
            bands = a.len();
            total += a.iter().zip(b).map(|(p, q)| (p - q).abs()).sum::<f32>();
        }
    }
    total / (views.0 * views.1 * bands) as f32
}

/// How much the disjoint grid's borders inside the patch at `(row, col)` stand out in `lf`:
/// the mean step across them over the mean step between the patch's other lenslets (0 for
/// a patch that crosses no border). Reads the rows `row..row + 5` of `lf`.
pub fn seam_score(lf: &impl Spectra, row: usize, col: usize) -> f32 {
    let (rows, cols) = lf.size();
    let (mut seam, mut seams, mut inner, mut inners) = (0.0f32, 0u32, 0.0f32, 0u32);
    for y in row..(row + 5).min(rows) {
        for x in col..(col + 5).min(cols) {
            // Steps into (y, x) from above and from the left, inside the patch.
            for (inside, at_border, from) in
                [(y > row, y % 5 == 0, (y.wrapping_sub(1), x)), (x > col, x % 5 == 0, (y, x.wrapping_sub(1)))]
            {
                if !inside {
                    continue;
                }
                let s = step(lf, from, (y, x));
                if at_border {
                    (seam, seams) = (seam + s, seams + 1);
                } else {
                    (inner, inners) = (inner + s, inners + 1);
                }
            }
        }
    }
    if seams == 0 {
        return 0.0;
    }
    let inner = if inners > 0 { inner / inners as f32 } else { 0.0 };
    (seam / seams as f32) / inner.max(1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of 0.01 between lenslet columns, 0.05 across column 4|5, none between rows. A
    /// patch from column 3 crosses that seam once per row (steps into columns 4..7: 0.01,
    /// 0.05, 0.01, 0.01); its other steps are 3 of 0.01 per row and 4 of 0 per column, so
    /// 15 of 0.01 and 20 of 0 over its 5 rows and columns: mean 0.03 / 7. A patch from
    /// column 0 crosses no border.
    #[test]
    fn a_seam_scores_its_step_over_the_steps_beside_it() {
        let seam =
            LightField::from_fn((2, 2), 10, 10, 13, |_, _, _, x, _| 0.01 * x as f32 + if x >= 5 { 0.04 } else { 0.0 });
        let s = seam_score(&seam, 0, 3);
        let want = 0.05 / (0.03 / 7.0);
        assert!((s - want).abs() <= 1e-3 * want, "score {s} vs {want}");
        assert_eq!(seam_score(&seam, 0, 0), 0.0, "no border inside");
    }
}
