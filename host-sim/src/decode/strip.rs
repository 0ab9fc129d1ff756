//! The streamed decode of a frame ([`decode_rows`]): the firmware's overlapped-decode engine
//! ([`slf_firmware::decode::engine`]) driven with batches of tiles, each batch decoded in
//! parallel into tiles' own sums and joined in the plan's order; only the lenslet rows that
//! tiles still add to are held (the engine's strip), and every finished row is handed to a
//! [`RowSink`](crate::io::rows::RowSink). Peak memory is the rows of a band of tiles (and their halo) across the
//! frame, not the frame.
//!
//! The order of the sums is the engine's, whatever the batches: a decode is the same bit
//! for bit with batches of one tile or of the whole frame, and the device's driver of the
//! same engine ([`slf_firmware::OverlapDecoder`]) decodes the same patches from the same
//! seeds.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use slf_firmware::decode::engine::plan::Planned;
use slf_firmware::decode::engine::rows::Fill;
use slf_firmware::decode::engine::schedule::{Next, Schedule};
use slf_firmware::decode::engine::strip::{SeedPatches, Seeds, Strip, StripShape};
use slf_firmware::{Frame, FrameSource, TileReport};

use crate::decode::options::Maps;
use crate::decode::plan::FramePlan;
use crate::decode::report::DecodeReport;
use crate::decode::seams::{Spectra, seam_score};
use crate::decode::tile_sums::TileSums;
use crate::io::map::MapFrame;
use crate::io::patch::{HostBands, HostModel, HostShape, HostWorkspace};
use crate::io::rows::{RowShape, Rows};

/// Tiles a batch holds by default, per worker thread: enough that the threads rarely wait
/// at a batch's end, few enough that the batch's sums stay small beside the rows held.
pub const BATCH_TILES_PER_THREAD: usize = 8;

/// How [`decode_rows`] runs a pass over the frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pass {
    /// Tiles a batch (0: [`BATCH_TILES_PER_THREAD`] a thread).
    pub batch: usize,
    /// A progress bar on stderr once the pass has taken a second.
    pub progress: bool,
    /// The per-patch maps the report keeps.
    pub maps: Maps,
}

/// The engine's seeds as the spectra the adaptive rule scores.
struct SeedRows<'r> {
    seeds: Seeds<'r, HostBands>,
    shape: RowShape,
}

impl Spectra for SeedRows<'_> {
    fn views(&self) -> (usize, usize) {
        self.shape.views
    }

    fn size(&self) -> (usize, usize) {
        (self.shape.rows, self.shape.cols)
    }

    fn spectrum(&self, u: usize, v: usize, y: usize, x: usize) -> &[f32] {
        self.seeds.spectrum(u, v, y, x).unwrap_or(&[])
    }
}

/// A batch's tiles, decoded.
type Decoded<const PU: usize, const PV: usize> = Vec<(Planned, TileSums<PU, PV>, Result<TileReport, String>)>;

