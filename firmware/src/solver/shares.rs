//! The projection of a patch behind a turned lenslet grid, whose measurements are the
//! shares of the view cells their pixels cover.
//!
//! Behind a real lenslet array (turned, a non-integer pitch, offset) a pixel is not a view
//! cell: its square lies up to half a cell off the cell whose centre it holds, and takes in
//! parts of the neighbouring cells, across a micro-image's border into the next lenslet's
//! views too. The pixel records each cell's light weighted by the share of its square the
//! cell covers ([`Measurements::set_shares`]). Along each axis the square is `width` cells
//! wide (the views over the pitch) and its centre sits at its place in its own cell
//! ([`Measurements::set_place`]), so it covers its own cell and one or two neighbours: the
//! shares of a 1D box, and of the pixel their product (the turn of the square itself, at
//! most a degree, is left out: it moves a corner by 0.01 cell). The unknowns stay the
//! light field's own views, so a decode's start, seed and output need no conversion.
//!
//! Call the operator `M`. SL0's projection `S <- S + D^T M^T (M M^T)^-1 (I - M D S)`
//! needs `(M M^T)^-1`. Two measurements share values only if they are of one band and
//! their pixels are neighbours, so `M M^T` is sparse, but its blocks of neighbours grow
//! with the measurements: at pixel k = 3 a band's neighbours chain across most of a
//! patch. The step here divides each measurement's residual by its row of `M M^T`
//! summed (`sum_j (M M^T)_ij = sum_c w_ic sum_j w_jc`, the shares of its cells that the
//! band's measurements cover, as SART scales its rows): for a measurement alone that is
//! its diagonal entry, the exact projection; for neighbours a shorter step, and since
//! every eigenvalue of the scaled `M M^T` is then in `(0, 1]` (its rows sum to 1), a
//! residual never grows from step to step, where dividing by the diagonal alone
//! diverges on a band measured everywhere. The blocks solved exactly (`L D L^T` of up
//! to 32 neighbours found breadth first) gave the same quality at seven times the time:
//! office at pixel k = 3 behind a grid turned 0.3 degrees at 5.04 px decoded to 39.07
//! dB in 22.7 s, the diagonal to 39.37 dB in 3.1 s (the aligned sensor: 44.12 dB in
//! 3.4 s, one thread).
//!
//! A neighbour is found on the sensor, not in the patch: a sheared patch's views are
//! shifted by whole lenslets ([`CellShares::shift`]), so the cell next to a pixel may sit
//! elsewhere in the patch. A share of a cell outside the patch is given to the pixel's own
//! cell (the light field taken as constant across that border): at the patch's edges
//! unsheared, at micro-image borders too when sheared; there a pixel largely outside the
//! patch is left out of its measurements ([`MAX_OUTSIDE_SHARE`]). Where a decode of the
//! frame holds those cells (a full-view patch of the overlapped decode's shifted grids,
//! seeded by the disjoint grid's decode, sheared or not), the read takes their shares out of the measurement by its estimates instead
//! ([`CellShares::known_outside`]): in a patch sheared by a whole lenslet the two outer
//! views' neighbours across every micro-image border lie outside it, and the own-cell rule
//! there cost those views up to 2.2 dB (`docs/results-grid-views.md`). A seeded pixel more
//! than half outside is left out ([`MAX_SEEDED_OUTSIDE_SHARE`]).
//!
//! A patch sheared to a half disparity has every other view half a lenslet off its grid
//! ([`crate::solver::fractional`]): such a view's cell is the mean of two grid positions, so
//! a measurement reads its cells' one or two positions each, at half a cell's share for a
//! half view's (up to 36 entries, not 9: a second footprint kind, the whole case's loops
//! unchanged). A cell whose second position lies past the patch is outside it, and the last
//! grid position of a half view is no measurement. On a textured plane at half a pixel of
//! disparity behind a grid turned 0.3 degrees at 5.04 px this beats whole disparities by 7
//! dB, where reading each half view at the pixel under its cell's centre lost to them
//! (`host-sim/tests/grid.rs`).
//!
//! Against the aligned sensor's band step this costs, per measurement, the sum of the
//! two to nine cells it covers before its dot product with `D5`'s band row and the scatter
//! of its correction back to them, and two patches on the stack (32 KB each for the
//! full-view patch): the step's residuals, and the solve's row sums, both in [`RowSums`]
//! with the patch's `Layout` (4.6 KB), found by its first projection. Keeping the sums took
//! office at pixel k = 3 behind a grid turned 0.3 degrees at 5.04 px from 3.1 to 2.6 s on
//! one thread (the aligned sensor 1.3 s; the output within 2.1e-7 of the division's, the
//! same 39.36 dB); their coverage pass adds each measured band's share alone (not a test of
//! every band), which took it from 4.0 to 3.1 s. Tried
//! and dropped: every footprint's cells without a branch on which neighbours it reaches
//! (nine cells, slower; or the own cell and the neighbour on the centre's side, four, no
//! faster: 2.6 s both). Counted by callgrind on office at 32 x 32 lenslets, pixel k = 3,
//! behind 0.3 degrees / 5.04 px, the DCT: the weights of a weighted ball read from the
//! solve's table as the aligned sensor's step does (not two divisions a measurement a step),
//! the residuals kept in [`RowSums`] (not a patch cleared each step) and the layout with its
//! overhangs built once a solve took the decode from 4.93 to 4.49 G instructions; the
//! aligned sensor's takes 2.72 G. Caching each pixel's footprint for the step's second
//! pass saved 1.7 % more for 22 KB of stack: not kept. The row sums' two passes work on
//! whole 13-band fibres (a 0 / 1 mask of the measured bands, then every band's sum at once),
//! not band by band: the same sums, and the decode from 4.97 to 4.79 G instructions (office
//! 32 x 32, k = 3, the DCT) and a paired median of 0.95 times the time (`farm-bench`, 11
//! pairs, office 64 x 64). Tried and not kept: each footprint's covered cells packed to
//! the front (no test per cell in the steps' loops), 6.5 % more instructions and 1.10 times
//! the time (`farm-bench`); a step that solves `M M^T` by 4 conjugate-gradient steps, which
//! gains noiseless and loses on noisy captures (`docs/design.md`).

