//! A band of the sensor's columns decoded on its own ([`Band`]), for a strip narrower than
//! the sensor: a device whose RAM holds the rows of a few dozen lenslet columns, not of the
//! whole width.
//!
//! A band puts its own columns `out`. Every estimate of a value in them comes from a tile
//! that reaches them, so the band decodes those tiles, in the plan's order: the shifted
//! tiles that reach `out`, and the disjoint tiles that reach `held`, which is `out` and, in a
//! seeded decode, every column those shifted tiles reach (their seeds are read there, and a
//! seed is final only once every disjoint tile that reaches it is added). So each value of a
//! band is the sum of the same estimates in the same order as in a decode of the whole
//! width, and a tile that reaches two bands is decoded for each: the price of the smaller
//! strip ([`Band::tiles`] counts it).

use core::ops::Range;

use crate::decode::engine::plan::{Grids, Planned};

/// A band of columns: config.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Band {
    /// Lenslet columns put.
    pub out: Range<usize>,
    /// Lenslet columns held: `out` and the columns its seeds are read from.
    pub held: Range<usize>,
}

fn meets(a: &Range<usize>, b: &Range<usize>) -> bool {
    a.start < b.end && b.start < a.end
}

impl Band {
    /// The band of `grids` that puts columns `out` (clipped to the sensor), seeded or not.
    pub fn new(grids: &Grids, out: Range<usize>, seeded: bool) -> Self {
        let cols = grids.lenslets().1;
        let out = out.start.min(cols)..out.end.min(cols);
        let mut held = out.clone();
        if seeded {
            for p in grids.shifted() {
                let reach = grids.cols(&p.tile);
                if meets(&reach, &out) {
                    held = held.start.min(reach.start)..held.end.max(reach.end);
                }
            }
        }
        Self { out, held }
    }

    /// The disjoint tiles the band decodes, in the plan's order.
    pub fn disjoint(&self, grids: &Grids) -> impl Iterator<Item = Planned> + Clone + use<> {
        let (g, held) = (*grids, self.held.clone());
        g.disjoint().filter(move |p| meets(&g.cols(&p.tile), &held))
    }

    /// The shifted tiles the band decodes, in the plan's order.
    pub fn shifted(&self, grids: &Grids) -> impl Iterator<Item = Planned> + Clone + use<> {
        let (g, out) = (*grids, self.out.clone());
        g.shifted().filter(move |p| meets(&g.cols(&p.tile), &out))
    }

    /// Tiles the band decodes.
    pub fn tiles(&self, grids: &Grids) -> usize {
        self.disjoint(grids).count() + self.shifted(grids).count()
    }

    /// The bands of at most `width` (at least 1) output columns across the sensor.
    pub fn across(grids: &Grids, width: usize, seeded: bool) -> impl Iterator<Item = Band> + use<> {
        let (g, width) = (*grids, core::num::NonZeroUsize::new(width).unwrap_or(core::num::NonZeroUsize::MIN));
        let bands = (g.lenslets().1 + width.get() - 1) / width;
        (0..bands).map(move |i| Band::new(&g, i * width.get()..(i + 1) * width.get(), seeded))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::engine::schedule::Schedule;

    /// A band's schedule never holds more rows than the whole width's: a strip sized for the
    /// whole width's rows decodes every band (the device's driver relies on it).
    #[test]
    fn a_band_holds_no_more_rows_than_the_whole_width() {
        for lenslets in [(8, 11), (17, 16), (23, 31), (12, 5)] {
            for stride in [(1, 1), (2, 2), (3, 2), (5, 5)] {
                for halo in [0, 1, 2] {
                    let g = Grids::new(lenslets, (5, 5), stride, (1, 1), (1, 1), halo).unwrap();
                    let whole = Schedule::new(g, g.disjoint(), g.shifted()).needs(1);
                    for width in 1..=usize::from(lenslets.1) {
                        for band in Band::across(&g, width, true) {
                            let n = Schedule::new(g, band.disjoint(&g), band.shifted(&g)).needs(1);
                            let what = (lenslets, stride, halo, width, &band);
                            assert!(
                                n.rows <= whole.rows && n.seed_rows <= whole.seed_rows,
                                "{what:?}: {n:?} > {whole:?}"
                            );
                            assert!(band.held.start <= band.out.start && band.out.end <= band.held.end, "{what:?}");
                        }
                    }
                }
            }
        }
    }
}
