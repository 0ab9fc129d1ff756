//! Overlapping patches in bounded memory: a strip of accumulated lenslet rows.
//!
//! Disjoint patches leave a grid at their borders, where each side was solved from a
//! different patch's measurements. Patches at a stride below the patch size, each estimate
//! weighed by a [`Window`] and averaged, remove it (issue 17, `docs/results-real.md`). The
//! host averages into a whole frame; a device cannot hold one, so the
//! [`OverlapDecoder`] walks the patches in order of their first lenslet row and keeps only
//! the rows a patch can still reach: a ring of `PS` lenslet rows, in a caller-owned `f32`
//! buffer. A row is finished when the walk passes it; it is divided by its weights and
//! handed to a [`RowSink`], and its slot is reused.
//!
//! The ring is as wide as the buffer allows: a buffer narrower than the sensor cuts the
//! frame into vertical bands decoded one after the other, and a patch that straddles a
//! band's border is decoded once for each band it reaches (the price of the smaller
//! buffer; [`OverlapDecoder::patch_decodes`] counts it). The output does not depend on the
//! band width beyond float summation order.
//!
//! The patches are those of the host's decode at the same stride (`slf_host::decode`):
//! the disjoint grid from lenslet `(0, 0)` with the end-aligned edge strips of
//! [`TileDecoder::tiles`], and one more disjoint grid shifted by `(dy, dx)` for every pair
//! of multiples of the stride below the patch size other than `(0, 0)`, whole patches only.

use core::fmt;

use crate::decode::tile::{ConfigError, PatchOrigin, PatchReport, PatchSink, Tile, TileDecoder, TileReport};
use crate::operators::shape::PatchShape;
use crate::sensor::source::TileSource;
use crate::solver::choice::PatchModel;
use crate::solver::workspace::Workspace;

/// How overlapping estimates of a value are weighed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Window {
    /// Every value of a patch counts the same.
    #[default]
    Uniform,
    /// A patch's lenslet weighs `1 + its distance from the patch's nearest edge` per axis
    /// (1, 2, 3, 2, 1 across the paper's 5 lenslets), the axes multiplied: a value is
    /// taken mostly from the patches it sits in the middle of, where a patch's model is
    /// best constrained.
    Tapered,
}

impl Window {
    /// The weight of lenslet `(s, t)` of a `PS x PT` patch.
    #[inline]
    pub fn weight<const PS: usize, const PT: usize>(self, s: usize, t: usize) -> f32 {
        let taper = |i: usize, p: usize| (1 + i.min(p.saturating_sub(1).saturating_sub(i))) as f32;
        match self {
            Window::Uniform => 1.0,
            Window::Tapered => taper(s, PS) * taper(t, PT),
        }
    }
}

/// Where patches sit and how their estimates are averaged. Config: immutable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Overlap {
    /// Lenslets between patch grids (rows, cols), each in `1..=` the patch's size; the
    /// patch size itself is the disjoint grid alone.
    pub stride: (u8, u8),
    /// How the estimates of one value are weighed.
    pub window: Window,
}

impl Overlap {
    /// The device's strip: stride 3, tapered window (the host's default with the paper's
    /// patch; the host's full-view default is stride 2).
    pub const DEFAULT: Self = Self { stride: (3, 3), window: Window::Tapered };
}

/// Receives the finished lenslet rows of an overlapped decode.
pub trait RowSink {
    /// A write failure. `Copy`, to travel in errors.
    type Error: Copy + fmt::Debug;

    /// One finished lenslet row, of the band of lenslet columns that starts at
    /// `first_col`: `values` in `(col, view_row, view_col, band)` order, band fastest, each
    /// the weighted mean of every decoded estimate of it. A value no decoded patch covered
    /// is 0 (counted in [`OverlapReport::uncovered`]).
    ///
    /// # Errors
    /// The sink's own error: the frame's decode stops there.
    fn row(&mut self, lenslet_row: u16, first_col: u16, values: &[f32]) -> Result<(), Self::Error>;
}

/// What an overlapped frame decode did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OverlapReport {
    /// Patch solves over every band (a patch straddling two bands counts twice).
    pub patches: TileReport,
    /// Patch positions whose source read failed (nothing of them was averaged in).
    pub source_failures: u32,
    /// Values no decoded patch covered (sent as 0).
    pub uncovered: u32,
    /// Values of a view no sheared patch covered, taken from the lenslet's other views.
    pub filled: u32,
    /// Vertical bands the frame was decoded in.
    pub bands: u16,
}

/// Errors of an overlapped frame decode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OverlapError<K> {
    /// The strip buffer holds less than one lenslet column of the ring.
    Strip,
    /// The row sink failed; the rows sent before stay sent.
    Sink(K),
}

