//! Where a frame's patches sit and in which order their estimates join ([`Grids`]).
//!
//! The order is the decode's canonical one, the same on the host and the device whatever
//! the batches: the disjoint grid's tiles row by row ([`Grids::disjoint`], the tiles of
//! [`TileDecoder::tiles`](crate::tile::TileDecoder::tiles)), then the tiles of the grids
//! shifted by multiples of the stride by their first lenslet row ([`Grids::shifted`]; at
//! one row, grid by grid). Both are iterators computed from the sizes: no list is held.
//! Each tile carries its place in the grid-by-grid order ([`Planned::order`]), the order
//! a report lists its patches in.

use core::num::NonZeroUsize;

use crate::decode::engine::error::EngineError;
use crate::decode::tile::Tile;

/// A size that is never zero: dividing by one has no division-by-zero panic path.
type Nz = NonZeroUsize;

/// A tile and its place in the canonical grid-by-grid order (the disjoint grid row by row,
/// then each shifted grid in turn).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Planned {
    pub tile: Tile,
    pub order: u32,
}

/// The patch grids of a frame: config, checked by [`Grids::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Grids {
    /// Lenslet rows and columns of the sensor.
    lenslets: (usize, usize),
    /// Lenslets of a patch (rows, cols).
    patch: (Nz, Nz),
    /// Lenslets between the grids, each axis in `1..=` the patch's size.
    stride: (Nz, Nz),
    /// Patches a disjoint tile holds (rows, cols).
    disjoint_per: (Nz, Nz),
    /// Patches a shifted tile holds (rows, cols).
    shifted_per: (Nz, Nz),
    /// Lenslets a sheared patch reaches beyond its tile on every side.
    halo: usize,
}

/// Spans along one axis of `total` lenslets of the grid shifted by `offset`, for patches of
/// `patch` lenslets, `per` patches a span, whole patches only.
fn spans(total: usize, offset: usize, patch: Nz, per: Nz) -> usize {
    (total.saturating_sub(offset) / patch + per.get() - 1) / per
}

/// Span `i` `(start, length)` of [`spans`].
fn span(total: usize, offset: usize, patch: Nz, per: Nz, i: usize) -> (usize, usize) {
    let whole = total.saturating_sub(offset) / patch;
    (offset + i * per.get() * patch.get(), per.get().min(whole.saturating_sub(i * per.get())) * patch.get())
}

/// The spans of [`spans`], in order.
fn shifted_spans(total: usize, offset: usize, patch: Nz, per: Nz) -> impl Iterator<Item = (usize, usize)> + Clone {
    (0..spans(total, offset, patch, per)).map(move |i| span(total, offset, patch, per, i))
}

/// Spans `(start, length)` of the disjoint grid along one axis: the grid from 0, then an
/// end-aligned strip of one patch where the patches do not fill the axis
/// ([`TileDecoder::tiles`](crate::tile::TileDecoder::tiles)).
fn disjoint_spans(total: usize, patch: Nz, per: Nz) -> impl Iterator<Item = (usize, usize)> + Clone {
    let whole = total / patch;
    let edge = (whole > 0 && total % patch != 0).then(|| (total - patch.get(), patch.get()));
    shifted_spans(total, 0, patch, per).chain(edge)
}

/// Multiples of `step` below `end`.
fn multiples(end: Nz, step: Nz) -> impl Iterator<Item = usize> + Clone {
    (0..(end.get() + step.get() - 1) / step).map(move |i| i * step.get())
}

fn tile(r: (usize, usize), c: (usize, usize)) -> Tile {
    Tile { lenslet_row: r.0 as u16, lenslet_col: c.0 as u16, lenslet_rows: r.1 as u16, lenslet_cols: c.1 as u16 }
}

impl Grids {
    /// The grids of a sensor of `lenslets` for patches of `patch` lenslets at `stride`,
    /// with `disjoint_per` and `shifted_per` patches a tile and sheared patches reaching
    /// `halo` lenslets beyond their tile.
    ///
    /// # Errors
    /// [`EngineError::Grids`] for a stride axis outside `1..=` the patch's size, an empty
    /// patch or tile, or a patch or halo over 64 lenslets.
    pub fn new(
        lenslets: (u16, u16),
        patch: (usize, usize),
        stride: (u8, u8),
        disjoint_per: (u16, u16),
        shifted_per: (u16, u16),
        halo: usize,
    ) -> Result<Self, EngineError> {
        let ok = |s: u8, p: usize| (1..=p).contains(&usize::from(s)) && p <= 64;
        if !ok(stride.0, patch.0) || !ok(stride.1, patch.1) || halo > 64 {
            return Err(EngineError::Grids);
        }
        let nz = |a: usize, b: usize| Nz::new(a).zip(Nz::new(b)).ok_or(EngineError::Grids);
        Ok(Self {
            lenslets: (usize::from(lenslets.0), usize::from(lenslets.1)),
            patch: nz(patch.0, patch.1)?,
            stride: nz(usize::from(stride.0), usize::from(stride.1))?,
            disjoint_per: nz(usize::from(disjoint_per.0), usize::from(disjoint_per.1))?,
            shifted_per: nz(usize::from(shifted_per.0), usize::from(shifted_per.1))?,
            halo,
        })
    }

