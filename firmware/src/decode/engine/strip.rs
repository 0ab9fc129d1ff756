//! The rows an overlapped decode holds ([`Strip`]), in one caller-owned buffer: a ring of
//! `slots` lenslet rows over a run of the sensor's columns, each slot the row's weighted
//! sums, its weights (one a pixel) and, where the decode is seeded, the disjoint grid's
//! finished values of the row (the seeds of the shifted patches that reach it).
//!
//! Lenslet row `y` is in slot `y % slots` (its seeds in `y % seed_slots`: fewer rows are
//! final in the disjoint grid and unfinished than are held). Which rows are held and when they are final is
//! the [`Schedule`]'s; the strip adds tiles' sums ([`Strip::join`]) or single patches
//! ([`StripSink`]) to its rows, makes seeds and finishes rows as the schedule says
//! ([`Strip::advance`]), and reads seeds ([`Seeds`]).
//!
//! A strip narrower than the sensor (a band of its columns) holds the columns `held` and
//! puts the columns `out` (inside them): the band's own columns, and beside them those the
//! band's seeds are read from ([`crate::decode::engine::band`]).

use core::marker::PhantomData;
use core::num::NonZeroUsize;
use core::ops::Range;

use crate::decode::engine::error::EngineError;
use crate::decode::engine::plan::Planned;
use crate::decode::engine::rows::{Fill, RowLayout, RowSink, finish};
use crate::decode::engine::schedule::Schedule;
use crate::decode::engine::tile_sums::{TileSums, pixel_at, weigh};
use crate::decode::engine::window::Window;
use crate::decode::tile::{PatchOrigin, PatchReport, PatchSeed, PatchSink};
use crate::operators::shape::{PerBand, PerValue, Shape};
use crate::sensor::extent::{Array, Bands};
use crate::solver::sl0::SolveError;

/// What a strip holds: config.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StripShape {
    /// Views of a lenslet (rows, cols).
    pub views: (usize, usize),
    /// Lenslet rows of the sensor.
    pub frame_rows: usize,
    /// Lenslet columns of the sensor held.
    pub held: Range<usize>,
    /// Lenslet columns put to the sink (inside `held`).
    pub out: Range<usize>,
    /// Lenslet rows of sums held at once.
    pub slots: usize,
    /// Lenslet rows of seeds held at once (from the first unfinished).
    pub seed_slots: usize,
    /// Whether the rows keep the disjoint grid's finished values (the seeds).
    pub seeded: bool,
}

impl StripShape {
    /// The layout of a held row.
    pub fn layout(&self) -> RowLayout {
        RowLayout { views: self.views, cols: self.held.len() }
    }

    /// `f32`s of the strip's buffer with `B` bands.
    pub fn buffer_len<C: Bands>(&self) -> usize {
        let pixels = self.layout().pixels();
        self.slots * pixels * (C::D + 1) + if self.seeded { self.seed_slots * pixels * C::D } else { 0 }
    }
}

/// The held rows of an overlapped decode: see the module.
pub struct Strip<'s, C: Bands> {
    bands: PhantomData<C>,
    /// The slots' sums and weights: `slots x (pixels x B + pixels)`.
    sums: &'s mut [f32],
    /// The seeds' slots: `seed_slots x pixels x B` (empty unless seeded).
    seeds: &'s mut [f32],
    ring: Ring,
    /// The sensor's range of decoded values.
    range: (f32, f32),
    window: Window,
}

/// Where a strip's rows are: what [`Strip`], [`Seeds`] and [`StripSink`] share.
#[derive(Clone, Debug)]
struct Ring {
    shape: StripShape,
    /// `shape.slots` and `shape.seed_slots`, checked.
    slots: NonZeroUsize,
    seed_slots: NonZeroUsize,
    layout: RowLayout,
    /// Rows below are finished.
    first: usize,
}

impl Ring {
    /// Row `y`'s slot, if held.
    fn slot(&self, y: usize) -> Option<usize> {
        (y >= self.first && y < self.first + self.slots.get()).then(|| y % self.slots)
    }

    /// Row `y`'s seed slot, if held.
    fn seed_slot(&self, y: usize) -> Option<usize> {
        (y >= self.first && y < self.first + self.seed_slots.get()).then(|| y % self.seed_slots)
    }
}