impl<K: fmt::Debug> fmt::Display for OverlapError<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Strip => f.write_str("strip buffer smaller than one lenslet column of patch rows"),
            Self::Sink(e) => write!(f, "row sink failed: {e:?}"),
        }
    }
}

impl<K: fmt::Debug> core::error::Error for OverlapError<K> {}

/// Whether `x` is a patch origin along an axis of `total` lenslets for patches of `p`
/// lenslets in the grid shifted by `offset`; the unshifted grid of the `(0, 0)` pair also
/// has its end-aligned edge strip (`edge`).
fn on_grid(x: usize, total: usize, p: usize, offset: usize, edge: bool) -> bool {
    let (Some(last), Some(d)) = (total.checked_sub(p), x.checked_sub(offset)) else {
        return false;
    };
    if x > last || p == 0 {
        return false;
    }
    d.is_multiple_of(p) || (edge && x == last && !total.is_multiple_of(p))
}

/// Bands `(first, end)` of at most `band` (at least 1) lenslet columns across `cols`.
fn bands(cols: usize, band: usize) -> impl Iterator<Item = (usize, usize)> {
    let band = band.max(1);
    (0..cols).step_by(band).map(move |c0| (c0, (c0 + band).min(cols)))
}

/// The tile decoder with patches at a stride: checked config, stateless.
#[derive(Clone, Copy, Debug)]
pub struct OverlapDecoder<
    'a,
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
> {
    tiles: TileDecoder<'a, PS, PT, PU, PV, B, N>,
    overlap: Overlap,
}

impl<'a, const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    OverlapDecoder<'a, PS, PT, PU, PV, B, N>
{
    /// Checks the stride against the patch.
    ///
    /// # Errors
    /// [`ConfigError::Stride`] for a stride axis outside `1..=` the patch's size.
    pub fn new(tiles: TileDecoder<'a, PS, PT, PU, PV, B, N>, overlap: Overlap) -> Result<Self, ConfigError> {
        let ok = |s: u8, p: usize| (1..=p).contains(&usize::from(s));
        if !ok(overlap.stride.0, PS) || !ok(overlap.stride.1, PT) {
            return Err(ConfigError::Stride);
        }
        Ok(Self { tiles, overlap })
    }