use crate::operators::dictionary::Dictionary;
use crate::operators::disparity::HalfViews;
use crate::operators::mode::ModeMatrix;
use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands, Extent};
use crate::solver::ball::Ball;
use crate::solver::projection::{band_bits, dot, measured_weight, project_whole};
use crate::solver::workspace::{CellShares, MAX_SHARE_VIEWS, Measurements, PLACE_UNIT};

/// The patch entries a measurement reads, with their weights: per axis (rows, columns), `N`
/// parts of a pixel index (`pixel = row part + column part`) and their weights (0: none);
/// an entry's weight is the product of its row's and its column's. With whole views
/// (`N = 3`) the parts are the cells before, at and after the pixel's own, each weighted by
/// its share; with half views (`N = 6`) each cell is its one or two grid positions, a half
/// view's two each taking half its share ([`Layout`]).
#[derive(Clone, Copy)]
struct Footprint<const N: usize> {
    rows: ([u16; N], [f32; N]),
    cols: ([u16; N], [f32; N]),
}

impl<const N: usize> Footprint<N> {
    /// `f(entry, weight)` for each entry read.
    #[inline(always)]
    fn each(&self, mut f: impl FnMut(usize, f32)) {
        let ((rp, rw), (cp, cw)) = (&self.rows, &self.cols);
        for (&r, &wr) in rp.iter().zip(rw) {
            if wr <= 0.0 {
                continue;
            }
            for (&c, &wc) in cp.iter().zip(cw) {
                if wc > 0.0 {
                    f(usize::from(r.wrapping_add(c)), wr * wc);
                }
            }
        }
    }

    /// The entries read, each by its weight, summed a whole fibre at a time (`cells` by
    /// patch pixel): every band's sum in the footprint's order.
    #[inline(always)]
    fn gather<C: Bands>(&self, cells: &[C::Per<f32>]) -> C::Per<f32> {
        let mut sum = C::Per::<f32>::splat(0.0);
        self.each(|c, w| {
            if let Some(f) = cells.get(c) {
                for (o, &x) in sum.iter_mut().zip(f.iter()) {
                    *o += w * x;
                }
            }
        });
        sum
    }

    /// `fibre` added to each entry read, by the entry's weight: [`Self::gather`]'s
    /// transpose.
    #[inline(always)]
    fn scatter<C: Bands>(&self, cells: &mut [C::Per<f32>], fibre: &C::Per<f32>) {
        self.each(|c, w| {
            if let Some(f) = cells.get_mut(c) {
                for (o, &x) in f.iter_mut().zip(fibre.iter()) {
                    *o += w * x;
                }
            }
        });
    }
}

/// One axis of the cells a measurement covers: the cells before, at and after the pixel's
/// own, each its part of a pixel index and its share (0: not covered).
type AxisCells = ([u16; 3], [f32; 3]);

/// How a step finds a measurement's footprint: whole views only (`Footprint<3>`, the cells
/// themselves) or with half views (`Footprint<6>`). Two kinds so that the common whole
/// case keeps its nine-entry loops.
trait Cover {
    fn of<S: Shape>(
        layout: &Layout<S>,
        m: &Measurements<S::Values>,
        at: (usize, usize, usize, usize),
        pixel: usize,
    ) -> Self;
}

impl Cover for Footprint<3> {
    #[inline(always)]
    fn of<S: Shape>(
        layout: &Layout<S>,
        m: &Measurements<S::Values>,
        at: (usize, usize, usize, usize),
        pixel: usize,
    ) -> Self {
        let (rows, cols) = layout.cells(m, at, pixel);
        Self { rows, cols }
    }
}

