//! One tile's decoded patches as weighted sums over its lenslets ([`TileSums`]), on
//! caller-owned slices, before they join the frame's rows ([`crate::decode::engine::strip`]);
//! and the weighing of a patch's estimates ([`weigh`]) that every sum of the engine uses.
//!
//! The layout is the rows' own ([`crate::decode::engine::rows`]) per lenslet row:
//! `(s, u, v, t, b)` for the sums and `(s, u, v, t)` for the weights. So a tile's lenslet
//! row of one view is one contiguous run of `extent columns x B` sums in the tile and in a
//! row of the strip, and joining them is a slice added to a slice. (With the pixel's
//! position innermost and a weight for each band, the join was 9.8 % of a default decode's
//! one-thread time on the host; `perf record`, depth 100 x 100, pixel k = 1.)

use crate::decode::engine::error::EngineError;
use crate::decode::engine::window::Window;
use crate::decode::tile::{PatchOrigin, Tile};
use crate::operators::disparity::FALLBACK_WEIGHT;
use core::marker::PhantomData;

use crate::operators::shape::{PerBand, Shape};
use crate::sensor::extent::{Array, Bands};

/// Lenslet `(s, t)` and view `(u, v)` of pixel `p` of a `PS x PT x PU x PV` patch, pixels in
/// the patch's order ([`crate::shape::PatchShape::index`] without the band).
#[inline]
pub(crate) fn pixel_at<S: Shape>(p: usize) -> (usize, usize, usize, usize) {
    (p / (S::PV * S::PU * S::PT), (p / (S::PV * S::PU)) % S::PT, (p / S::PV) % S::PU, p % S::PV)
}

/// A patch's estimates weighed into pixels: for each pixel `(s, t, u, v)` of the patch at
/// `origin`, in the patch's order, `add(row, col, view_row, view_col, weight, values)` with
/// the sensor lenslet its values were read from (sheared patches: shifted per view; it may
/// lie outside the sensor), the lenslet's view, the window's weight (a fallback's times
/// [`FALLBACK_WEIGHT`]) and its `B` values. A pixel a half-pixel shear names no lenslet of
/// is skipped.
pub fn weigh<S: Shape>(
    patch: &[f32],
    origin: PatchOrigin,
    fallback: bool,
    views: (usize, usize),
    window: Window,
    mut add: impl FnMut(isize, isize, usize, usize, f32, &PerBand<S, f32>),
) {
    let scale = if fallback { FALLBACK_WEIGHT } else { 1.0 };
    for (p, bands) in S::Bands::chunks(patch).iter().enumerate() {
        let (s, t, u, v) = pixel_at::<S>(p);
        let Some((r, c)) = origin.lenslet::<S>(s, t, u, v, views) else { continue };
        let w = scale * window.weight::<S>(s, t);
        add(r, c, origin.view_row as usize + u, origin.view_col as usize + v, w, bands);
    }
}

/// Weighted sums of a tile's patch estimates over its lenslets and the halo a sheared patch
/// reaches beyond them (`halo` lenslets on every side), all views and `B` bands, on
/// caller-owned slices of [`TileSums::lens`].
pub struct TileSums<'b, C: Bands> {
    /// The band count the sums are over.
    pub bands: PhantomData<C>,
    pub tile: Tile,
    pub views: (usize, usize),
    pub window: Window,
    pub halo: usize,
    /// `(s, u, v, t, b)`.
    pub sum: &'b mut [f32],
    /// `(s, u, v, t)`: a pixel's weight, the same for each of its bands.
    pub weight: &'b mut [f32],
}

impl<'b, C: Bands> TileSums<'b, C> {
    /// Lenslet rows and columns of the sums of `tile` with `halo`.
    pub fn extent_of(tile: &Tile, halo: usize) -> (usize, usize) {
        (usize::from(tile.lenslet_rows) + 2 * halo, usize::from(tile.lenslet_cols) + 2 * halo)
    }

    /// `f32`s of the sums and of the weights of `tile` with `views` and `halo`.
    pub fn lens(tile: &Tile, views: (usize, usize), halo: usize) -> (usize, usize) {
        let (rows, cols) = Self::extent_of(tile, halo);
        let pixels = rows * cols * views.0 * views.1;
        (pixels * C::D, pixels)
    }

    /// The sums of `tile` on `sum` and `weight`, zeroed (the rest of a longer slice is not
    /// used).
    ///
    /// # Errors
    /// [`EngineError::TileSums`] when they are shorter than [`Self::lens`] says.
    pub fn new(
        tile: Tile,
        views: (usize, usize),
        window: Window,
        halo: usize,
        sum: &'b mut [f32],
        weight: &'b mut [f32],
    ) -> Result<Self, EngineError> {
        let (s, w) = Self::lens(&tile, views, halo);
        let (Some(sum), Some(weight)) = (sum.get_mut(..s), weight.get_mut(..w)) else {
            return Err(EngineError::TileSums);
        };
        sum.fill(0.0);
        weight.fill(0.0);
        Ok(Self { bands: PhantomData, tile, views, window, halo, sum, weight })
    }

    /// Lenslet rows and columns of the sums.
    pub fn extent(&self) -> (usize, usize) {
        Self::extent_of(&self.tile, self.halo)
    }

    /// The pixel index (into [`Self::weight`]; times `B` into [`Self::sum`]) of lenslet
    /// `(s, t)` of the sums, counted from the halo's corner, view `(u, v)`.
    #[inline]
    pub fn pixel(&self, s: usize, t: usize, u: usize, v: usize) -> usize {
        ((s * self.views.0 + u) * self.views.1 + v) * self.extent().1 + t
    }

    /// Adds the estimates of the patch at `o` (a fallback's: see
    /// [`PatchReport::fallback`](crate::tile::PatchReport::fallback)).
    pub fn add<S: Shape<Bands = C>>(&mut self, o: PatchOrigin, patch: &[f32], fallback: bool) {
        // The halo's corner, in sensor lenslets.
        let (r0, c0) =
            (self.tile.lenslet_row as isize - self.halo as isize, self.tile.lenslet_col as isize - self.halo as isize);
        let (rows, cols) = self.extent();
        let views = self.views;
        let (sum, weight) = (&mut *self.sum, &mut *self.weight);
        let add = |r: isize, c: isize, u: usize, v: usize, w: f32, bands: &PerBand<S, f32>| {
            let (Ok(r), Ok(c)) = (usize::try_from(r - r0), usize::try_from(c - c0)) else { return };
            if r >= rows || c >= cols {
                return;
            }
            let j = ((r * views.0 + u) * views.1 + v) * cols + c;
            let (Some(dst), Some(wt)) = (sum.get_mut(j * C::D..j * C::D + C::D), weight.get_mut(j)) else { return };
            for (d, &x) in dst.iter_mut().zip(bands.iter()) {
                *d += w * x;
            }
            *wt += w;
        };
        weigh::<S>(patch, o, fallback, views, self.window, add);
    }
}