    /// Lenslet rows and columns of the sensor.
    pub fn lenslets(&self) -> (usize, usize) {
        self.lenslets
    }

    /// Lenslets a sheared patch reaches beyond its tile on every side.
    pub fn halo(&self) -> usize {
        self.halo
    }

    /// The disjoint grid's tiles, row by row: the order their sums join the rows in.
    pub fn disjoint(&self) -> impl Iterator<Item = Planned> + Clone + use<> {
        let (rows, cols) = self.lenslets;
        let (ps, pt) = self.patch;
        let per = self.disjoint_per;
        disjoint_spans(rows, ps, per.0)
            .flat_map(move |r| disjoint_spans(cols, pt, per.1).map(move |c| tile(r, c)))
            .zip(0u32..)
            .map(|(tile, order)| Planned { tile, order })
    }

    /// Tiles of the disjoint grid.
    pub fn disjoint_len(&self) -> usize {
        let (rows, cols) = self.lenslets;
        disjoint_spans(rows, self.patch.0, self.disjoint_per.0).count()
            * disjoint_spans(cols, self.patch.1, self.disjoint_per.1).count()
    }

    /// The shifted grids' offsets `(dy, dx)`, in their canonical order: every pair of
    /// multiples of the stride below the patch's size but `(0, 0)`.
    fn offsets(&self) -> impl Iterator<Item = (usize, usize)> + Clone + use<> {
        let (ps, pt) = self.patch;
        let (sy, sx) = self.stride;
        multiples(ps, sy).flat_map(move |dy| multiples(pt, sx).map(move |dx| (dy, dx))).filter(|&o| o != (0, 0))
    }

    /// Tiles of the grid shifted by `(dy, dx)`.
    fn grid_len(&self, (dy, dx): (usize, usize)) -> usize {
        let (rows, cols) = self.lenslets;
        let (sr, sc) = self.shifted_per;
        spans(rows, dy, self.patch.0, sr) * spans(cols, dx, self.patch.1, sc)
    }

    /// The shifted grids' tiles by their first lenslet row; at one row grid by grid, each
    /// grid's tiles left to right (the grid-by-grid order sorted stably by first row).
    pub fn shifted(&self) -> Shifted {
        Shifted { grids: *self, row: 0, dx: 0, col: 0 }
    }

    /// Tiles of the shifted grids.
    pub fn shifted_len(&self) -> usize {
        self.offsets().map(|o| self.grid_len(o)).sum()
    }

    /// Lenslet rows a tile's estimates reach: its own and the halo beside them, on the
    /// sensor.
    pub fn rows(&self, tile: &Tile) -> core::ops::Range<usize> {
        let row = usize::from(tile.lenslet_row);
        row.saturating_sub(self.halo)..(row + usize::from(tile.lenslet_rows) + self.halo).min(self.lenslets.0)
    }

    /// Lenslet columns a tile's estimates reach: its own and the halo beside them, on the
    /// sensor.
    pub fn cols(&self, tile: &Tile) -> core::ops::Range<usize> {
        let col = usize::from(tile.lenslet_col);
        col.saturating_sub(self.halo)..(col + usize::from(tile.lenslet_cols) + self.halo).min(self.lenslets.1)
    }
}

/// The shifted grids' tiles in the plan's order ([`Grids::shifted`]): a walk down the
/// sensor's rows, at each row the grids whose tiles start there.
#[derive(Clone, Debug)]
pub struct Shifted {
    grids: Grids,
    /// The lenslet row walked, the grid's column offset (its index) and the column span.
    row: usize,
    dx: usize,
    col: usize,
}

impl Iterator for Shifted {
    type Item = Planned;