impl Cover for Footprint<6> {
    #[inline(always)]
    fn of<S: Shape>(
        layout: &Layout<S>,
        m: &Measurements<S::Values>,
        at: (usize, usize, usize, usize),
        pixel: usize,
    ) -> Self {
        let (s, t, u, v) = at;
        let (rows, cols) = layout.cells(m, at, pixel);
        let halves = |h: Option<&[bool; 3]>| h.copied().unwrap_or([false; 3]);
        Self {
            rows: split(rows, halves(layout.halves.0.get(s * S::PU + u)), S::PT * S::PU * S::PV),
            cols: split(cols, halves(layout.halves.1.get(t * S::PV + v)), S::PU * S::PV),
        }
    }
}

/// One axis of a footprint with half views: each of the three cells (`parts`, shares)
/// its grid position, or for a half view (`half`) that position and the next (`next` on
/// in the pixel index) at half its share each.
#[inline(always)]
fn split((parts, shares): AxisCells, half: [bool; 3], next: usize) -> ([u16; 6], [f32; 6]) {
    let (mut p, mut w) = ([0u16; 6], [0.0f32; 6]);
    let pairs = p.chunks_exact_mut(2).zip(w.chunks_exact_mut(2));
    for ((pp, ww), ((&part, &share), &h)) in pairs.zip(parts.iter().zip(&shares).zip(&half)) {
        if let ([p0, p1], [w0, w1]) = (pp, ww) {
            (*p0, *w0) = (part, share);
            if h {
                (*p1, *w0, *w1) = (part.wrapping_add(next as u16), 0.5 * share, 0.5 * share);
            }
        }
    }
    (p, w)
}

/// The bands set in `bits`, lowest first.
#[inline(always)]
fn bands(mut bits: u64) -> impl Iterator<Item = usize> {
    core::iter::from_fn(move || {
        (bits != 0).then(|| {
            let b = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            b
        })
    })
}

/// The most lenslet rows times view rows (and columns times view columns) of a patch
/// whose neighbouring cells are looked up in a table; a larger patch's pixels keep every
/// share in their own cells.
pub const MAX_AXIS: usize = 64;

/// No neighbour in the patch, in a [`Layout`] table.
const OUTSIDE: u16 = u16::MAX;

/// A patch's cells on the sensor: for each grid row and view row `(s, u)` (at `s * PU +
/// u`), the row part of the pixel index (`pixel = row part + column part`) of the cells
/// before and after it on the sensor, found through the shear's whole-lenslet shifts
/// ([`OUTSIDE`] beyond the patch); likewise for columns: the lookups cost more than the
/// shares. With it, each place's overhangs ([`overhang`]) per axis, by the place's `i8`
/// (offset by 128): a solve builds its layout once ([`RowSums`]), and a lookup costs less
/// than the arithmetic for each pixel, axis and pass.
///
/// In a patch sheared to a half disparity every other view is half a lenslet off its grid
/// ([`HalfViews`]): such a view's cell at grid position `s` is the mean of positions `s`
/// and `s + 1` ([`crate::solver::fractional`]), so a cell whose next position lies past
/// the patch is outside it, and a pixel whose own cell is (the last position of a half
/// view) is no measurement (`gone`).
struct Layout<S: Shape> {
    shape: core::marker::PhantomData<S>,
    rows: [[u16; 2]; MAX_AXIS],
    cols: [[u16; 2]; MAX_AXIS],
    /// Per axis index, whether the cells before, at and after it are half views; whether
    /// any is; whether the own cell lies past the patch.
    halves: ([[bool; 3]; MAX_AXIS], [[bool; 3]; MAX_AXIS]),
    any_half: bool,
    gone: ([bool; MAX_AXIS], [bool; MAX_AXIS]),
    /// Whether a share outside the patch is known (taken out of the measurement) rather
    /// than given to the pixel's own cell ([`CellShares::known_outside`]).
    known: bool,
    /// One over a pixel's side in cells, rows and columns; the side over 2.
    inv: (f32, f32),
    half: (f32, f32),
    /// [`overhang`] of each place (rows, columns), at index `place + 128`.
    over: ([[f32; 2]; PLACES], [[f32; 2]; PLACES]),
}

/// The values of a place (an `i8`).
const PLACES: usize = 256;

/// A place in cells off its cell's centre.
#[inline(always)]
fn place(x: i8) -> f32 {
    f32::from(x) * (1.0 / PLACE_UNIT)
}

impl<S: Shape> Layout<S> {
    /// No patch yet ([`RowSums::new`]): every neighbour outside, no overhang. Built in code,
    /// not a constant: as a `const` its 4.6 KB were copied from flash.
    fn empty() -> Self {
        Self {
            shape: core::marker::PhantomData,
            rows: [[OUTSIDE; 2]; MAX_AXIS],
            cols: [[OUTSIDE; 2]; MAX_AXIS],
            halves: ([[false; 3]; MAX_AXIS], [[false; 3]; MAX_AXIS]),
            any_half: false,
            gone: ([false; MAX_AXIS], [false; MAX_AXIS]),
            known: false,
            inv: (1.0, 1.0),
            half: (0.5, 0.5),
            over: ([[0.0; 2]; PLACES], [[0.0; 2]; PLACES]),
        }
    }

