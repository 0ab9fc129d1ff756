//! The streamed decode of a frame ([`decode_rows`]): its tiles in batches, down the frame,
//! each batch in parallel; only the lenslet rows that tiles still add to held, and every
//! finished row handed to a [`RowSink`] and dropped. Peak memory is the rows of a band of
//! tiles (and their halo) across the frame, not the frame.
//!
//! Every light-field value is the weighted mean of the estimates that cover it, summed in
//! one order whatever the batches: the disjoint grid's tiles row by row, then the shifted
//! grids' tiles by their first row (a tile's estimates added in the order it decoded them).
//! So a decode is the same bit for bit with batches of one tile or of the whole frame. A
//! shifted tile waits until every disjoint tile that reaches its rows has been added (its
//! seed, and the order), and a row is finished once no tile left to decode reaches it:
//!
//! - `disjoint`: the disjoint grid's sums, rows from the first that a pending disjoint
//!   tile reaches; when a row leaves it, its values (the seed of the shifted patches)
//!   join `seeds` and its sums move to `sums`;
//! - `sums`: the disjoint grid's sums with the shifted grids' added;
//! - a row of `sums` no pending shifted tile reaches is finished: each value its weighted
//!   mean, clamped to the sensor's range, a view no patch covered filled from its lenslet's
//!   other views (`finish_row`), and put to the sink.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use slf_firmware::tile::PatchSeed;
use slf_firmware::{FrameSource, PatchModel, PatchOrigin, PatchShape, RawFrame, TileReport, Workspace};

use crate::decode::plan::{FramePlan, Planned};
use crate::decode::report::DecodeReport;
use crate::decode::seams::{Spectra, seam_score};
use crate::decode::tile_sums::TileSums;
use crate::io::rows::{RowShape, RowSink};

/// Tiles a batch holds by default, per worker thread: enough that the threads rarely wait
/// at a batch's end, few enough that the batch's sums stay small beside the rows held.
pub const BATCH_TILES_PER_THREAD: usize = 8;

/// Lenslet rows `first..first + rows.len()` of something row-shaped.
struct Rows<T> {
    first: usize,
    rows: VecDeque<T>,
}

impl<T> Rows<T> {
    fn new() -> Self {
        Self { first: 0, rows: VecDeque::new() }
    }

    fn end(&self) -> usize {
        self.first + self.rows.len()
    }

    /// Row `y`, made by `make` (and every row before it) if not held yet; `y` must not be
    /// below the first held.
    fn row_mut(&mut self, y: usize, make: impl Fn() -> T) -> &mut T {
        while self.end() <= y {
            self.rows.push_back(make());
        }
        &mut self.rows[y - self.first]
    }

    /// The first row, taken out; `make` if none is held.
    fn take_first(&mut self, make: impl Fn() -> T) -> T {
        self.first += 1;
        self.rows.pop_front().unwrap_or_else(make)
    }

    /// Drops the rows below `y`.
    fn drop_below(&mut self, y: usize) {
        while self.first < y && !self.rows.is_empty() {
            self.rows.pop_front();
            self.first += 1;
        }
        self.first = self.first.max(y);
    }
}

/// A row's sums ([`RowShape::row_len`]) and weights (one a pixel: [`RowShape::pixels`]).
struct SumRow {
    sum: Vec<f32>,
    weight: Vec<f32>,
}

impl SumRow {
    /// A row of `shape` no estimate has reached.
    fn zeros(shape: RowShape) -> Self {
        Self { sum: vec![0.0; shape.row_len()], weight: vec![0.0; shape.pixels()] }
    }
}

/// The finished rows of the disjoint grid's decode: the shifted patches' seeds, and what
/// the adaptive rule scores.
struct SeedRows<'r> {
    rows: &'r Rows<Vec<f32>>,
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
        let i = self.shape.at(u, v, x, 0);
        &self.rows.rows[y - self.rows.first][i..i + self.shape.bands]
    }
}

/// The disjoint grid's decode as the start of the shifted patches that overlap it
/// ([`PatchSeed`]).
struct FrameSeed<'r, const PU: usize, const PV: usize> {
    rows: SeedRows<'r>,
}

impl<const PU: usize, const PV: usize, const N: usize> PatchSeed<N> for FrameSeed<'_, PU, PV> {
    fn seed(&mut self, o: PatchOrigin, patch: &mut [f32; N]) -> bool {
        let (rows, cols) = (self.rows.shape.rows as isize, self.rows.shape.cols as isize);
        for (p, bands) in patch.as_chunks_mut::<13>().0.iter_mut().enumerate() {
            let [s, t, u, v, _] = PatchShape::<5, 5, PU, PV, 13, N>::coordinates(p * 13);
            let Some((r, c)) = o.lenslet::<5, 5>(s, t, u, v, self.rows.shape.views) else { continue };
            // A sheared patch reaches past the sensor: its nearest lenslet's value.
            let (r, c) = (r.clamp(0, rows - 1) as usize, c.clamp(0, cols - 1) as usize);
            bands.copy_from_slice(self.rows.spectrum(o.view_row as usize + u, o.view_col as usize + v, r, c));
        }
        true
    }
}

