//! One tile's decoded patches ([`TileSums`]): the firmware engine's weighted sums
//! ([`slf_firmware::decode::engine::tile_sums`]) on buffers of the tile's own, and what the
//! host's report keeps of each patch (solves, steps, the member, disparity and error maps).

use slf_firmware::decode::engine::tile_sums::TileSums as Sums;
use slf_firmware::disparity::Disparity;
use slf_firmware::overlap::Window;
use slf_firmware::{PatchOrigin, PatchReport, PatchSink, SolveError, Tile};

use crate::decode::report::PatchDecoder;
use crate::io::patch::{HostBands, HostShape};

/// A tile's weighted sums and report: the [`PatchSink`] a tile decodes into before its
/// sums join the frame's rows.
pub(crate) struct TileSums<const PU: usize, const PV: usize> {
    pub tile: Tile,
    views: (usize, usize),
    window: Window,
    halo: usize,
    sum: Vec<f32>,
    weight: Vec<f32>,
    pub steps: u64,
    pub solves: u64,
    pub members: Vec<(PatchOrigin, PatchDecoder)>,
    pub disparities: Vec<(PatchOrigin, Disparity)>,
    pub errors: Vec<(PatchOrigin, f32)>,
}

impl<const PU: usize, const PV: usize> TileSums<PU, PV> {
    pub fn new(tile: Tile, views: (usize, usize), window: Window, halo: usize) -> Self {
        let (sums, pixels) = Sums::<HostBands>::lens(&tile, views, halo);
        Self {
            tile,
            views,
            window,
            halo,
            sum: vec![0.0; sums],
            weight: vec![0.0; pixels],
            steps: 0,
            solves: 0,
            members: Vec::new(),
            disparities: Vec::new(),
            errors: Vec::new(),
        }
    }

    /// The sums, as the engine reads and adds them.
    pub fn sums(&mut self) -> Sums<'_, HostBands> {
        Sums {
            bands: core::marker::PhantomData,
            tile: self.tile,
            views: self.views,
            window: self.window,
            halo: self.halo,
            sum: &mut self.sum,
            weight: &mut self.weight,
        }
    }
}

impl<const PU: usize, const PV: usize, const N: usize> PatchSink<HostShape<PU, PV, N>> for TileSums<PU, PV> {
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
        self.sums().add::<HostShape<PU, PV, N>>(o, patch, report.fallback);
        Ok(())
    }

    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        Ok(())
    }
}