    /// The tile decoder underneath.
    pub fn tiles(&self) -> &TileDecoder<'a, PS, PT, PU, PV, B, N> {
        &self.tiles
    }

    /// Lenslet views (rows, cols) of the sensor.
    fn views(&self) -> (usize, usize) {
        let l = self.tiles.config().sensor.lenslet;
        (l.rows as usize, l.cols as usize)
    }

    /// Lenslets a sheared patch reaches beyond its rectangle (rows, cols): the halo of
    /// the tile decoder's disparity range ([`crate::operators::disparity`]; 0 when it is off).
    fn halo(&self) -> (usize, usize) {
        let (u, v) = self.views();
        let range = self.tiles.disparities();
        (range.halo(u), range.halo(v))
    }

    /// Lenslet rows the ring keeps: a patch's `PS` and its halo above and below.
    fn ring_rows(&self) -> usize {
        PS + 2 * self.halo().0
    }

    /// `f32`s of the strip per lenslet column: `PS` rows (and the rows a sheared patch
    /// reaches beyond them) of every view's `B` sums and one weight.
    pub fn strip_per_column(&self) -> usize {
        let (u, v) = self.views();
        self.ring_rows() * u * v * (B + 1)
    }

    /// `f32`s of a strip that decodes the whole sensor width in one band.
    pub fn strip_len(&self) -> usize {
        self.strip_per_column() * self.tiles.config().sensor.lenslets.1 as usize
    }

    /// The patch grids: offsets `(dy, dx)` (multiples of the stride below the patch size).
    fn grids(&self) -> impl Iterator<Item = (usize, usize)> + use<'a, PS, PT, PU, PV, B, N> {
        let (sy, sx) = (usize::from(self.overlap.stride.0.max(1)), usize::from(self.overlap.stride.1.max(1)));
        (0..PS).step_by(sy).flat_map(move |dy| (0..PT).step_by(sx).map(move |dx| (dy, dx)))
    }

    /// Number of grids whose patches start at lenslet `(row, col)` (a position can be on
    /// more than one: an edge strip and a shifted grid).
    pub fn starts_at(&self, row: usize, col: usize) -> usize {
        let (rows, cols) = self.tiles.config().sensor.lenslets;
        self.grids()
            .filter(|&(dy, dx)| {
                let edge = (dy, dx) == (0, 0);
                on_grid(row, rows as usize, PS, dy, edge) && on_grid(col, cols as usize, PT, dx, edge)
            })
            .count()
    }

    /// Columns of the grid's patches that start at lenslet row `r` and reach columns
    /// `c0..c1`, a column once for each grid that starts a patch there.
    fn starts(
        &self,
        r: usize,
        c0: usize,
        c1: usize,
    ) -> impl Iterator<Item = usize> + use<'_, 'a, PS, PT, PU, PV, B, N> {
        let h = self.halo().1;
        (c0.saturating_sub(PT - 1 + h)..c1 + h).flat_map(move |c| core::iter::repeat_n(c, self.starts_at(r, c)))
    }

    /// Patch solves (angular windows included) a frame costs when the strip holds `band`
    /// lenslet columns: a patch straddling a band border is decoded for each band.
    pub fn patch_decodes(&self, band: usize) -> usize {
        let (rows, cols) = self.tiles.config().sensor.lenslets;
        let (rows, cols) = (rows as usize, cols as usize);
        let positions: usize =
            bands(cols, band).map(|(c0, c1)| (0..rows).map(|r| self.starts(r, c0, c1).count()).sum::<usize>()).sum();
        positions * self.tiles.windows().count()
    }

    /// Decodes the whole frame with `model`, every patch position at this stride, and
    /// sends each finished lenslet row to `sink`, in row order per band. `strip` is the
    /// ring ([`strip_len`](Self::strip_len) `f32`s decode the sensor's full width in one
    /// band; fewer give narrower bands, at least [`strip_per_column`](Self::strip_per_column)).
    ///
    /// A patch whose read fails is counted and left out; the rest of the frame is decoded.
    ///
    /// # Errors
    /// [`OverlapError::Strip`] before anything is read; [`OverlapError::Sink`] stops the
    /// decode (the rows sent stay sent).
    pub fn decode_frame<M: PatchModel<PS, PT, PU, PV, B, N>, S: TileSource, K: RowSink>(
        &self,
        model: &M,
        source: &mut S,
        strip: &mut [f32],
        sink: &mut K,
        ws: &mut Workspace<PS, PT, PU, PV, B, N>,
    ) -> Result<OverlapReport, OverlapError<K::Error>> {
        let (rows, cols) = self.tiles.config().sensor.lenslets;
        let (rows, cols) = (rows as usize, cols as usize);
        let per_col = self.strip_per_column();
        let band = (strip.len() / per_col.max(1)).min(cols);
        if band == 0 {
            return Err(OverlapError::Strip);
        }
        let (vu, vv) = self.views();
        let halo = self.halo().0;
        let mut report = OverlapReport::default();
        for (c0, c1) in bands(cols, band) {
            report.bands += 1;
            let mut ring = Ring::<PS, PT, PU, PV, B, N> {
                strip: &mut *strip,
                first_col: c0,
                cols: c1 - c0,
                rows: self.ring_rows(),
                frame_rows: rows,
                views: (vu, vv),
                window: self.overlap.window,
                range: self.tiles.config().raw.range(),
            };
            ring.clear();
            let mut next_row = 0;
            for r in 0..rows {
                // Rows above `r - halo` are finished: no later patch reaches them.
                while next_row + halo < r {
                    ring.flush(next_row, sink, &mut report)?;
                    next_row += 1;
                }
                for c in self.starts(r, c0, c1) {
                    let tile = Tile {
                        lenslet_row: r as u16,
                        lenslet_col: c as u16,
                        lenslet_rows: PS as u16,
                        lenslet_cols: PT as u16,
                    };
                    match self.tiles.decode_tile(model, tile, source, &mut ring, ws) {
                        Ok(t) => report.patches.add(&t),
                        Err(_) => report.source_failures += 1,
                    }
                }
            }
            while next_row < rows {
                ring.flush(next_row, sink, &mut report)?;
                next_row += 1;
            }
        }
        Ok(report)
    }
}