/// Adds a tile's sums into the rows it reaches (made where not held yet): per lenslet row
/// and view, the run of the tile's columns on the sensor, a slice onto a slice.
fn add_tile<const PU: usize, const PV: usize>(rows: &mut Rows<SumRow>, sums: &TileSums<PU, PV>, shape: RowShape) {
    let zero = || SumRow::zeros(shape);
    let tile = sums.tile;
    let (extent_rows, extent_cols) = sums.extent();
    // The tile's columns on the sensor: `t0..t1` of the buffer, from sensor column `c`.
    let left = tile.lenslet_col as usize;
    let t0 = sums.halo.saturating_sub(left);
    let t1 = extent_cols.min((shape.cols + sums.halo).saturating_sub(left));
    if t0 >= t1 {
        return;
    }
    let (c, len) = (left + t0 - sums.halo, t1 - t0);
    for s in 0..extent_rows {
        let Some(r) = (tile.lenslet_row as usize + s).checked_sub(sums.halo) else { continue };
        if r >= shape.rows {
            continue;
        }
        let row = rows.row_mut(r, zero);
        for u in 0..shape.views.0 {
            for v in 0..shape.views.1 {
                let src = sums.pixel(s, t0, u, v);
                let dst = shape.pixel(u, v, c);
                for (d, &x) in row.sum[dst * 13..(dst + len) * 13].iter_mut().zip(&sums.sum[src * 13..(src + len) * 13])
                {
                    *d += x;
                }
                for (d, &x) in row.weight[dst..dst + len].iter_mut().zip(&sums.weight[src..src + len]) {
                    *d += x;
                }
            }
        }
    }
}

/// Values of a view no patch covered, and of those, the ones filled from their lenslet's
/// other views.
#[derive(Clone, Copy, Debug, Default)]
struct Fill {
    filled: usize,
    uncovered: usize,
}

/// A finished row: each value the weighted mean of the estimates that cover it, clamped to
/// the sensor's range `[lo, hi]` (the clamp takes off only what rounding adds; the
/// firmware's overlap ring does the same); a value of a view no (sheared) patch covered the
/// mean of its lenslet's covered views, as the overlap ring does; a lenslet with none 0.
/// Each mean adds the covered views in view order.
fn finish_row(row: &SumRow, shape: RowShape, (lo, hi): (f32, f32), out: &mut Vec<f32>, fill: &mut Fill) {
    let bands = shape.bands;
    out.clear();
    out.resize(row.sum.len(), 0.0);
    for ((x, s), &w) in out.chunks_exact_mut(bands).zip(row.sum.chunks_exact(bands)).zip(&row.weight) {
        if w > 0.0 {
            for (x, &s) in x.iter_mut().zip(s) {
                *x = (s / w).clamp(lo, hi);
            }
        }
    }
    let run = shape.run_len();
    let (mut mean, mut covered) = (vec![0.0f32; run], vec![0u32; shape.cols]);
    for (data, weight) in out.chunks_exact(run).zip(row.weight.chunks_exact(shape.cols)) {
        for (((m, n), x), &w) in
            mean.chunks_exact_mut(bands).zip(covered.iter_mut()).zip(data.chunks_exact(bands)).zip(weight)
        {
            if w > 0.0 {
                for (m, &x) in m.iter_mut().zip(x) {
                    *m += x;
                }
                *n += 1;
            }
        }
    }
    for (data, weight) in out.chunks_exact_mut(run).zip(row.weight.chunks_exact(shape.cols)) {
        for ((x, &w), (m, &n)) in data.chunks_exact_mut(bands).zip(weight).zip(mean.chunks_exact(bands).zip(&covered)) {
            if w > 0.0 {
                continue;
            }
            if n > 0 {
                for (x, &m) in x.iter_mut().zip(m) {
                    *x = (m / n as f32).clamp(lo, hi);
                }
                fill.filled += bands;
            } else {
                fill.uncovered += bands;
            }
        }
    }
}

/// A batch's tiles, decoded.
type Decoded<const PU: usize, const PV: usize> = Vec<(Planned, TileSums<PU, PV>, Result<TileReport, String>)>;

