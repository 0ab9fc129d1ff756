//! Decoding a capture on the workstation with the firmware's own tile decoder, in parallel
//! over tiles (rayon), one [`slf_firmware::Workspace`] per worker thread.
//!
//! The patch is 5 x 5 lenslets x `PU x PV` views x 13 bands, a decode setting
//! ([`PatchViews`]): the paper's 4 x 4-view window, or the full-view patch, every view of a
//! 5 x 5-view lenslet. Where a patch has fewer views than a lenslet, the decoder's
//! overlapping angular windows
//! each give an estimate of the shared views; so do the end-aligned edge tiles for the
//! lenslets they share with the grid, and (by default) the patch grids shifted by the
//! stride ([`DEFAULT_STRIDE`], [`Window::Tapered`]). Every estimate is averaged into the
//! light field with its window's weight. The solver's noise ball comes from the capture's
//! noise description unless told otherwise ([`NoiseSource`]).
//!
//! A frame's way through: its [`FramePlan`] (the decoder, the trials' picks, the tiles) is
//! made once, then [`decode_rows`] decodes it down the frame and puts each finished lenslet
//! row into a [`RowSink`]: a [`LightField`] in memory ([`decode_with`]), or a file as it
//! goes ([`decode_into`]), in the memory of a band of rows whatever the frame's height.

use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use slf_firmware::{HoldOut, Pick, Picked, Sl0Config};

use crate::decode::blend::{self, BaselineBlend};
use crate::decode::held_out::HeldOutDecode;
pub use crate::decode::options::{
    Balance, Basis, DEFAULT_STRIDE, DecodeOptions, EstimateBy, MAX_BLOB, NoiseSource, PatchViews, SolveSchedule,
    TrialBy, Window, read_blob,
};
use crate::decode::plan::{FramePlan, patch_estimates};
pub use crate::decode::plan::{ModelPick, tile_decoder};
pub use crate::decode::report::{
    BlendReport, DecodeReport, PatchDecoder, ShearTrialReport, TrialReport, disparity_per_lenslet, error_per_lenslet,
    estimated_psnr,
};
use crate::decode::strip::{Pass, decode_rows};
use crate::decode::trial::{DCT_LEAN, rms};
use crate::io::capture::Capture;
use crate::io::grid::OffSensor;
use crate::io::lightfield::LightField;
use crate::io::patch::{BANDS, HostDictionary, HostEnsemble, HostModel};
use crate::io::rows::{RowShape, Rows};

/// A dictionary of the paper's patch: 5 x 5 lenslets x 4 x 4 views x 13 bands.
pub type PaperDictionary = HostDictionary<4, 4, 5200>;
/// A dictionary of the full-view patch: 5 x 5 lenslets x 5 x 5 views x 13 bands.
pub type FullViewDictionary = HostDictionary<5, 5, 8125>;

/// Decodes `capture` with `basis` (see [`decode`]).
///
/// # Errors
/// An invalid blob, or what [`decode`] reports.
pub fn decode_with(capture: &Capture, basis: &Basis, opts: &DecodeOptions) -> Result<(LightField, DecodeReport)> {
    decode_with_observer(capture, basis, opts, &|_, _| {})
}

/// [`decode_with`], calling `observer` after each tile (see [`decode_observed`]).
///
/// # Errors
/// An invalid blob, or what [`decode`] reports.
pub fn decode_with_observer(
    capture: &Capture,
    basis: &Basis,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    let mut lf = empty_light_field(capture)?;
    let report = decode_into(capture, basis, opts, observer, &mut lf)?;
    Ok((lf, report))
}