impl<'s, C: Bands> Strip<'s, C> {
    /// A strip of `shape` on `buf` (zeroed), finishing values into `range` and weighing
    /// estimates by `window`.
    ///
    /// # Errors
    /// [`EngineError::Strip`] when `buf` is shorter than [`StripShape::buffer_len`], `out` is
    /// not inside `held`, or there is no slot or no view.
    pub fn new(buf: &'s mut [f32], shape: StripShape, range: (f32, f32), window: Window) -> Result<Self, EngineError> {
        Self::checked(buf, shape, range, window).ok_or(EngineError::Strip)
    }

    fn checked(buf: &'s mut [f32], shape: StripShape, range: (f32, f32), window: Window) -> Option<Self> {
        let ok = shape.slots > 0
            && shape.views.0 > 0
            && shape.views.1 > 0
            && !shape.out.is_empty()
            && shape.held.start <= shape.out.start
            && shape.out.end <= shape.held.end;
        let slots = NonZeroUsize::new(shape.slots)?;
        let seed_slots = NonZeroUsize::new(shape.seed_slots)?;
        let buf = buf.get_mut(..shape.buffer_len::<C>()).filter(|_| ok)?;
        buf.fill(0.0);
        let layout = shape.layout();
        let (sums, seeds) = buf.split_at_mut_checked(shape.slots * layout.pixels() * (C::D + 1))?;
        Some(Self {
            bands: PhantomData,
            sums,
            seeds,
            ring: Ring { shape, slots, seed_slots, layout, first: 0 },
            range,
            window,
        })
    }

    /// What the strip holds.
    pub fn shape(&self) -> &StripShape {
        &self.ring.shape
    }

    /// Row `y`'s slot as its sums, weights and seeds (empty unless seeded); `None` outside
    /// the rows held.
    fn slot(&mut self, y: usize) -> Option<(&mut [f32], &mut [f32], &mut [f32])> {
        slot_parts::<C>(&self.ring, self.sums, self.seeds, y)
    }

    /// Adds a tile's sums into the rows they reach: per lenslet row and view, the run of
    /// the tile's columns inside the held ones, a slice onto a slice.
    pub fn join(&mut self, sums: &TileSums<'_, C>) {
        let tile = sums.tile;
        let (extent_rows, extent_cols) = sums.extent();
        // The sums' first column on the sensor, and the run `t0..t1` of them held.
        let left = usize::from(tile.lenslet_col) as isize - sums.halo as isize;
        let (h0, h1) = (self.ring.shape.held.start as isize, self.ring.shape.held.end as isize);
        let t0 = (h0 - left).clamp(0, extent_cols as isize) as usize;
        let t1 = (h1 - left).clamp(0, extent_cols as isize) as usize;
        if t0 >= t1 {
            return;
        }
        let (x0, len) = ((left + t0 as isize - h0) as usize, t1 - t0);
        let (views, layout) = (self.ring.shape.views, self.ring.layout);
        for s in 0..extent_rows {
            let Some(r) = (usize::from(tile.lenslet_row) + s).checked_sub(sums.halo) else { continue };
            if r >= self.ring.shape.frame_rows {
                continue;
            }
            let Some((row, weights, _)) = self.slot(r) else { continue };
            for u in 0..views.0 {
                for v in 0..views.1 {
                    let (src, dst) = (sums.pixel(s, t0, u, v), layout.pixel(u, v, x0));
                    let (Some(d), Some(x)) =
                        (row.get_mut(dst * C::D..(dst + len) * C::D), sums.sum.get(src * C::D..(src + len) * C::D))
                    else {
                        continue;
                    };
                    for (d, &x) in d.iter_mut().zip(x.iter()) {
                        *d += x;
                    }
                    let (Some(d), Some(x)) = (weights.get_mut(dst..dst + len), sums.weight.get(src..src + len)) else {
                        continue;
                    };
                    for (d, &x) in d.iter_mut().zip(x.iter()) {
                        *d += x;
                    }
                }
            }
        }
    }

    /// The disjoint grid's finished values of row `y`, its seeds (what finishing would put
    /// there, the sums left as they are); the fills counted in `fill`.
    fn make_seeds(&mut self, y: usize, fill: &mut Fill) {
        let (layout, range) = (self.ring.layout, self.range);
        if let Some((sums, weights, seeds)) = self.slot(y)
            && seeds.len() == sums.len()
        {
            seeds.copy_from_slice(sums.as_ref());
            finish::<C>(seeds, weights, layout, range, fill);
        }
    }