/// Decodes every tile of `plan` with `model` from `raw`, in batches of `batch` tiles (0:
/// [`BATCH_TILES_PER_THREAD`] a thread), putting each finished lenslet row into `sink` in
/// order; calls `observer` with (tiles done, tiles in all) after each tile. Returns the
/// report (without the trials', which the plan holds).
///
/// # Errors
/// What the sink returns.
pub fn decode_rows<const PU: usize, const PV: usize, const N: usize, M>(
    plan: &FramePlan<'_, PU, PV, N>,
    model: &M,
    raw: &[RawFrame<'_, u16>],
    batch: usize,
    progress: bool,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut dyn RowSink,
) -> Result<DecodeReport>
where
    M: PatchModel<5, 5, PU, PV, 13, N> + Sync,
{
    let start = Instant::now();
    let shape = plan.shape;
    let batch = if batch == 0 { BATCH_TILES_PER_THREAD * rayon::current_num_threads() } else { batch };
    let total = plan.disjoint.len() + plan.shifted.len();
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
    let run = |tiles: &[Planned], seeds: Option<&Rows<Vec<f32>>>| -> Decoded<PU, PV> {
        tiles
            .par_iter()
            .map_init(
                || Box::new(Workspace::<5, 5, PU, PV, 13, N>::new()),
                |ws, &planned| {
                    let mut sums = TileSums::new(planned.tile, shape.views, plan.window, plan.halo);
                    let mut source = FrameSource::new(raw);
                    let r = match seeds {
                        Some(rows) => plan.decoder.decode_tile_seeded(
                            model,
                            planned.tile,
                            &mut source,
                            &mut FrameSeed::<PU, PV> { rows: SeedRows { rows, shape } },
                            &mut sums,
                            ws,
                        ),
                        None => plan.decoder.decode_tile(model, planned.tile, &mut source, &mut sums, ws),
                    }
                    .map_err(|e| e.to_string());
                    tick(1);
                    (planned, sums, r)
                },
            )
            .collect()
    };
    let mut report = DecodeReport::default();
    let mut maps = Vec::new();
    let mut account = |decoded: Decoded<PU, PV>, into: &mut Rows<SumRow>, report: &mut DecodeReport| {
        for (planned, sums, r) in decoded {
            add_tile(into, &sums, shape);
            match r {
                Ok(t) => report.patches.add(&t),
                Err(_) => report.failed_tiles += 1,
            }
            report.tiles += 1;
            report.steps += sums.steps;
            report.solves += sums.solves;
            maps.push((planned.order, sums.members, sums.disparities, sums.errors));
        }
    };
    let seeds_needed = plan.seeded || plan.adaptive.is_some();
    let mut disjoint = Rows::<SumRow>::new();
    let mut sums = Rows::<SumRow>::new();
    let mut seeds = Rows::<Vec<f32>>::new();
    let zero = || SumRow::zeros(shape);
    let (mut next_disjoint, mut next_shifted) = (0, 0);
    // Rows below these are final in `disjoint` (moved on), and put to the sink.
    let (mut disjoint_done, mut put) = (0, 0);
    let (mut out, mut fill, mut unused) = (Vec::new(), Fill::default(), Fill::default());
    loop {
        // Shifted tiles whose rows the disjoint grid has finished, else the next disjoint
        // batch; a shifted tile needs the rows it reaches, and the adaptive rule's score
        // the patch's own (inside them).
        let ready = plan.shifted[next_shifted..]
            .iter()
            .take(batch)
            .take_while(|p| plan.reach(&p.tile).end <= disjoint_done)
            .count();
        if ready > 0 {
            let tiles = &plan.shifted[next_shifted..next_shifted + ready];
            next_shifted += ready;
            let chosen: Vec<Planned> = match plan.adaptive {
                Some(threshold) => {
                    let rows = SeedRows { rows: &seeds, shape };
                    tiles
                        .iter()
                        .filter(|p| {
                            seam_score(&rows, usize::from(p.tile.lenslet_row), usize::from(p.tile.lenslet_col))
                                > threshold
                        })
                        .copied()
                        .collect()
                }
                None => tiles.to_vec(),
            };
            if chosen.len() < tiles.len() {
                tick(tiles.len() - chosen.len());
            }
            let decoded = run(&chosen, plan.seeded.then_some(&seeds));
            account(decoded, &mut sums, &mut report);
        } else if next_disjoint < plan.disjoint.len() {
            let n = batch.min(plan.disjoint.len() - next_disjoint);
            let decoded = run(&plan.disjoint[next_disjoint..next_disjoint + n], None);
            next_disjoint += n;
            account(decoded, &mut disjoint, &mut report);
        } else if next_shifted < plan.shifted.len() {
            // Unreachable: with every disjoint tile added, every row is final.
            anyhow::bail!("the streamed decode stalled at shifted tile {next_shifted}");
        } else {
            break;
        }
        report.rows_held = report.rows_held.max(disjoint.rows.len() + sums.rows.len());
        // Rows no pending disjoint tile reaches: final in the disjoint grid's sums.
        let until = plan.disjoint.get(next_disjoint).map_or(shape.rows, |p| plan.reach(&p.tile).start);
        while disjoint_done < until {
            let row = disjoint.take_first(zero);
            if seeds_needed {
                let mut values = Vec::with_capacity(shape.row_len());
                finish_row(&row, shape, plan.range, &mut values, &mut unused);
                *seeds.row_mut(disjoint_done, Vec::new) = values;
            }
            *sums.row_mut(disjoint_done, zero) = row;
            disjoint_done += 1;
        }
        // Rows no pending tile reaches: finished.
        let until =
            plan.shifted.get(next_shifted).map_or(disjoint_done, |p| plan.reach(&p.tile).start.min(disjoint_done));
        while put < until {
            let row = sums.take_first(zero);
            finish_row(&row, shape, plan.range, &mut out, &mut fill);
            sink.put_row(put, &out)?;
            put += 1;
        }
        seeds.drop_below(put);
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
    report.filled = fill.filled;
    report.uncovered = fill.uncovered;
    Ok(report)
}
