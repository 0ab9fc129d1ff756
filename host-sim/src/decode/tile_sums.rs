//! One tile's decoded patches as weighted sums over its lenslets ([`TileSums`]), the
//! [`PatchSink`] a tile decodes into before its sums join the frame's rows
//! ([`crate::decode::strip`]).
//!
//! The layout is the frame rows' own, per lenslet row: `(s, u, v, t, b)` for the sums and
//! `(s, u, v, t)` for the weights (one a pixel: its 13 bands share it). So a tile's lenslet
//! row of one view is one contiguous run of `extent columns x 13` sums in the tile and in
//! the frame's row, and joining the rows is a slice added to a slice. With the pixel's
//! position innermost and a weight for each band, the join was 9.8 % of a default decode's
//! one-thread time (`perf record`, depth 100 x 100, pixel k = 1); each value is still the
//! sum of the same estimates in the same order, so the bits are the same.

use slf_firmware::disparity::Disparity;
use slf_firmware::overlap::Window;
use slf_firmware::{PatchOrigin, PatchReport, PatchShape, PatchSink, SolveError, Tile};

use crate::decode::report::PatchDecoder;

/// Weighted sums of the patch estimates over one tile's lenslets and the halo a sheared
/// patch reaches beyond them (`halo` lenslets on every side), all views and bands.
pub(crate) struct TileSums<const PU: usize, const PV: usize> {
    pub tile: Tile,
    views: (usize, usize),
    window: Window,
    pub halo: usize,
    /// `(s, u, v, t, b)`.
    pub sum: Vec<f32>,
    /// `(s, u, v, t)`: a pixel's weights, the same for each of its bands.
    pub weight: Vec<f32>,
    pub steps: u64,
    pub solves: u64,
    pub members: Vec<(PatchOrigin, PatchDecoder)>,
    pub disparities: Vec<(PatchOrigin, Disparity)>,
    pub errors: Vec<(PatchOrigin, f32)>,
}

impl<const PU: usize, const PV: usize> TileSums<PU, PV> {
    pub fn new(tile: Tile, views: (usize, usize), window: Window, halo: usize) -> Self {
        let (rows, cols) = (tile.lenslet_rows as usize + 2 * halo, tile.lenslet_cols as usize + 2 * halo);
        let pixels = rows * cols * views.0 * views.1;
        Self {
            tile,
            views,
            window,
            halo,
            sum: vec![0.0; pixels * 13],
            weight: vec![0.0; pixels],
            steps: 0,
            solves: 0,
            members: Vec::new(),
            disparities: Vec::new(),
            errors: Vec::new(),
        }
    }

    /// Lenslet rows and columns of the buffer.
    pub fn extent(&self) -> (usize, usize) {
        (self.tile.lenslet_rows as usize + 2 * self.halo, self.tile.lenslet_cols as usize + 2 * self.halo)
    }

    /// The pixel index (into [`Self::weight`]; times 13 into [`Self::sum`]) of lenslet
    /// `(s, t)` of the buffer, counted from the halo's corner, view `(u, v)`.
    pub fn pixel(&self, s: usize, t: usize, u: usize, v: usize) -> usize {
        ((s * self.views.0 + u) * self.views.1 + v) * self.extent().1 + t
    }
}

impl<const PU: usize, const PV: usize, const N: usize> PatchSink<N> for TileSums<PU, PV> {
    type Error = core::convert::Infallible;

    fn accept(&mut self, o: PatchOrigin, patch: &[f32; N], report: &PatchReport) -> Result<(), Self::Error> {
        self.steps += u64::from(report.outcome.iterations);
        self.solves += u64::from(report.solves);
        self.members.push((o, PatchDecoder::of(report)));
        if (o.view_row, o.view_col) == (0, 0) && self.halo > 0 && !report.fallback {
            self.disparities.push((o, o.disparity));
        }
        if let (Some(e), false) = (report.error, report.fallback) {
            self.errors.push((o, e));
        }
        let scale = if report.fallback { slf_firmware::disparity::FALLBACK_WEIGHT } else { 1.0 };
        // The halo's corner, in sensor lenslets.
        let (r0, c0) =
            (self.tile.lenslet_row as isize - self.halo as isize, self.tile.lenslet_col as isize - self.halo as isize);
        let (rows, cols) = self.extent();
        // A pixel at a time: its 13 bands are consecutive in the patch and in the buffer, and
        // share the pixel's position and weight, found once instead of once a value (7 % of a
        // preview's one-thread time when they were, 1.6 % now; `perf record`, cotton_128).
        for (p, bands) in patch.as_chunks::<13>().0.iter().enumerate() {
            let [s, t, u, v, _] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(p * 13);
            // The pixel the value was read from (sheared patches: shifted per view).
            let Some((r, c)) = o.lenslet::<5, 5>(s, t, u, v, self.views) else { continue };
            let (Ok(r), Ok(c)) = (usize::try_from(r - r0), usize::try_from(c - c0)) else { continue };
            if r >= rows || c >= cols {
                continue;
            }
            let j = self.pixel(r, c, o.view_row as usize + u, o.view_col as usize + v);
            let w = scale * self.window.weight::<5, 5>(s, t);
            for (sum, &x) in self.sum[j * 13..j * 13 + 13].iter_mut().zip(bands) {
                *sum += w * x;
            }
            self.weight[j] += w;
        }
        Ok(())
    }

    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        Ok(())
    }
}