    /// Finishes row `y` ([`finish`]), puts its `out` columns to `sink` and clears its slot.
    fn finish_row<K: RowSink + ?Sized>(&mut self, y: usize, sink: &mut K, fill: &mut Fill) -> Result<(), K::Error> {
        let (layout, range) = (self.ring.layout, self.range);
        let (held, out) = (self.ring.shape.held.clone(), self.ring.shape.out.clone());
        let views = layout.views.0 * layout.views.1;
        let sent = match self.slot(y) {
            Some((sums, weights, _)) => {
                finish::<C>(sums, weights, layout, range, fill);
                // The `out` columns of each view, moved to the front (a run never moves past
                // its own start).
                let (o0, width) = (out.start.saturating_sub(held.start), out.len());
                if width < layout.cols {
                    for p in 0..views {
                        let (from, to) = ((p * layout.cols + o0) * C::D, p * width * C::D);
                        for k in 0..width * C::D {
                            if let Some(&x) = sums.get(from + k)
                                && let Some(d) = sums.get_mut(to + k)
                            {
                                *d = x;
                            }
                        }
                    }
                }
                let r = match sums.get(..views * width * C::D) {
                    Some(row) => sink.row(y as u16, out.start as u16, row),
                    None => Ok(()),
                };
                sums.fill(0.0);
                weights.fill(0.0);
                r
            }
            None => Ok(()),
        };
        self.ring.first = y + 1;
        sent
    }

    /// After a batch is added: advances `schedule`, makes the seeds of the rows it made final
    /// in the disjoint grid (their fills counted in `unused`) and finishes and puts the rows
    /// it finished (counted in `fill`).
    ///
    /// # Errors
    /// The sink's: the rows put before stay put.
    pub fn advance<D, S, K>(
        &mut self,
        schedule: &mut Schedule<D, S>,
        sink: &mut K,
        fill: &mut Fill,
        unused: &mut Fill,
    ) -> Result<(), K::Error>
    where
        D: Iterator<Item = Planned> + Clone,
        S: Iterator<Item = Planned> + Clone,
        K: RowSink + ?Sized,
    {
        let a = schedule.advance();
        if self.ring.shape.seeded {
            for y in a.seeds {
                self.make_seeds(y, unused);
            }
        }
        for y in a.finished {
            self.finish_row(y, sink, fill)?;
        }
        Ok(())
    }

    /// The seeds held, to read.
    pub fn seeds(&self) -> Seeds<'_, C> {
        Seeds { bands: PhantomData, seeds: self.seeds, ring: &self.ring }
    }

    /// A sink that adds each accepted patch straight into the rows (by [`weigh`], in the
    /// patch's order; a device's way, without a tile's buffer), and the seeds beside it.
    pub fn sink<S: Shape<Bands = C>>(&mut self) -> (StripSink<'_, S>, Seeds<'_, C>) {
        let sink = StripSink { shape: PhantomData, sums: self.sums, ring: &self.ring, window: self.window };
        (sink, Seeds { bands: PhantomData, seeds: self.seeds, ring: &self.ring })
    }
}

/// Row `y`'s slot of `ring` in `sums` and `seeds` as its sums, weights and seeds.
fn slot_parts<'a, C: Bands>(
    ring: &Ring,
    sums: &'a mut [f32],
    seeds: &'a mut [f32],
    y: usize,
) -> Option<(&'a mut [f32], &'a mut [f32], &'a mut [f32])> {
    let i = ring.slot(y)?;
    let pixels = ring.layout.pixels();
    let slot = sums.get_mut(i * pixels * (C::D + 1)..(i + 1) * pixels * (C::D + 1))?;
    let (sums, weights) = slot.split_at_mut_checked(pixels * C::D)?;
    let seeds = match ring.seed_slot(y) {
        Some(j) => seeds.get_mut(j * pixels * C::D..(j + 1) * pixels * C::D).unwrap_or_default(),
        None => Default::default(),
    };
    Some((sums, weights, seeds))
}

/// The disjoint grid's finished values held by a [`Strip`]: the seeds of the shifted
/// patches ([`PatchSeed`]).
#[derive(Clone, Copy)]
pub struct Seeds<'a, C: Bands> {
    bands: PhantomData<C>,
    seeds: &'a [f32],
    ring: &'a Ring,
}