/// The strip during one band: `rows` slots of `cols` lenslets, each slot the sums
/// `(col, u, v, b)` and then the weights `(col, u, v)`; lenslet row `y` is in slot
/// `y % rows`.
struct Ring<'s, const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize> {
    strip: &'s mut [f32],
    first_col: usize,
    cols: usize,
    /// Slots: `PS` and the shear's halo above and below.
    rows: usize,
    /// Lenslet rows of the sensor: a sheared value beyond them is dropped.
    frame_rows: usize,
    views: (usize, usize),
    window: Window,
    /// The sensor's physical range: a mean of estimates inside it stays inside it, and
    /// the clamp takes off what rounding adds (`max` then `min`: `f32::clamp` asserts its
    /// bounds, a panic path).
    range: (f32, f32),
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    Ring<'_, PS, PT, PU, PV, B, N>
{
    fn slot_len(&self) -> usize {
        self.cols * self.views.0 * self.views.1 * (B + 1)
    }

    fn clear(&mut self) {
        let n = self.rows * self.slot_len();
        if let Some(s) = self.strip.get_mut(..n) {
            s.fill(0.0);
        }
    }

    /// Slot `y % rows` split into its sums and weights.
    fn slot(&mut self, y: usize) -> Option<(&mut [f32], &mut [f32])> {
        let len = self.slot_len();
        let sums = self.cols * self.views.0 * self.views.1 * B;
        let start = (y % self.rows.max(1)) * len;
        self.strip.get_mut(start..start + len).map(|s| s.split_at_mut(sums.min(len)))
    }

    /// Divides row `y` by its weights, sends it, and clears its slot. A view of a lenslet
    /// that no patch covered (sheared patches can leave one at the frame's edge or between
    /// blocks sheared apart) takes the mean of the lenslet's covered views.
    fn flush<K: RowSink>(
        &mut self,
        y: usize,
        sink: &mut K,
        report: &mut OverlapReport,
    ) -> Result<(), OverlapError<K::Error>> {
        let first_col = self.first_col as u16;
        let views = self.views.0 * self.views.1;
        let (lo, hi) = self.range;
        let Some((sums, weights)) = self.slot(y) else {
            return Ok(());
        };
        // (`max(1)`: a chunk size of 0 is a panic path; the views are at least 1.)
        for (lenslet, lw) in sums.chunks_exact_mut((views * B).max(1)).zip(weights.chunks_exact_mut(views.max(1))) {
            let mut mean = [0.0f32; B];
            let mut covered = 0u32;
            for (values, w) in lenslet.chunks_exact_mut(B).zip(lw.iter()) {
                if *w > 0.0 {
                    for (x, m) in values.iter_mut().zip(mean.iter_mut()) {
                        *x = (*x / *w).max(lo).min(hi);
                        *m += *x;
                    }
                    covered += 1;
                }
            }
            if covered == 0 {
                report.uncovered += (views * B) as u32;
            } else if covered < views as u32 {
                for m in mean.iter_mut() {
                    *m = (*m / covered as f32).max(lo).min(hi);
                }
                for (values, w) in lenslet.chunks_exact_mut(B).zip(lw.iter()) {
                    if *w <= 0.0 {
                        values.copy_from_slice(&mean);
                        report.filled += B as u32;
                    }
                }
            }
            lw.fill(0.0);
        }
        let sent = sink.row(y as u16, first_col, sums).map_err(OverlapError::Sink);
        sums.fill(0.0);
        sent
    }
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize> PatchSink<N>
    for Ring<'_, PS, PT, PU, PV, B, N>
{
    type Error = core::convert::Infallible;

    fn accept(&mut self, o: PatchOrigin, patch: &[f32; N], r: &PatchReport) -> Result<(), Self::Error> {
        let scale = if r.fallback { crate::operators::disparity::FALLBACK_WEIGHT } else { 1.0 };
        let (vu, vv) = self.views;
        let (first, cols, window, frame_rows) = (self.first_col, self.cols, self.window, self.frame_rows);
        for s in 0..PS {
            for u in 0..PU {
                for t in 0..PT {
                    let w = scale * window.weight::<PS, PT>(s, t);
                    for v in 0..PV {
                        // The pixel the value was read from (sheared patches: shifted per view).
                        let Some((row, col)) = o.lenslet::<PS, PT>(s, t, u, v, (vu, vv)) else {
                            continue;
                        };
                        let Some(c) =
                            usize::try_from(col).ok().and_then(|c| c.checked_sub(first)).filter(|&c| c < cols)
                        else {
                            continue;
                        };
                        let Some(row) = usize::try_from(row).ok().filter(|&r| r < frame_rows) else {
                            continue;
                        };
                        let Some((sums, weights)) = self.slot(row) else {
                            continue;
                        };
                        let at = (c * vu + o.view_row as usize + u) * vv + o.view_col as usize + v;
                        let i = PatchShape::<PS, PT, PU, PV, B, N>::pixel_index(s, t, u, v);
                        let (Some(dst), Some(src), Some(wt)) =
                            (sums.get_mut(at * B..at * B + B), patch.get(i..i + B), weights.get_mut(at))
                        else {
                            continue;
                        };
                        for (d, x) in dst.iter_mut().zip(src) {
                            *d += w * x;
                        }
                        *wt += w;
                    }
                }
            }
        }
        Ok(())
    }
}