    fn new(shares: &CellShares, half: HalfViews) -> Self {
        let mut layout = Self::empty();
        layout.fill(shares, half);
        layout
    }

    /// This layout made the one of a patch whose pixels share cells as `shares` says, its
    /// views half off the grid as `halves` says, in place (a solve's [`RowSums`] holds it:
    /// no second copy on the stack).
    fn fill(&mut self, shares: &CellShares, halves: HalfViews) {
        self.inv = (1.0 / shares.width.0, 1.0 / shares.width.1);
        self.half = (0.5 * shares.width.0, 0.5 * shares.width.1);
        let (half, inv) = (self.half, self.inv);
        for (i, (r, c)) in self.over.0.iter_mut().zip(self.over.1.iter_mut()).enumerate() {
            let x = place((i as i16 - 128) as i8);
            let (rb, ra) = overhang(x, half.0, inv.0);
            let (cb, ca) = overhang(x, half.1, inv.1);
            (*r, *c) = ([rb, ra], [cb, ca]);
        }
        let part = |x: Option<usize>| x.and_then(|x| u16::try_from(x).ok()).unwrap_or(OUTSIDE);
        self.any_half = !halves.is_none();
        self.known = shares.known_outside;
        // A cell of a half view needs the grid position after its own too.
        let whole = |(s, u): (usize, usize), len: usize, is_half: &dyn Fn(usize) -> bool| !is_half(u) || s + 1 < len;
        let row_half = |u: usize| halves.row(u);
        let col_half = |v: usize| halves.col(v);
        let axis = (&mut self.rows, &mut self.halves.0, &mut self.gone.0);
        for (i, ((o, h), g)) in axis.0.iter_mut().zip(axis.1.iter_mut()).zip(axis.2.iter_mut()).enumerate() {
            (*o, *h, *g) = ([OUTSIDE; 2], [false; 3], false);
            if i >= S::PS * S::PU {
                continue;
            }
            let (s, u) = (i / S::PU, i % S::PU);
            (h[1], *g) = (row_half(u), !whole((s, u), S::PS, &row_half));
            let p = (s as isize + shares.shift.0.get(u).copied().unwrap_or(0) as isize) * S::PU as isize + u as isize;
            for (d, (x, hx)) in [-1isize, 1].into_iter().zip(o.iter_mut().zip([0usize, 2])) {
                let cell = along(p + d, S::PU, S::PS, &shares.shift.0).filter(|&c| whole(c, S::PS, &row_half));
                *x = part(cell.map(|(s, u)| (s * S::PT * S::PU + u) * S::PV));
                if let (Some((_, u)), Some(f)) = (cell, h.get_mut(hx)) {
                    *f = row_half(u);
                }
            }
        }
        let axis = (&mut self.cols, &mut self.halves.1, &mut self.gone.1);
        for (i, ((o, h), g)) in axis.0.iter_mut().zip(axis.1.iter_mut()).zip(axis.2.iter_mut()).enumerate() {
            (*o, *h, *g) = ([OUTSIDE; 2], [false; 3], false);
            if i >= S::PT * S::PV {
                continue;
            }
            let (t, v) = (i / S::PV, i % S::PV);
            (h[1], *g) = (col_half(v), !whole((t, v), S::PT, &col_half));
            let q = (t as isize + shares.shift.1.get(v).copied().unwrap_or(0) as isize) * S::PV as isize + v as isize;
            for (d, (x, hx)) in [-1isize, 1].into_iter().zip(o.iter_mut().zip([0usize, 2])) {
                let cell = along(q + d, S::PV, S::PT, &shares.shift.1).filter(|&c| whole(c, S::PT, &col_half));
                *x = part(cell.map(|(t, v)| t * S::PU * S::PV + v));
                if let (Some((_, v)), Some(f)) = (cell, h.get_mut(hx)) {
                    *f = col_half(v);
                }
            }
        }
    }

    /// Whether patch pixel `(s, t, u, v)` can be a measurement: its own cell lies in the
    /// patch (not the last grid position of a half view).
    #[inline(always)]
    fn measures(&self, (s, t, u, v): (usize, usize, usize, usize)) -> bool {
        !self.gone.0.get(s * S::PU + u).copied().unwrap_or(true)
            && !self.gone.1.get(t * S::PV + v).copied().unwrap_or(true)
    }

