//! Lenslet rows of a decoded light field: their layout ([`RowLayout`]), how a row of
//! weighted sums is finished ([`finish`]) and where finished rows go ([`RowSink`]).
//!
//! A row is every value of one lenslet row `y` over a run of lenslet columns, views
//! outermost: `(u, v, x, b)`, band fastest, so each view's part of the row is one
//! contiguous run of a `(U, V, H, W, B)` light field (and of its `.npy` file). Its weights
//! are one a pixel, `(u, v, x)`: a pixel's bands share their patches and their weight.

use core::fmt;

use crate::sensor::extent::{Array, Bands};

/// The shape of a run of lenslet rows: views and lenslet columns (the bands are the
/// engine's `B`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RowLayout {
    /// Views of a lenslet (rows, cols).
    pub views: (usize, usize),
    /// Lenslet columns of the run.
    pub cols: usize,
}

impl RowLayout {
    /// Pixels of a row: `U x V x cols`.
    #[inline]
    pub fn pixels(&self) -> usize {
        self.views.0 * self.views.1 * self.cols
    }

    /// Index of pixel `(u, v, x)` in a row's pixels (times the bands: of its first value).
    #[inline]
    pub fn pixel(&self, u: usize, v: usize, x: usize) -> usize {
        (u * self.views.1 + v) * self.cols + x
    }
}

/// Where finished lenslet rows go, each once, in order from the first.
pub trait RowSink {
    /// A write failure.
    type Error: fmt::Debug;

    /// Lenslet row `lenslet_row` over the lenslet columns from `first_col`: `values` in
    /// `(u, v, x, b)` order ([`RowLayout`]), each the weighted mean of the estimates that
    /// cover it.
    ///
    /// # Errors
    /// The sink's own error: the frame's decode stops there.
    fn row(&mut self, lenslet_row: u16, first_col: u16, values: &[f32]) -> Result<(), Self::Error>;
}

/// Values of a view no patch covered: filled from their lenslet's other views, or left 0
/// where none of them was covered either.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fill {
    pub filled: u32,
    pub uncovered: u32,
}

/// Finishes a row of sums in place: each value its sum over its pixel's weight, clamped to
/// the sensor's range `[lo, hi]` (the clamp takes off only what rounding adds; `max` then
/// `min`, as `f32::clamp` asserts its bounds, a panic path); a value of a view no patch
/// covered (weight 0) the mean of its lenslet's covered views, in view order; a lenslet
/// with none 0. `values` and `weights` are one row of `layout` with `B` bands.
pub fn finish<C: Bands>(values: &mut [f32], weights: &[f32], layout: RowLayout, (lo, hi): (f32, f32), fill: &mut Fill) {
    for (x, &w) in C::chunks_mut(values).iter_mut().zip(weights) {
        if w > 0.0 {
            for x in x.iter_mut() {
                *x = (*x / w).max(lo).min(hi);
            }
        }
    }
    // Each lenslet's views, `cols` pixels apart: their mean where some are not covered.
    let (views, cols) = (layout.views.0 * layout.views.1, layout.cols);
    let pixels = C::chunks_mut(values);
    for x in 0..cols {
        let mut mean = C::ZEROS;
        let mut covered = 0u32;
        for p in (0..views).map(|view| view * cols + x) {
            if let (Some(&w), Some(v)) = (weights.get(p), pixels.get(p))
                && w > 0.0
            {
                for (m, &v) in mean.iter_mut().zip(v.iter()) {
                    *m += v;
                }
                covered += 1;
            }
        }
        if covered == views as u32 {
            continue;
        }
        for p in (0..views).map(|view| view * cols + x) {
            let (Some(&w), Some(v)) = (weights.get(p), pixels.get_mut(p)) else { continue };
            if w > 0.0 {
                continue;
            }
            if covered > 0 {
                for (v, &m) in v.iter_mut().zip(mean.iter()) {
                    *v = (m / covered as f32).max(lo).min(hi);
                }
                fill.filled += C::D as u32;
            } else {
                fill.uncovered += C::D as u32;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of 2 x 2 views and 3 columns of 2 bands, finished, against each value worked by
    /// hand: column 0 every view covered, column 1 two views covered (the other two take
    /// their mean), column 2 none (left 0); a sum past the range is clamped.
    #[test]
    fn a_row_is_its_weighted_means_with_uncovered_views_filled() {
        let layout = RowLayout { views: (2, 2), cols: 3 };
        // Pixels `(u, v, x)`: view-major, `cols` apart.
        let mut weights = [0.0f32; 12];
        let mut values = [0.0f32; 24];
        let mut set = |view: usize, x: usize, w: f32, sum: [f32; 2]| {
            let p = view * 3 + x;
            weights[p] = w;
            values[p * 2..p * 2 + 2].copy_from_slice(&sum);
        };
        for view in 0..4 {
            set(view, 0, 2.0, [0.2 * view as f32, 0.4]);
        }
        set(1, 1, 4.0, [0.8, 1.2]);
        set(2, 1, 1.0, [0.5, 9.0]);
        let mut fill = Fill::default();
        finish::<crate::sensor::extent::Fixed<2>>(&mut values, &weights, layout, (0.0, 1.0), &mut fill);
        let at = |view: usize, x: usize| {
            let p = (view * 3 + x) * 2;
            [values[p], values[p + 1]]
        };
        for view in 0..4 {
            assert_eq!(at(view, 0), [0.1 * view as f32, 0.2]);
        }
        // Covered: (0.2, 0.3) and (0.5, 9.0 clamped to 1.0); the others their mean.
        assert_eq!(at(1, 1), [0.2, 0.3]);
        assert_eq!(at(2, 1), [0.5, 1.0]);
        for view in [0, 3] {
            assert_eq!(at(view, 1), [(0.2 + 0.5) / 2.0, (0.3 + 1.0) / 2.0]);
        }
        for view in 0..4 {
            assert_eq!(at(view, 2), [0.0, 0.0]);
        }
        assert_eq!(fill, Fill { filled: 4, uncovered: 8 });
    }
}
