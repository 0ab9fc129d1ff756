//! The device's driver of the overlapped decode ([`OverlapDecoder`]): the engine
//! ([`crate::decode::engine`]) run one tile at a time, straight into a caller-owned strip
//! of lenslet rows, band by band where the strip is narrower than the sensor.
//!
//! The host drives the same engine with batches of tiles in parallel; both decode the same
//! patches, seeded the same way, and join them in the same order of tiles, so a device
//! decode equals the host's with the same options to float rounding (within a tile the
//! host sums a tile's patches before they join the rows, the device adds each patch to the
//! rows; `slf device-check` holds them to 1e-5 relative). The device's tiles are single
//! patches (the host's default holds 2 x 2): a tile's buffer would cost the device as much
//! RAM as its strip.
//!
//! A strip narrower than the sensor cuts the frame into vertical bands decoded one after
//! the other ([`crate::decode::engine::band`]); a tile that reaches two bands is decoded
//! for each (the price of the smaller strip; [`OverlapDecoder::patch_decodes`] counts it).

use core::fmt;

use crate::decode::engine::band::Band;
use crate::decode::engine::plan::Grids;
use crate::decode::engine::rows::Fill;
pub use crate::decode::engine::rows::RowSink;
use crate::decode::engine::schedule::{Needs, Next, Schedule};
use crate::decode::engine::strip::{SeedPatches, Strip, StripShape};
pub use crate::decode::engine::window::Window;
use crate::decode::tile::{ConfigError, TileDecoder, TileReport};
use crate::operators::shape::Shape;
use crate::sensor::source::TileSource;
use crate::solver::choice::PatchModel;
use crate::solver::workspace::Workspace;

/// Where patches sit and how their estimates are averaged. Config: immutable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Overlap {
    /// Lenslets between patch grids (rows, cols), each in `1..=` the patch's size; the
    /// patch size itself is the disjoint grid alone.
    pub stride: (u8, u8),
    /// How the estimates of one value are weighed.
    pub window: Window,
    /// Start the shifted grids' patches from the disjoint grid's decode (below the
    /// patch's size only).
    pub seeded: bool,
}

impl Overlap {
    /// The host's default: stride 2, tapered window, seeded.
    pub const DEFAULT: Self = Self { stride: (2, 2), window: Window::Tapered, seeded: true };
}

/// What an overlapped frame decode did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OverlapReport {
    /// Patch solves over every band (a patch reaching two bands counts twice).
    pub patches: TileReport,
    /// Tiles whose source read failed (nothing after the failed read was averaged in).
    pub source_failures: u32,
    /// Values no decoded patch covered (put as 0).
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
    /// The strip buffer holds less than one lenslet column's band.
    Strip,
    /// The row sink failed; the rows put before stay put.
    Sink(K),
}

impl<K: fmt::Debug> fmt::Display for OverlapError<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Strip => f.write_str("strip buffer smaller than a band of one lenslet column"),
            Self::Sink(e) => write!(f, "row sink failed: {e:?}"),
        }
    }
}

impl<K: fmt::Debug> core::error::Error for OverlapError<K> {}

/// The tile decoder with patches at a stride: checked config, stateless.
#[derive(Clone, Copy, Debug)]
pub struct OverlapDecoder<'a, S: Shape> {
    tiles: TileDecoder<'a, S>,
    overlap: Overlap,
    grids: Grids,
    /// Lenslet rows the strip holds: the schedule of the whole width run dry.
    needs: Needs,
}

impl<'a, S: Shape> OverlapDecoder<'a, S> {
    /// Checks the stride against the patch.
    ///
    /// # Errors
    /// [`ConfigError::Stride`] for a stride axis outside `1..=` the patch's size.
    pub fn new(tiles: TileDecoder<'a, S>, overlap: Overlap) -> Result<Self, ConfigError> {
        let c = tiles.config().sensor;
        let (vu, vv) = (usize::from(c.lenslet.rows), usize::from(c.lenslet.cols));
        let halo = tiles.disparities().halo(vu.max(vv));
        let grids = Grids::new(c.lenslets, (S::PS, S::PT), overlap.stride, (1, 1), (1, 1), halo)
            .map_err(|_| ConfigError::Stride)?;
        let needs = Schedule::new(grids, grids.disjoint(), grids.shifted()).needs(1);
        Ok(Self { tiles, overlap, grids, needs })
    }