    /// The cells the measurements of patch pixel `(s, t, u, v)` (index `pixel`) cover, per
    /// axis: their parts of the pixel index and their shares.
    #[inline(always)]
    fn cells(
        &self,
        m: &Measurements<S::Values>,
        (s, t, u, v): (usize, usize, usize, usize),
        pixel: usize,
    ) -> (AxisCells, AxisCells) {
        let [pr, pc] = m.place.get(pixel).copied().unwrap_or([0, 0]);
        let over =
            |table: &[[f32; 2]; PLACES], x: i8| table.get((i16::from(x) + 128) as usize).copied().unwrap_or([0.0; 2]);
        let (before, after) = match self.rows.get(s * S::PU + u) {
            Some(&[b, a]) => (b, a),
            None => (OUTSIDE, OUTSIDE),
        };
        let row_parts = [before, ((s * S::PT * S::PU + u) * S::PV) as u16, after];
        let (before, after) = match self.cols.get(t * S::PV + v) {
            Some(&[b, a]) => (b, a),
            None => (OUTSIDE, OUTSIDE),
        };
        let col_parts = [before, (t * S::PU * S::PV + v) as u16, after];
        (axis(over(&self.over.0, pr), row_parts, self.known), axis(over(&self.over.1, pc), col_parts, self.known))
    }
}

/// The most of a pixel's square a sheared patch keeps outside itself, at two snapshots or
/// more: a pixel past it is not the patch's measurement ([`Reach`]).
///
/// A share of a cell outside the patch goes to the pixel's own cell (module docs). On an
/// unsheared patch that happens at the patch's rim only. A patch sheared by whole lenslets holds neighbouring views
/// at neighbouring grid positions (`shift` differs by `d` from view to view), so every view
/// of its rim lenslets reaches outside, and across a micro-image border (view `U - 1` of
/// sensor lenslet `L` beside view 0 of `L + 1`) the neighbour is `1 - (U - 1) d` grid
/// positions away: outside for `d = 1` (and for `d = -1` from the rim's three lenslets).
/// The value given for it is then that of a point about five lenslets away.
/// Measured (`docs/results-grid-shear.md`, `scripts/grid-shear.sh`: calibrated, noisy
/// sensors behind grids of 0.3 degrees / 5.04 px and 1 degree / 5.1 px, pixel k = 3):
/// leaving out the pixels more than this outside raised every decode. The limit was picked
/// on office alone: 0.05 lowered a decode by 0.5 dB (it leaves out more measurements than
/// model error), 0.2 and 0.3 were within 0.11 dB of 0.25, 0.4 0.5 to 0.6 dB below. On unsheared
/// patches the rule moved office's decodes by 0.01 dB, so they keep every pixel (their
/// decodes stay as they were). At k = 1, short of measurements more than of a fit, it lost
/// up to 2.2 dB (and won up to 1.5), so one snapshot keeps every pixel.
pub const MAX_OUTSIDE_SHARE: f32 = 0.25;

/// The most of a pixel's square a seeded patch keeps outside itself
/// ([`CellShares::known_outside`]): a pixel past it is more the seeds' estimate of the cells
/// outside than a measurement of the patch, and is left out, sheared or not, at any number
/// of snapshots ([`Reach`]).
///
/// A seeded read takes the outside cells' shares out of a measurement by the seeds (the
/// disjoint grid's decode), so what is left carries the seeds' error times those shares,
/// over a part of the pixel inside of less than a half. Measured on 2026-12-01
/// (`docs/results-grid-known.md`'s calibrated captures, the default decode): picked on 7 of
/// its 28 decodes (0.25 lowered 6 of them, by up to 0.36 dB; 0.4 raised 6 by at most 0.17
/// and lowered one by 0.05; 0.5 and 0.6 raised all 7, by at most 0.12 and 0.10 dB); on the
/// other 21, 0.5 raised 20 by 0.01 to 0.09 dB and lowered one by 0.04 (dino, k = 1, 0.3
/// degrees); all 28 in `docs/results-grid-seeded.md`. A small gain: the loss behind a grid
/// is elsewhere (`docs/results-grid-target.md`).
pub const MAX_SEEDED_OUTSIDE_SHARE: f32 = 0.5;

/// How much of each pixel's square lies over cells outside a patch: built once a patch from
/// its shares.
pub struct Reach<S: Shape>(Layout<S>);

impl<S: Shape> Reach<S> {
    /// The reach of a patch whose pixels share cells as `shares` says, its views half off the
    /// grid as `half` says.
    pub fn new(shares: &CellShares, half: HalfViews) -> Self {
        Self(Layout::new(shares, half))
    }

    /// The share of patch pixel `(s, t, u, v)`'s square, its centre `place` cells off its
    /// cell's (rows, columns), that covers cells outside the patch (given to its own cell
    /// by the projection): the footprint's own overhangs (`overhang`), per axis, the two
    /// axes' inside parts multiplied.
    pub fn outside(&self, (s, t, u, v): (usize, usize, usize, usize), place: (f32, f32)) -> f32 {
        let l = &self.0;
        let side = |delta: f32, half: f32, inv: f32, nb: Option<&[u16; 2]>| {
            let [b, a] = nb.copied().unwrap_or([OUTSIDE, OUTSIDE]);
            let (before, after) = overhang(delta, half, inv);
            (if b == OUTSIDE { before } else { 0.0 }) + (if a == OUTSIDE { after } else { 0.0 })
        };
        let r = side(place.0, l.half.0, l.inv.0, l.rows.get(s * S::PU + u));
        let c = side(place.1, l.half.1, l.inv.1, l.cols.get(t * S::PV + v));
        // Inside along both axes: (1 - r)(1 - c).
        r + c - r * c
    }
}