impl<C: Bands> Seeds<'_, C> {
    /// Views (rows, cols) of a lenslet.
    pub fn views(&self) -> (usize, usize) {
        self.ring.shape.views
    }

    /// The seed spectrum of view `(u, v)` of lenslet `(y, x)` of the sensor; `None` where
    /// the strip holds no seeds of it.
    pub fn spectrum(&self, u: usize, v: usize, y: usize, x: usize) -> Option<&[f32]> {
        let r = self.ring;
        let i = r.seed_slot(y).filter(|_| r.shape.seeded && r.shape.held.contains(&x))?;
        let at = (i * r.layout.pixels() + r.layout.pixel(u, v, x - r.shape.held.start)) * C::D;
        self.seeds.get(at..at + C::D)
    }

    /// The estimate of the patch at `o` (a `PS x PT x PU x PV x B` patch): each pixel the
    /// seed of the lenslet its value is read from, clamped to the sensor (a sheared patch
    /// reaches past it: its nearest lenslet's value); `false` where a seed is not held.
    pub fn patch<S: Shape<Bands = C>>(&self, o: PatchOrigin, patch: &mut [f32], lenslets: (usize, usize)) -> bool {
        let views = self.views();
        let (rows, cols) = (lenslets.0 as isize, lenslets.1 as isize);
        if rows == 0 || cols == 0 {
            return false;
        }
        for (p, bands) in S::Bands::chunks_mut(patch).iter_mut().enumerate() {
            let (s, t, u, v) = pixel_at::<S>(p);
            let Some((r, c)) = o.lenslet::<S>(s, t, u, v, views) else { continue };
            // (`max` then `min`: `clamp` asserts its bounds, a panic path.)
            let (r, c) = (r.max(0).min(rows - 1) as usize, c.max(0).min(cols - 1) as usize);
            let Some(seed) = self.spectrum(o.view_row as usize + u, o.view_col as usize + v, r, c) else {
                return false;
            };
            bands.copy_from_slice(seed.as_ref());
        }
        true
    }
}

/// [`Seeds`] as a [`PatchSeed`] of `PS x PT x PU x PV x B` patches on a sensor of
/// `lenslets`.
pub struct SeedPatches<'a, S: Shape> {
    pub seeds: Seeds<'a, S::Bands>,
    pub lenslets: (usize, usize),
}

impl<S: Shape> PatchSeed<S> for SeedPatches<'_, S> {
    fn seed(&mut self, o: PatchOrigin, patch: &mut PerValue<S, f32>) -> bool {
        self.seeds.patch::<S>(o, patch.as_mut(), self.lenslets)
    }

    fn cell(&mut self, (y, x): (usize, usize), (u, v): (usize, usize), band: usize) -> Option<f32> {
        self.seeds.spectrum(u, v, y, x)?.get(band).copied().filter(|x| x.is_finite())
    }
}

/// A [`PatchSink`] adding each patch straight into a [`Strip`]'s rows.
pub struct StripSink<'a, S: Shape> {
    shape: PhantomData<S>,
    sums: &'a mut [f32],
    ring: &'a Ring,
    window: Window,
}

impl<S: Shape> PatchSink<S> for StripSink<'_, S> {
    type Error = core::convert::Infallible;

    fn accept(&mut self, o: PatchOrigin, patch: &PerValue<S, f32>, report: &PatchReport) -> Result<(), Self::Error> {
        let ring = self.ring;
        let (views, window, frame_rows) = (ring.shape.views, self.window, ring.shape.frame_rows);
        let (held, layout, pixels) = (ring.shape.held.clone(), ring.layout, ring.layout.pixels());
        let sums_all = &mut *self.sums;
        let add = |r: isize, c: isize, u: usize, v: usize, w: f32, bands: &PerBand<S, f32>| {
            let (Ok(r), Ok(c)) = (usize::try_from(r), usize::try_from(c)) else { return };
            if r >= frame_rows || !held.contains(&c) {
                return;
            }
            let Some(i) = ring.slot(r) else { return };
            let (j, base) = (layout.pixel(u, v, c - held.start), i * pixels * (S::B + 1));
            let Some(dst) = sums_all.get_mut(base + j * S::B..base + j * S::B + S::B) else { return };
            for (d, &x) in dst.iter_mut().zip(bands.iter()) {
                *d += w * x;
            }
            let Some(wt) = sums_all.get_mut(base + pixels * S::B + j) else { return };
            *wt += w;
        };
        weigh::<S>(patch.as_ref(), o, report.fallback, views, window, add);
        Ok(())
    }

    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        Ok(())
    }
}