/// [`decode_with_observer`], each finished lenslet row put into `sink` in order
/// ([`decode_picked_into`]): a frame of any size in the memory of a band of rows.
///
/// # Errors
/// An invalid blob, or what [`decode`] or the sink reports.
pub fn decode_into(
    capture: &Capture,
    basis: &Basis,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport> {
    match opts.patch_views_for(capture, basis)? {
        PatchViews::Four => decode_basis::<4, 4, 5200>(capture, basis, opts, observer, sink),
        PatchViews::Five => decode_basis::<5, 5, 8125>(capture, basis, opts, observer, sink),
    }
}

/// [`decode_with_observer`] for one patch shape.
fn decode_basis<const PU: usize, const PV: usize, const N: usize>(
    capture: &Capture,
    basis: &Basis,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport> {
    let trained = opts.schedule == SolveSchedule::Trained;
    match basis {
        // With the model trial, a DCT decode screens the shipped ensemble on pilots and
        // leans to the DCT: the ensemble only where its pilots clearly predict better.
        Basis::Dct if opts.model_trial => {
            let lean = ModelPick::Trial { towards: Pick::First, margin: DCT_LEAN };
            trial_decode::<PU, PV, N>(
                capture,
                None,
                slf_firmware::MemberChoice::Screened(slf_firmware::ChoiceRule::DEFAULT),
                lean,
                opts,
                observer,
                sink,
            )
        }
        Basis::Dct => {
            let dictionary = HostDictionary::<PU, PV, N>::dct();
            // The DCT takes the schedules of the shipped blob, whose cold one is trained on
            // the DCT's solves (the screen's).
            match ensemble::<PU, PV, N>(None)?.schedules().filter(|_| trained) {
                Some(schedules) => {
                    let model = slf_firmware::ScheduledDictionary { dictionary, schedules };
                    decode_observed_into::<PU, PV, N, _>(capture, &model, opts, observer, sink)
                }
                None => decode_observed_into::<PU, PV, N, _>(capture, &dictionary, opts, observer, sink),
            }
        }
        // The screened ensemble with the model trial: the model whose pilots err less, or
        // where they tie, the one the mask and snapshot count favour
        // ([`slf_firmware::tie_prior`]).
        Basis::Ensemble { blob, choice } if opts.model_trial => {
            let mask = capture.mask()?;
            let prior = ModelPick::UnlessTied { prior: slf_firmware::tie_prior(mask.family(), mask.snapshots()) };
            trial_decode::<PU, PV, N>(capture, blob.as_deref(), *choice, prior, opts, observer, sink)
        }
        Basis::Ensemble { blob, choice } => {
            let ensemble = ensemble::<PU, PV, N>(blob.as_deref())?;
            let model = slf_firmware::EnsembleModel::new(ensemble, *choice);
            let model = if trained { model } else { model.with_schedules(None) };
            decode_observed_into::<PU, PV, N, _>(capture, &model, opts, observer, sink)
        }
    }
}

/// The decode of the DCT or the ensemble of `blob` (the shipped one for `None`) with
/// `choice`, whichever the model trial picks by `pick`.
fn trial_decode<const PU: usize, const PV: usize, const N: usize>(
    capture: &Capture,
    blob: Option<&[u8]>,
    choice: slf_firmware::MemberChoice,
    pick: ModelPick,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport> {
    let model = slf_firmware::EnsembleModel::new(ensemble::<PU, PV, N>(blob)?, choice);
    let model = if opts.schedule == SolveSchedule::Trained { model } else { model.with_schedules(None) };
    // The trial's other model: the DCT the ensemble screens with, on its schedules.
    match model.scheduled_screen() {
        Some(dct) => decode_picked_into::<PU, PV, N, _, _>(capture, &dct, &model, pick, opts, observer, sink),
        None => {
            let dct = HostDictionary::<PU, PV, N>::dct();
            decode_picked_into::<PU, PV, N, _, _>(capture, &dct, &model, pick, opts, observer, sink)
        }
    }
}

/// The ensemble of `blob` (the shipped one of the patch for `None`) for `5 x 5 x PU x PV x
/// 13` patches.
///
/// # Errors
/// A blob that does not validate, or of the other patch (named, with the flag to change).
pub fn ensemble<const PU: usize, const PV: usize, const N: usize>(
    blob: Option<&[u8]>,
) -> Result<HostEnsemble<'_, PU, PV, N>> {
    let views = PatchViews::of_views(PU, PV).ok_or_else(|| anyhow!("no patch of {PU} x {PV} views"))?;
    let bytes = blob.unwrap_or(views.shipped_ensemble());
    if let Some(made) = PatchViews::of_blob(bytes).filter(|&m| m != views) {
        bail!(
            "the ensemble blob is for {} patches, this decode's patch is {} (--patch-views {views}): pass \
             --patch-views {made}, or train a blob for it with slf train --patch-views {views}",
            made.shape_name(),
            views.shape_name()
        );
    }
    HostEnsemble::<PU, PV, N>::new(bytes).map_err(|e| anyhow!("ensemble blob: {e}"))
}

/// Patches the CS decoder decodes in `capture` with `views`-view patches (every tile's
/// patches in every angular window): the unit that times per patch are given in, also for
/// methods without patches.
///
/// # Errors
/// A capture the decoder does not take.
pub fn patch_count(capture: &Capture, views: PatchViews) -> Result<u64> {
    fn count<const PU: usize, const PV: usize, const N: usize>(capture: &Capture) -> Result<u64> {
        let decoder = capture.decoder::<PU, PV, N>(Sl0Config::DEFAULT)?;
        let windows = decoder.windows().count() as u64;
        Ok(decoder.tiles((2, 2)).map(|t| u64::from(t.lenslet_rows / 5) * u64::from(t.lenslet_cols / 5) * windows).sum())
    }
    match views {
        PatchViews::Four => count::<4, 4, 5200>(capture),
        PatchViews::Five => count::<5, 5, 8125>(capture),
    }
}

/// Decodes every tile of `capture` with `model` (a dictionary or an ensemble); returns the
/// light field `(U, V, S, T, 13)`.
///
/// # Errors
/// A capture the decoder cannot take (band count, views, mask), with the reason.
pub fn decode<const PU: usize, const PV: usize, const N: usize, M: HostModel<PU, PV, N>>(
    capture: &Capture,
    model: &M,
    opts: &DecodeOptions,
) -> Result<(LightField, DecodeReport)> {
    decode_observed(capture, model, opts, &|_, _| {})
}

/// [`decode`], calling `observer` after each tile with (tiles done, tiles in the pass), from
/// the worker threads: a progress display of the caller's own (the Python package's
/// callback). The adaptive rule ([`DecodeOptions::adaptive`]) makes a second pass.
///
/// # Errors
/// As [`decode`].
pub fn decode_observed<const PU: usize, const PV: usize, const N: usize, M: HostModel<PU, PV, N>>(
    capture: &Capture,
    model: &M,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)> {
    decode_picked(capture, model, model, ModelPick::Given(Pick::Second), opts, observer)
}

/// [`decode_observed`] into `sink` ([`decode_picked_into`]).
///
/// # Errors
/// As [`decode`], or what the sink returns.
pub fn decode_observed_into<const PU: usize, const PV: usize, const N: usize, M: HostModel<PU, PV, N>>(
    capture: &Capture,
    model: &M,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport> {
    decode_picked_into(capture, model, model, ModelPick::Given(Pick::Second), opts, observer, sink)
}

/// [`decode_observed`] with two models: decoded by the one `pick` names, or by the one the
/// model trial picks for the frame ([`crate::decode::trial`]).
///
/// # Errors
/// As [`decode`].
pub fn decode_picked<const PU: usize, const PV: usize, const N: usize, A, Z>(
    capture: &Capture,
    first: &A,
    second: &Z,
    pick: ModelPick,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
) -> Result<(LightField, DecodeReport)>
where
    A: HostModel<PU, PV, N>,
    Z: HostModel<PU, PV, N>,
{
    let mut lf = empty_light_field(capture)?;
    let report = decode_picked_into(capture, first, second, pick, opts, observer, &mut lf)?;
    Ok((lf, report))
}

/// The light field a decode of `capture` fills, zeros, its size checked first.
///
/// # Errors
/// A light field too large to hold ([`LightField::check_size`]).
pub fn empty_light_field(capture: &Capture) -> Result<LightField> {
    let d = &capture.description;
    RowShape { views: (d.views[0], d.views[1]), rows: d.lenslets[0], cols: d.lenslets[1], bands: BANDS }.zeros()
}

/// [`decode_picked`], each finished lenslet row put into `sink` in order as the decode goes
/// down the frame ([`crate::decode::strip`]): the memory it holds is a band of rows, not
/// the frame.
///
/// # Errors
/// As [`decode`], or what the sink returns.
pub fn decode_picked_into<const PU: usize, const PV: usize, const N: usize, A, Z>(
    capture: &Capture,
    first: &A,
    second: &Z,
    pick: ModelPick,
    opts: &DecodeOptions,
    observer: &(dyn Fn(usize, usize) + Sync),
    sink: &mut Rows<'_>,
) -> Result<DecodeReport>
where
    A: HostModel<PU, PV, N>,
    Z: HostModel<PU, PV, N>,
{
    let start = Instant::now();
    let raw = capture.raw_frames()?;
    let mut plan = FramePlan::<PU, PV, N>::new(capture, first, second, pick, opts, &raw)?;
    // The model trial by held-out decodes: both models' decodes of the frame made again
    // without one sample in eight, the pick by their errors at those (leaning as the
    // pilots' trial leans); the picked one's tallies are the error map's too.
    let mut estimated = None;
    let mut by_decode = None;
    // By decode, the frame's two errors alone have no spread: a tie is an equal pair.
    let lean = match pick {
        ModelPick::Trial { towards, margin } => Some((towards, margin)),
        ModelPick::UnlessTied { prior } => Some((prior.unwrap_or(Pick::Second), 1.0)),
        ModelPick::Given(_) => None,
    };
    if let (Some(_), TrialBy::Decode, true, Some((towards, margin))) =
        (plan.model_trial, opts.trial_by, plan.decoder.samples_are_values(), lean)
    {
        let held = Instant::now();
        let run =
            |pick| HeldOutDecode::run(&plan, &Picked { first, second, pick }, &raw, HoldOut::DEFAULT, opts.batch_tiles);
        let (a, z) = (run(Pick::First)?, run(Pick::Second)?);
        if let (Some(ea), Some(ez)) = (a.frame_error(), z.frame_error()) {
            let t = slf_firmware::PairedErrors::one((ea * ea) as f32, (ez * ez) as f32);
            plan.pick = t.pick_leaning(towards, margin);
            by_decode = Some((ea, ez));
        }
        estimated = Some((if plan.pick == Pick::First { a } else { z }, held.elapsed().as_secs_f64()));
    }
    let model = Picked { first, second, pick: plan.pick };
    // The baseline blend, measured before the decode whose rows it mixes as they come.
    let blending = Instant::now();
    // A blend that cannot be made (a fold that leaves PPID no measurement, the memory cap)
    // leaves the decode alone, and the report says why.
    let (blend, blend_skipped) = match opts.baseline_blend && blend::applies(&plan) {
        true => match BaselineBlend::measure(&plan, &model, capture, &raw, opts.batch_tiles) {
            Ok(b) => (Some(b), None),
            Err(e) => (None, Some(crate::io::message::one_line(&e))),
        },
        false => (None, None),
    };
    let blend_seconds = blending.elapsed().as_secs_f64();
    let pass = Pass { batch: opts.batch_tiles, progress: opts.progress, maps: opts.maps };
    let mut report = match &blend {
        Some(b) => {
            let mut rows = b.rows(sink, plan.shape);
            decode_rows(&plan, &model, &raw, pass, observer, &mut rows)?
        }
        None => decode_rows(&plan, &model, &raw, pass, observer, sink)?,
    };
    if opts.error_estimate && !patch_estimates(opts, &plan.decoder) {
        let held = Instant::now();
        let (map, seconds) = match (blend.as_ref(), estimated.take()) {
            // The blend's held-out decodes estimate the blended output, every sample held
            // out once: no decode more.
            (Some(b), _) => (b.held_out.map(), 0.0),
            (None, Some((d, s))) => (d.map(), s),
            (None, None) => (HeldOutDecode::run(&plan, &model, &raw, HoldOut::DEFAULT, opts.batch_tiles)?.map(), 0.0),
        };
        report.error_lenslets = map;
        report.estimate_seconds = seconds + held.elapsed().as_secs_f64();
    }
    report.blend_skipped = blend_skipped;
    report.blend = blend.map(|b| BlendReport { seconds: blend_seconds, weights: b.weights });
    report.seconds = start.elapsed().as_secs_f64();
    report.gains = *plan.decoder.gains();
    report.patch_views = PatchViews::of_views(PU, PV);
    report.grid = capture.description.turned_grid();
    report.off_sensor = plan.decoder.grid().map(|g| OffSensor::of(g, capture.description.lenslets)).unwrap_or_default();
    // The solves the trials' pilots ran, as they counted them.
    report.solves += u64::from(plan.shear_trial.map_or(0, |t| t.solves) + plan.model_trial.map_or(0, |t| t.solves));
    report.shear_trial = plan.shear_trial.map(|t| {
        let (half_error, whole_error) = rms(&t.errors);
        ShearTrialReport { pilots: t.errors.pilots, halves: !plan.alias, half_error, whole_error }
    });
    // Asked for with nothing to try: said, not silent.
    if opts.shear_trial && plan.shear_trial.is_none() {
        let d = plan.decoder.disparities();
        report.shear_trial_skipped = Some(if d.is_off() {
            "the decode searches no disparity".into()
        } else {
            format!("the decode's disparities, {}:{} in whole pixels, have no half-pixel step to try", d.min(), d.max())
        });
    }
    report.trial = plan.model_trial.map(|trial| {
        let t = trial.errors;
        let (dct_error, ensemble_error) = rms(&t);
        let tied = match pick {
            ModelPick::UnlessTied { prior } => by_decode.is_none() && t.takes_prior(prior),
            _ => false,
        };
        TrialReport { pilots: t.pilots, dct: plan.pick == Pick::First, dct_error, ensemble_error, tied, by_decode }
    });
    Ok(report)
}