    /// The tile decoder underneath.
    pub fn tiles(&self) -> &TileDecoder<'a, S> {
        &self.tiles
    }

    /// The patch grids.
    pub fn grids(&self) -> &Grids {
        &self.grids
    }

    /// Whether the decode seeds: asked, and a stride below the patch's size.
    fn seeded(&self) -> bool {
        self.overlap.seeded && self.overlap.stride != (S::PS as u8, S::PT as u8)
    }

    /// Lenslet views (rows, cols) of the sensor.
    fn views(&self) -> (usize, usize) {
        let l = self.tiles.config().sensor.lenslet;
        (l.rows as usize, l.cols as usize)
    }

    /// Lenslet rows the strip holds at once: of sums and of seeds.
    pub fn slots(&self) -> Needs {
        self.needs
    }

    /// Columns a band holds beyond its own on each side, at most: a seeded band reads the
    /// seeds of every shifted patch that reaches it.
    fn margin(&self) -> usize {
        if self.seeded() { S::PT + 2 * self.grids.halo() } else { 0 }
    }

    /// `f32`s of a strip that decodes bands of `width` lenslet columns (the whole width in
    /// one band at the sensor's columns).
    pub fn strip_len(&self, width: usize) -> usize {
        let held = (width + 2 * self.margin()).min(self.grids.lenslets().1);
        self.strip_shape(0..held, 0..held).buffer_len::<S::Bands>()
    }

    /// The strip of a band holding columns `held` and putting `out`.
    fn strip_shape(&self, held: core::ops::Range<usize>, out: core::ops::Range<usize>) -> StripShape {
        StripShape {
            views: self.views(),
            frame_rows: self.grids.lenslets().0,
            held,
            out,
            slots: self.needs.rows,
            seed_slots: self.needs.seed_rows,
            seeded: self.seeded(),
        }
    }

    /// The widest band a strip of `len` `f32`s holds; `None` below one column.
    pub fn band_width(&self, len: usize) -> Option<usize> {
        (1..=self.grids.lenslets().1).rev().find(|&w| self.strip_len(w) <= len)
    }

    /// Patch decodes (angular windows included) a frame costs in bands of `width` lenslet
    /// columns: a tile reaching two bands is decoded for each.
    pub fn patch_decodes(&self, width: usize) -> usize {
        let tiles: usize = Band::across(&self.grids, width, self.seeded()).map(|b| b.tiles(&self.grids)).sum();
        tiles * self.tiles.windows().count()
    }

    /// Decodes the whole frame with `model`, every patch position at this stride, the
    /// shifted patches seeded where asked, and sends each finished lenslet row to `sink`,
    /// in row order per band. `strip` holds the rows ([`strip_len`](Self::strip_len) of
    /// the sensor's columns decode the whole width in one band; fewer give narrower bands).
    ///
    /// A tile whose read fails is counted and the rest of the frame decoded.
    ///
    /// # Errors
    /// [`OverlapError::Strip`] before anything is read; [`OverlapError::Sink`] stops the
    /// decode (the rows sent stay sent).
    pub fn decode_frame<M: PatchModel<S>, Src: TileSource, K: RowSink>(
        &self,
        model: &M,
        source: &mut Src,
        strip: &mut [f32],
        sink: &mut K,
        ws: &mut Workspace<S>,
    ) -> Result<OverlapReport, OverlapError<K::Error>> {
        let width = self.band_width(strip.len()).ok_or(OverlapError::Strip)?;
        let (grids, seeded, needs) = (self.grids, self.seeded(), self.needs);
        let (rows, cols) = grids.lenslets();
        let range = self.tiles.config().raw.range();
        let mut report = OverlapReport::default();
        for band in Band::across(&grids, width, seeded) {
            report.bands += 1;
            let shape = self.strip_shape(band.held.clone(), band.out.clone());
            let mut rows_held = Strip::<S::Bands>::new(&mut *strip, shape, range, self.overlap.window)
                .map_err(|_| OverlapError::Strip)?;
            let mut schedule = Schedule::new(grids, band.disjoint(&grids), band.shifted(&grids));
            let (mut fill, mut unused) = (Fill::default(), Fill::default());
            loop {
                let (planned, seed) = match schedule.next(1, needs.rows) {
                    Next::Disjoint(_) => (schedule.take_disjoint(), false),
                    Next::Shifted(_) => (schedule.take_shifted(), seeded),
                    Next::Done => break,
                    Next::Stalled => return Err(OverlapError::Strip),
                };
                if let Some(p) = planned {
                    let (mut into, seeds) = rows_held.sink::<S>();
                    let r = if seed {
                        let mut q = SeedPatches::<S> { seeds, lenslets: (rows, cols) };
                        self.tiles.decode_tile_seeded(model, p.tile, source, &mut q, &mut into, ws)
                    } else {
                        self.tiles.decode_tile(model, p.tile, source, &mut into, ws)
                    };
                    match r {
                        Ok(t) => report.patches.add(&t),
                        Err(_) => report.source_failures += 1,
                    }
                }
                rows_held.advance(&mut schedule, sink, &mut fill, &mut unused).map_err(OverlapError::Sink)?;
            }
            report.filled += fill.filled;
            report.uncovered += fill.uncovered;
        }
        Ok(report)
    }
}