impl<S: Shape> Reach<S> {
    /// `f((dr, dc), share)` for each cell outside the patch that patch pixel `(s, t, u, v)`'s
    /// square covers (its centre `place` cells off its cell's), `(dr, dc)` the cell's offset
    /// on the sensor from the pixel's own (each -1, 0 or 1), `share` the part of the square
    /// over it: what [`CellShares::known_outside`] takes out of the measurement.
    pub fn outside_cells(
        &self,
        (s, t, u, v): (usize, usize, usize, usize),
        place: (f32, f32),
        mut f: impl FnMut((isize, isize), f32),
    ) {
        let l = &self.0;
        let axis = |delta: f32, half: f32, inv: f32, nb: Option<&[u16; 2]>| {
            let [b, a] = nb.copied().unwrap_or([OUTSIDE, OUTSIDE]);
            let (before, after) = overhang(delta, half, inv);
            [(before, b == OUTSIDE), (1.0 - before - after, false), (after, a == OUTSIDE)]
        };
        let r = axis(place.0, l.half.0, l.inv.0, l.rows.get(s * S::PU + u));
        let c = axis(place.1, l.half.1, l.inv.1, l.cols.get(t * S::PV + v));
        for (dr, &(wr, outr)) in (-1isize..=1).zip(&r) {
            for (dc, &(wc, outc)) in (-1isize..=1).zip(&c) {
                if (outr || outc) && wr * wc > 0.0 {
                    f((dr, dc), wr * wc);
                }
            }
        }
    }
}

/// Grid position and view of sensor cell `p` along an axis of `views` views and `len`
/// lenslets with per-view shifts `shift`; `None` outside the patch.
#[inline(always)]
fn along(p: isize, views: usize, len: usize, shift: &[i8; MAX_SHARE_VIEWS]) -> Option<(usize, usize)> {
    let n = views as isize;
    let (lenslet, view) = (p.checked_div_euclid(n)?, p.checked_rem_euclid(n)?);
    let view = usize::try_from(view).ok()?;
    let s = lenslet - *shift.get(view)? as isize;
    usize::try_from(s).ok().filter(|&s| s < len).map(|s| (s, view))
}

/// One axis of a footprint: the shares of a pixel whose square overhangs its own cell by
/// `[before, after]` ([`overhang`]), in the cells before, at and after its own (`parts`,
/// [`OUTSIDE`] beyond the patch: that share goes to its own cell). A box against unit
/// cells: `half <= 1` and `|delta| <= 1/2`, so it reaches no further.
#[inline(always)]
fn axis([mut before, mut after]: [f32; 2], parts: [u16; 3], known: bool) -> AxisCells {
    let mut own = 1.0 - before - after;
    if parts[0] == OUTSIDE {
        own += if known { 0.0 } else { before };
        before = 0.0;
    }
    if parts[2] == OUTSIDE {
        own += if known { 0.0 } else { after };
        after = 0.0;
    }
    (parts, [before, own, after])
}

/// The shares of a pixel `2 half` cells wide (`inv` its inverse), its centre `delta` cells
/// off its own cell's centre, over the cells before and after its own along one axis.
#[inline(always)]
fn overhang(delta: f32, half: f32, inv: f32) -> (f32, f32) {
    let (a, b) = (delta - half, delta + half);
    let before = if a < -0.5 { (-0.5 - a) * inv } else { 0.0 };
    let after = if b > 0.5 { (b - 0.5) * inv } else { 0.0 };
    (before, after)
}

/// Each measurement's step scale behind a lenslet grid: one over its row of `M M^T` summed
/// (module docs; 0 for a measurement that covers no cell), by patch entry. The sums depend on
/// which entries are measured and where their pixels sit, not on the iterate: a solve's
/// first projection finds them and its other projections reuse them (half of a step's
/// passes). A fresh one for each solve: the measurements must not change while it is kept.
///
/// It also holds the step's residuals (`res`), by patch entry, so a step does not clear a
/// patch of them: each step writes every measured entry before it reads it, and the
/// measurements are the solve's throughout. Cleared each step, they were 4 % of a decode's
/// instructions behind a grid (office 32 x 32 lenslets, pixel k = 3, the DCT: callgrind).
///
/// And the patch's `Layout` (its cells' neighbours and overhangs), built by the same
/// first projection.
pub struct RowSums<S: Shape> {
    inv: PerValue<S, f32>,
    res: PerValue<S, f32>,
    layout: Layout<S>,
    ready: bool,
}