/// Decodes every tile of `plan` with `model` from `raw`, in batches of `pass.batch` tiles,
/// putting each finished lenslet row into `sink` in
/// order, the report keeping the per-patch maps `pass.maps` asks for; calls `observer` with (tiles done, tiles in all) after each tile. Returns the
/// report (without the trials', which the plan holds).
///
/// # Errors
/// What the sink returns.
pub fn decode_rows<const PU: usize, const PV: usize, const N: usize, M, F>(
    plan: &FramePlan<'_, PU, PV, N>,
    model: &M,
    raw: &[F],
    pass: Pass,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport>
where
    M: HostModel<PU, PV, N>,
    F: Frame + Sync,
{
    let start = Instant::now();
    let Pass { batch, progress, maps: maps_asked } = pass;
    let shape = plan.shape;
    let batch = if batch == 0 { BATCH_TILES_PER_THREAD * rayon::current_num_threads() } else { batch };
    let total = plan.grids.disjoint_len() + plan.grids.shifted_len();
    let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("decoding {bar:40} {pos}/{len} tiles, {elapsed} elapsed, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let shown = AtomicBool::new(false);
    // Tiles done, counted here: the bar's position read after its increment could be
    // another thread's too, and an observer then saw one count twice.
    let done = AtomicUsize::new(0);
    let tick = |n: usize| {
        bar.inc(n as u64);
        let d = done.fetch_add(n, Ordering::Relaxed) + n;
        observer(d, total);
        if progress && start.elapsed().as_secs_f64() > 1.0 && !shown.swap(true, Ordering::Relaxed) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    };
    let lenslets = (shape.rows, shape.cols);
    let run = |tiles: &[Planned], seeds: Option<Seeds<'_, HostBands>>| -> Decoded<PU, PV> {
        tiles
            .par_iter()
            .map_init(
                || (Box::new(HostWorkspace::<PU, PV, N>::new()), plan.flat.as_ref().map(MapFrame::new)),
                |(ws, flat), &planned| {
                    let mut sums = TileSums::new(planned.tile, shape.views, plan.window, plan.grids.halo());
                    // A corrected capture's flat, for the per-patch error estimate's noise
                    // (read only by it).
                    let source = match flat.as_ref() {
                        Some(f) => FrameSource::new(raw).with_flat(f),
                        None => Ok(FrameSource::new(raw)),
                    };
                    let r = source.map_err(|e| format!("the flat map: {e:?}")).and_then(|mut source| {
                        match seeds {
                            Some(seeds) => plan.decoder.decode_tile_seeded(
                                model,
                                planned.tile,
                                &mut source,
                                &mut SeedPatches::<HostShape<PU, PV, N>> { seeds, lenslets },
                                &mut sums,
                                ws,
                            ),
                            None => plan.decoder.decode_tile(model, planned.tile, &mut source, &mut sums, ws),
                        }
                        .map_err(|e| e.to_string())
                    });
                    tick(1);
                    (planned, sums, r)
                },
            )
            .collect()
    };
    let mut report = DecodeReport::default();
    let mut maps = Vec::new();
    let keep = maps_asked;
    let mut counts = std::collections::BTreeMap::new();
    let mut account = |decoded: Decoded<PU, PV>, into: &mut Strip<'_, HostBands>, report: &mut DecodeReport| {
        for (planned, mut sums, r) in decoded {
            into.join(&sums.sums());
            match r {
                Ok(t) => report.patches.add(&t),
                Err(_) => report.failed_tiles += 1,
            }
            report.tiles += 1;
            report.steps += sums.steps;
            report.solves += sums.solves;
            for (_, d) in &sums.disparities {
                *counts.entry(*d).or_insert(0usize) += 1;
            }
            let members = if keep.members { sums.members } else { Vec::new() };
            let disparities = if keep.disparities { sums.disparities } else { Vec::new() };
            maps.push((planned.order, members, disparities, sums.errors));
        }
    };
    let grids = plan.grids;
    let seeds_needed = plan.seeded || plan.adaptive.is_some();
    let mut schedule = Schedule::new(grids, grids.disjoint(), grids.shifted());
    // The rows the batches need: the schedule run dry (no stall, and the batches as sized).
    let needs = schedule.clone().needs(batch);
    let slots = needs.rows;
    let held = StripShape {
        views: shape.views,
        frame_rows: shape.rows,
        held: 0..shape.cols,
        out: 0..shape.cols,
        slots,
        seed_slots: needs.seed_rows,
        seeded: seeds_needed,
    };
    let mut buf = vec![0.0f32; held.buffer_len::<HostBands>()];
    // The strip's whole allocation, the seed rows' slots with the sums' (the summary's
    // `memory:` line once counted the sums alone).
    report.strip_bytes = buf.len() * 4;
    report.seed_rows = if seeds_needed { needs.seed_rows } else { 0 };
    let mut strip = Strip::<HostBands>::new(&mut buf, held, plan.range, plan.window)
        .map_err(|e| anyhow::anyhow!("{e} ({slots} rows of {} x {} lenslets)", shape.rows, shape.cols))?;
    let (mut fill, mut unused) = (Fill::default(), Fill::default());
    loop {
        match schedule.next(batch, slots) {
            Next::Shifted(n) => {
                let tiles: Vec<Planned> = (0..n).filter_map(|_| schedule.take_shifted()).collect();
                // The adaptive rule's score reads the patch's own rows, inside its reach.
                let chosen: Vec<Planned> = match plan.adaptive {
                    Some(threshold) => {
                        let rows = SeedRows { seeds: strip.seeds(), shape };
                        tiles
                            .iter()
                            .filter(|p| {
                                seam_score(&rows, usize::from(p.tile.lenslet_row), usize::from(p.tile.lenslet_col))
                                    > threshold
                            })
                            .copied()
                            .collect()
                    }
                    None => tiles.clone(),
                };
                if chosen.len() < tiles.len() {
                    tick(tiles.len() - chosen.len());
                }
                let decoded = run(&chosen, plan.seeded.then(|| strip.seeds()));
                account(decoded, &mut strip, &mut report);
            }
            Next::Disjoint(n) => {
                let tiles: Vec<Planned> = (0..n).filter_map(|_| schedule.take_disjoint()).collect();
                let decoded = run(&tiles, None);
                account(decoded, &mut strip, &mut report);
            }
            Next::Done => break,
            // Unreachable: the strip holds the rows the dry run needed.
            Next::Stalled => anyhow::bail!("the streamed decode stalled at row {}", schedule.put()),
        }
        report.rows_held = report.rows_held.max(schedule.end() - schedule.put());
        strip.advance(&mut schedule, sink, &mut fill, &mut unused)?;
    }
    bar.finish_and_clear();
    // The maps in the canonical order (the disjoint grid, then grid by grid), whatever
    // order the batches decoded their tiles in.
    maps.sort_by_key(|m| m.0);
    for (_, members, disparities, errors) in maps {
        report.member_map.extend(members);
        report.disparity_map.extend(disparities);
        report.error_map.extend(errors);
    }
    report.disparity_counts = counts.into_iter().collect();
    report.filled = fill.filled as usize;
    report.uncovered = fill.uncovered as usize;
    Ok(report)
}