    fn next(&mut self) -> Option<Planned> {
        let g = self.grids;
        let (rows, cols) = g.lenslets;
        let ((ps, pt), (sy, sx), (sr, sc)) = (g.patch, g.stride, g.shifted_per);
        let offsets_x = (pt.get() + sx.get() - 1) / sx;
        // Each step moves to the next span, grid or row: at most rows x grids x spans.
        while self.row < rows {
            // At row `r`, only the grids of offset `r % ps` can start a tile: their rows
            // start at the offset plus multiples of `ps` times their tiles' rows.
            let dy = self.row % ps;
            let step = ps.saturating_mul(sr);
            let i = (self.row - dy) / step;
            let starts = dy % sy == 0 && (self.row - dy) % step == 0 && i < spans(rows, dy, ps, sr);
            if starts && self.dx < offsets_x {
                let dx = self.dx * sx.get();
                if (dy, dx) == (0, 0) || self.col >= spans(cols, dx, pt, sc) {
                    (self.dx, self.col) = (self.dx + 1, 0);
                    continue;
                }
                let j = self.col;
                self.col += 1;
                // The grid's place in the order: the disjoint grid's tiles and the grids
                // before it, then its tiles before row span `i`.
                let before: usize = g.offsets().take_while(|&o| o != (dy, dx)).map(|o| g.grid_len(o)).sum();
                let order = g.disjoint_len() + before + i * spans(cols, dx, pt, sc) + j;
                let tile = tile(span(rows, dy, ps, sr, i), span(cols, dx, pt, sc, j));
                return Some(Planned { tile, order: order as u32 });
            }
            (self.row, self.dx, self.col) = (self.row + 1, 0, 0);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;

    /// The plan written out: the disjoint grid row by row with its edge strips, then every
    /// shifted grid in turn, whole patches only, each tile numbered, and the shifted tiles
    /// sorted stably by first row.
    fn written_out(g: &Grids) -> (Vec<Planned>, Vec<Planned>) {
        let (rows, cols) = g.lenslets;
        let (ps, pt) = (g.patch.0.get(), g.patch.1.get());
        let (dp, sp, st) = (g.disjoint_per, g.shifted_per, g.stride);
        let (dp, sp, st) = ((dp.0.get(), dp.1.get()), (sp.0.get(), sp.1.get()), (st.0.get(), st.1.get()));
        let mut order = 0u32;
        let mut next = |tile| {
            order += 1;
            Planned { tile, order: order - 1 }
        };
        let axis = |total: usize, p: usize, per: usize, off: usize, edge: bool| {
            let mut v = Vec::new();
            let mut x = off;
            while x + p <= total {
                let n = ((total - x) / p).min(per);
                v.push((x, n * p));
                x += n * p;
            }
            if edge && !total.is_multiple_of(p) && total >= p {
                v.push((total - p, p));
            }
            v
        };
        let mut disjoint = Vec::new();
        for r in axis(rows, ps, dp.0, 0, true) {
            for c in axis(cols, pt, dp.1, 0, true) {
                disjoint.push(next(tile(r, c)));
            }
        }
        let mut shifted = Vec::new();
        for dy in (0..ps).step_by(st.0) {
            for dx in (0..pt).step_by(st.1) {
                if (dy, dx) == (0, 0) {
                    continue;
                }
                for r in axis(rows, ps, sp.0, dy, false) {
                    for c in axis(cols, pt, sp.1, dx, false) {
                        shifted.push(next(tile(r, c)));
                    }
                }
            }
        }
        shifted.sort_by_key(|p| p.tile.lenslet_row);
        (disjoint, shifted)
    }

    #[test]
    fn the_iterators_are_the_plan_written_out() {
        for lenslets in [(5, 5), (8, 11), (17, 16), (23, 40), (4, 9)] {
            for stride in [(1, 1), (2, 2), (3, 2), (2, 4), (5, 5)] {
                for (dp, sp) in [((1, 1), (1, 1)), ((2, 2), (2, 2)), ((2, 3), (1, 1)), ((3, 1), (2, 3))] {
                    let g = Grids::new(lenslets, (5, 5), stride, dp, sp, 2).unwrap();
                    let (d, s) = written_out(&g);
                    let what = (lenslets, stride, dp, sp);
                    assert_eq!(g.disjoint().collect::<Vec<_>>(), d, "{what:?}");
                    assert_eq!(g.shifted().collect::<Vec<_>>(), s, "{what:?}");
                    assert_eq!((g.disjoint_len(), g.shifted_len()), (d.len(), s.len()), "{what:?}");
                }
            }
        }
        assert!(Grids::new((10, 10), (5, 5), (0, 2), (1, 1), (1, 1), 0).is_err());
        assert!(Grids::new((10, 10), (5, 5), (2, 6), (1, 1), (1, 1), 0).is_err());
        assert!(Grids::new((10, 10), (5, 5), (2, 2), (0, 1), (1, 1), 0).is_err());
    }
}