impl<S: Shape> RowSums<S> {
    /// Not yet found: the next projection finds them.
    pub fn new() -> Self {
        Self {
            inv: <S::Values as Extent>::ZEROS,
            res: <S::Values as Extent>::ZEROS,
            layout: Layout::empty(),
            ready: false,
        }
    }
}

impl<S: Shape> Default for RowSums<S> {
    fn default() -> Self {
        Self::new()
    }
}

/// Moves the coefficients `coeffs` (of `dict`) onto the measurements `m`, whose pixels
/// share view cells ([`Measurements::shares`]; the selection's projection without them):
/// exactly, or onto the noise [`Ball`]. `scratch` is clobbered. Returns the residual norm
/// before the move. [`crate::solver::projection::project_coefficients`] behind a lenslet
/// grid. `rows` is found by the first
/// projection of a solve and kept for its others ([`RowSums`]). A weighted ball's weights
/// are read from `weights` when given ([`crate::solver::projection::weigh`] of the same
/// measurements and ball), else computed (two divisions a measurement): the same sums.
pub fn project_shares<S: Shape>(
    dict: &Dictionary<S>,
    coeffs: &mut PerValue<S, f32>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    ball: &Ball,
    rows: &mut RowSums<S>,
    weights: Option<&PerValue<S, f32>>,
) -> f32 {
    // The pixel modes' synthesis, every slice back in place (the half-pixel projection's
    // frame, `crate::solver::fractional`): each pixel's band coefficients.
    let mut step = |scratch: &mut PerValue<S, f32>| match &m.shares {
        Some(shares) => share_step::<S>(&dict.d.m5, scratch, m, (ball, weights), shares, rows),
        None => (0.0, 0.0),
    };
    project_whole(dict, coeffs, scratch, ball, &mut step)
}

/// Calls `f((s, t, u, v), pixel, band bits)` for every patch pixel with a measurement (one
/// whose own cell lies in the patch, `layout`).
#[inline(always)]
fn each_measured<S: Shape>(
    m: &Measurements<S::Values>,
    layout: &Layout<S>,
    mut f: impl FnMut((usize, usize, usize, usize), usize, u64),
) {
    for s in 0..S::PS {
        for t in 0..S::PT {
            for u in 0..S::PU {
                for v in 0..S::PV {
                    if layout.any_half && !layout.measures((s, t, u, v)) {
                        continue;
                    }
                    let pixel = ((s * S::PT + t) * S::PU + u) * S::PV + v;
                    let Some(flags) = m.measured.get(pixel * S::B..pixel * S::B + S::B) else { continue };
                    let bits = band_bits(flags);
                    if bits != 0 {
                        f((s, t, u, v), pixel, bits);
                    }
                }
            }
        }
    }
}

/// The band step: the pixels' band coefficients in `scratch` become the correction's
/// `M^T W^-1 r`, `W` each measurement's row of `M M^T` summed (module docs). Returns the
/// sums of squared residuals, plain and over their variances (weighted balls).
///
/// Two passes over the measurements: residuals (from the coefficients), then with the
/// coefficients no longer needed the correction in `scratch`. Between them, once a solve,
/// `rows` (each band's coverage of each cell in `scratch`, the shares its measurements put
/// there, then each measurement's row sum).
#[inline(never)]
fn share_step<S: Shape>(
    m5: &ModeMatrix<S::Bands>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    (ball, weights): (&Ball, Option<&PerValue<S, f32>>),
    shares: &CellShares,
    rows: &mut RowSums<S>,
) -> (f32, f32) {
    if !rows.ready {
        // The layout and the row sums, once a solve (the residuals' buffer is the sums'
        // scratch: every measured entry is written below before it is read).
        rows.layout.fill(shares, m.half);
        let fibres = S::Bands::chunks_mut(rows.res.as_mut());
        if rows.layout.any_half {
            row_sums::<S, 6>(fibres, m, &rows.layout, &mut rows.inv);
        } else {
            row_sums::<S, 3>(fibres, m, &rows.layout, &mut rows.inv);
        }
        rows.ready = true;
    }
    if rows.layout.any_half {
        step_with::<S, 6>(m5, scratch, m, (ball, weights), rows)
    } else {
        step_with::<S, 3>(m5, scratch, m, (ball, weights), rows)
    }
}

