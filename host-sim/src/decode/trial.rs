//! The model trial on the workstation: the DCT or the screened ensemble for the frame,
//! picked by their held-out errors on pilot patches ([`slf_firmware::trial`]).
//!
//! The pilots are the first blocks of the disjoint grid's tiles, at most [`pilot_budget`]
//! of them (one for 16 of the decode's patches, 16 to [`MAX_PILOTS`]) spread evenly over the
//! frame. A pilot costs both models' decodes (the DCT's one solve and the ensemble's two): in
//! the default, 3 solves a tile of 36 patches at stride 2 (0.08 a patch) up to 160 x 160
//! lenslets, a fixed 768 on a larger frame; in the preview (4 patches a tile) about 0.19 a
//! patch, and 48 solves at least.
//!
//! Why one pick for the frame, not per region: a pilot's held-out error is a noisy
//! sample (about 78 held-out measurements, or 9 held-out (lenslet, band) groups on a lenslet
//! mask). Picked per region of 3 x 3 tiles, the smooth scene at lenslet k = 3 went to the
//! DCT in 16 of 25 regions, where the frame's pilots together favour the ensemble by 1.7
//! times (0.0086 against 0.0111 RMS) and the ensemble decodes it 0.5 dB better
//! (`docs/results-model-trial.md`).

use rayon::prelude::*;
use std::ops::AddAssign;

use crate::io::frames::SensorFrame;
use crate::io::patch::{HostDecoder, HostModel, HostWorkspace};
use slf_firmware::{FrameSource, ModelTrial, PairedErrors, ShearTrial, Tile};

/// The most pilots a frame's trial takes. With 64, the HCI crops' 196 tiles gave 49 pilots,
/// and cotton and antinous at lenslet k = 3 went to the DCT (held-out RMS 0.00164 against
/// 0.00168, and 0.00274 against 0.00276), where the ensemble decodes 1.35 and 0.49 dB better;
/// with every tile a pilot both went to the ensemble (0.00260 against 0.00175, 0.00293
/// against 0.00277): a few pilots with large errors decide the sums, and 49 missed them.
pub const MAX_PILOTS: usize = 256;

/// The fewest pilots a frame's trial takes, where it has as many tiles.
pub const MIN_PILOTS: usize = 16;

/// Patches a pilot: a frame's trial takes at most one pilot for this many of the decode's
/// patches (and [`MIN_PILOTS`] at least). The default's stride-2 grid has 36 patches a
/// tile, so it keeps its pilot a tile; the preview's disjoint grid has 4, where a pilot a
/// tile (3 solves) cost the preview 0.75 solves a patch on top of its one.
pub const PATCHES_A_PILOT: usize = 16;

/// How many pilots a trial over a decode of `patches` patches takes.
pub fn pilot_budget(patches: usize) -> usize {
    (patches / PATCHES_A_PILOT).clamp(MIN_PILOTS, MAX_PILOTS)
}

/// How far below the DCT's (RMS over the pilots) the ensemble's held-out error must be
/// for a DCT decode with the model trial (the preview's) to give the frame to the ensemble,
/// which costs it about 1.7 times the DCT's time. Chosen on the preview's table with an
/// ensemble column (every scene and setting; no set held out): the frames whose pilots
/// favoured the ensemble by 1.25 times or more decoded 0.8 to 3.9 dB better with it, and
/// those within 1.2 times from -0.7 to +1.8 dB, most within 0.5. In
/// `docs/results-preview.md` the six frames it moved decoded 0.14 to 4.53 dB better.
pub const DCT_LEAN: f32 = 0.8;

/// The model trial over `tiles` (the disjoint grid's): one pilot on each of at most
/// `budget` ([`pilot_budget`]) of them, evenly spaced, in parallel; their errors summed.
pub fn frame_trial<const PU: usize, const PV: usize, const N: usize, A, Z>(
    decoder: &HostDecoder<'_, PU, PV, N>,
    first: &A,
    second: &Z,
    raw: &[SensorFrame<'_>],
    tiles: &[Tile],
    budget: usize,
) -> ModelTrial
where
    A: HostModel<PU, PV, N>,
    Z: HostModel<PU, PV, N>,
{
    pilots::<PU, PV, N, _>(raw, tiles, budget, |source, at, ws| decoder.trial(first, second, at, source, ws))
}

/// The shear trial over `tiles` (the disjoint grid's): on each of at most `budget`
/// of them whose first block's views agree best at a half-pixel disparity, the held-out
/// errors at it and at the better whole one beside it
/// ([`TileDecoder::shear_trial`]), summed.
pub fn frame_shear_trial<const PU: usize, const PV: usize, const N: usize, M>(
    decoder: &HostDecoder<'_, PU, PV, N>,
    model: &M,
    raw: &[SensorFrame<'_>],
    tiles: &[Tile],
    budget: usize,
) -> ShearTrial
where
    M: HostModel<PU, PV, N>,
{
    pilots::<PU, PV, N, _>(raw, tiles, budget, |source, at, ws| decoder.shear_trial(model, at, source, ws))
}

/// `pilot` on the first block of each of at most `budget` of `tiles`, evenly
/// spaced, in parallel (a workspace a thread); their trials summed (a pilot whose source
/// failed counts as none).
fn pilots<const PU: usize, const PV: usize, const N: usize, T: AddAssign + Default + Send>(
    raw: &[SensorFrame<'_>],
    tiles: &[Tile],
    budget: usize,
    pilot: impl Fn(
        &mut FrameSource<'_, SensorFrame<'_>>,
        (u16, u16),
        &mut HostWorkspace<PU, PV, N>,
    ) -> Result<T, slf_firmware::raw::ReadError>
    + Sync,
) -> T {
    let step = tiles.len().div_ceil(budget.max(1)).max(1);
    tiles
        .par_iter()
        .step_by(step)
        .map_init(
            || Box::new(HostWorkspace::<PU, PV, N>::new()),
            |ws, t| pilot(&mut FrameSource::new(raw), (t.lenslet_row, t.lenslet_col), ws).unwrap_or_default(),
        )
        .reduce(T::default, |mut a, b| {
            a += b;
            a
        })
}

/// A trial's errors as RMS over its pilots (first, second; 0 without pilots).
pub fn rms(t: &PairedErrors) -> (f64, f64) {
    let per = |sum: f32| (f64::from(sum) / f64::from(t.pilots.max(1))).sqrt();
    (per(t.first), per(t.second))
}
