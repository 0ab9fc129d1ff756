//! A pixel's footprint: the share of a sensor pixel each view cell of a lenslet grid covers.
//!
//! A pixel integrates the light that falls on its square. Behind a lenslet grid
//! ([`crate::io::grid`]) the square lies across view cells, and across the micro-images'
//! borders too. The light field is constant over a view cell (a view is what one pixel of
//! the aligned sensor saw), so the pixel records the cells' light weighted by the share of
//! its area each covers. The shares are exact: the square mapped to cell coordinates is a
//! parallelogram, clipped against each cell it reaches (Sutherland-Hodgman, against the
//! cell's four sides) and measured with the shoelace formula.

use crate::io::grid::GridDescription;

/// The most vertices a clipped parallelogram can have (4 sides cut by 4 more).
const MAX_VERTICES: usize = 8;

/// A convex polygon of at most [`MAX_VERTICES`] vertices.
#[derive(Clone, Copy)]
struct Polygon {
    points: [[f64; 2]; MAX_VERTICES],
    len: usize,
}

impl Polygon {
    fn area(&self) -> f64 {
        let p = &self.points[..self.len];
        let twice: f64 = (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum();
        0.5 * twice.abs()
    }

    /// The part at or below (`below`) or at or above `at` along `axis`.
    fn clip(&self, axis: usize, at: f64, below: bool) -> Self {
        let inside = |p: [f64; 2]| if below { p[axis] <= at } else { p[axis] >= at };
        let mut out = Polygon { points: [[0.0; 2]; MAX_VERTICES], len: 0 };
        let mut push = |p: [f64; 2]| {
            if out.len < MAX_VERTICES {
                out.points[out.len] = p;
                out.len += 1;
            }
        };
        for i in 0..self.len {
            let (a, b) = (self.points[i], self.points[(i + 1) % self.len]);
            let (ia, ib) = (inside(a), inside(b));
            if ia {
                push(a);
            }
            if ia != ib {
                let f = (at - a[axis]) / (b[axis] - a[axis]);
                push([a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]);
            }
        }
        out
    }
}

/// Pixel `(row, col)`'s footprint on `grid`'s view cells for `views` views, into `out`:
/// each cell `(i, j)` it covers (`(s U + u, t V + v)`, possibly outside the light field)
/// with the share of the pixel's area it covers. The shares sum to 1.
pub fn footprint(grid: &GridDescription, views: [usize; 2], row: usize, col: usize, out: &mut Vec<([i64; 2], f64)>) {
    out.clear();
    let (r, c) = (row as f64, col as f64);
    let corners = [[r, c], [r, c + 1.0], [r + 1.0, c + 1.0], [r + 1.0, c]].map(|p| grid.cell(views, p));
    let mut square = Polygon { points: [[0.0; 2]; MAX_VERTICES], len: 4 };
    square.points[..4].copy_from_slice(&corners);
    let whole = square.area();
    let lo = |a: usize| corners.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min).floor() as i64;
    let hi = |a: usize| corners.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max).ceil() as i64;
    for i in lo(0)..hi(0) {
        let band = square.clip(0, i as f64, false).clip(0, (i + 1) as f64, true);
        if band.len < 3 {
            continue;
        }
        for j in lo(1)..hi(1) {
            let cell = band.clip(1, j as f64, false).clip(1, (j + 1) as f64, true);
            if cell.len < 3 {
                continue;
            }
            let share = cell.area() / whole;
            if share > 1e-12 {
                out.push(([i, j], share));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_aligned_pixel_is_its_own_cell() {
        let g = GridDescription::aligned([4, 4], [5, 5]);
        let mut out = Vec::new();
        for (row, col) in [(0, 0), (7, 13), (19, 19)] {
            footprint(&g, [5, 5], row, col, &mut out);
            assert_eq!(out.len(), 1);
            assert_eq!(out[0].0, [row as i64, col as i64]);
            assert!((out[0].1 - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn shares_sum_to_one_and_follow_a_shift() {
        // Shifted by a quarter pixel down: a pixel covers 3/4 of its cell and 1/4 of the one above.
        let g = GridDescription { offset: [2.75, 2.5], ..GridDescription::aligned([4, 4], [5, 5]) };
        let mut out = Vec::new();
        footprint(&g, [5, 5], 7, 3, &mut out);
        out.sort_by_key(|c| c.0);
        assert_eq!(out.len(), 2);
        assert_eq!((out[0].0, out[1].0), ([6, 3], [7, 3]));
        assert!((out[0].1 - 0.25).abs() < 1e-12 && (out[1].1 - 0.75).abs() < 1e-12, "{out:?}");
        let g = GridDescription::centred([10, 10], 0.8, [5.1, 4.95]);
        for (row, col) in [(0, 0), (23, 31), (40, 12)] {
            footprint(&g, [5, 5], row, col, &mut out);
            assert!((out.iter().map(|c| c.1).sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(out.len() >= 2 && out.len() <= 9, "{out:?}");
        }
    }
}