/// [`share_step`] once its layout and row sums are found, with footprints of `N` entries an
/// axis.
#[inline(always)]
fn step_with<S: Shape, const N: usize>(
    m5: &ModeMatrix<S::Bands>,
    scratch: &mut PerValue<S, f32>,
    m: &Measurements<S::Values>,
    (ball, weights): (&Ball, Option<&PerValue<S, f32>>),
    rows: &mut RowSums<S>,
) -> (f32, f32)
where
    Footprint<N>: Cover,
{
    let layout = &rows.layout;
    let fibres = S::Bands::chunks_mut(scratch.as_mut());
    // Each measurement's residual, in its patch entry.
    let res = &mut rows.res;
    let (mut r2, mut w2) = (0.0f32, 0.0f32);
    let weighted = ball.is_weighted();
    each_measured::<S>(m, layout, |at, pixel, bits| {
        let sum = Footprint::<N>::of(layout, m, at, pixel).gather::<S::Bands>(fibres);
        for b in bands(bits) {
            let i = pixel * S::B + b;
            let (Some(row), Some(&y), Some(r)) = (m5.get(b), m.values.get(i), res.get_mut(i)) else { continue };
            *r = y - dot(row.as_ref(), sum.as_ref());
            r2 += *r * *r;
            if weighted {
                w2 += *r * *r * measured_weight::<S>(weights, i, ball, y, m.gains.get(b));
            }
        }
    });
    let res = &rows.res;
    // The correction: each measurement's step (its residual over its row sum) times its
    // band's row of `D5`, spread over the cells it covers by their shares.
    for f in fibres.iter_mut() {
        *f = <PerBand<S, f32>>::splat(0.0);
    }
    each_measured::<S>(m, layout, |at, pixel, bits| {
        let mut correction = <PerBand<S, f32>>::splat(0.0);
        for b in bands(bits) {
            let i = pixel * S::B + b;
            let (Some(row), Some(&r), Some(&inv)) = (m5.get(b), res.get(i), rows.inv.get(i)) else { continue };
            let z = r * inv;
            for (o, &w) in correction.iter_mut().zip(row.iter()) {
                *o += z * w;
            }
        }
        Footprint::<N>::of(layout, m, at, pixel).scatter::<S::Bands>(fibres, &correction);
    });
    (r2, w2)
}

/// One over each measurement's row of `M M^T` summed, into `inv` by patch entry (0 where
/// nothing is covered): each band's coverage of each cell first (in `fibres`, clobbered),
/// then each measurement's shares of its cells' coverage.
#[inline(never)]
fn row_sums<S: Shape, const N: usize>(
    fibres: &mut [PerBand<S, f32>],
    m: &Measurements<S::Values>,
    layout: &Layout<S>,
    inv: &mut PerValue<S, f32>,
) where
    Footprint<N>: Cover,
{
    for f in fibres.iter_mut() {
        *f = <PerBand<S, f32>>::splat(0.0);
    }
    each_measured::<S>(m, layout, |at, pixel, bits| {
        // The pixel's measured bands as a 0 / 1 mask, so each cell's coverage is one
        // whole-fibre multiply-add (the unmeasured bands add `w * 0`, which leaves them as
        // they are): band by band it was a scalar loop a cell.
        let mut measured = <PerBand<S, f32>>::splat(0.0);
        for b in bands(bits) {
            if let Some(x) = measured.get_mut(b) {
                *x = 1.0;
            }
        }
        Footprint::<N>::of(layout, m, at, pixel).scatter::<S::Bands>(fibres, &measured);
    });
    each_measured::<S>(m, layout, |at, pixel, bits| {
        // Every band's row sum at once, then the measured bands' read off.
        let rows = Footprint::<N>::of(layout, m, at, pixel).gather::<S::Bands>(fibres);
        for b in bands(bits) {
            let row = rows.get(b).copied().unwrap_or(0.0);
            if let Some(x) = inv.get_mut(pixel * S::B + b) {
                *x = if row > f32::MIN_POSITIVE { 1.0 / row } else { 0.0 };
            }
        }
    });
}

/// A decoded patch as its pixels measured it: each measured entry becomes the shares of
/// the cells its pixel covers (the model's prediction of the measurement, for the
/// held-out error estimate). Unmeasured entries are left as they are; `scratch` is
/// clobbered (a copy of the patch).
pub fn to_sensor<S: Shape>(m: &Measurements<S::Values>, patch: &mut PerValue<S, f32>, scratch: &mut PerValue<S, f32>) {
    let Some(shares) = &m.shares else { return };
    let layout = Layout::<S>::new(shares, m.half);
    scratch.copy_from_slice(patch.as_ref());
    if layout.any_half {
        predict::<S, 6>(m, &layout, patch, scratch);
    } else {
        predict::<S, 3>(m, &layout, patch, scratch);
    }
}

/// [`to_sensor`]'s measured entries from the patch's copy `cells`, footprints of `N`
/// entries an axis.
fn predict<S: Shape, const N: usize>(
    m: &Measurements<S::Values>,
    layout: &Layout<S>,
    patch: &mut PerValue<S, f32>,
    cells: &PerValue<S, f32>,
) where
    Footprint<N>: Cover,
{
    let cells = S::Bands::chunks(cells.as_ref());
    each_measured::<S>(m, layout, |at, pixel, bits| {
        let sums = Footprint::<N>::of(layout, m, at, pixel).gather::<S::Bands>(cells);
        for b in bands(bits) {
            if let (Some(y), Some(&x)) = (patch.get_mut(pixel * S::B + b), sums.get(b)) {
                *y = x;
            }
        }
    });
}
