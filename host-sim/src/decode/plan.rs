//! A frame's plan ([`FramePlan`]), made once before its rows are decoded: the firmware's
//! tile decoder with the capture's mask, noise model, white balance and disparities, the
//! trials' picks (half-pixel shears, DCT or ensemble), and the patch grids (the firmware
//! engine's [`Grids`]: the disjoint grid and the grids shifted by the stride, in the order
//! the strip decodes them, [`crate::decode::strip`]).

use crate::io::frames::SensorFrame;
use anyhow::{Result, anyhow, ensure};
use slf_firmware::decode::engine::plan::Grids;
use slf_firmware::{FrameSource, HoldOut, ModelTrial, PairedErrors, Pick, ShearTrial, Tile};

use crate::decode::options::{Balance, DecodeOptions, EstimateBy};
use crate::decode::trial::{frame_shear_trial, frame_trial, pilot_budget};
use crate::io::capture::Capture;
use crate::io::map::Map;
use crate::io::patch::{BANDS, HostDecoder, HostModel};
use crate::io::rows::RowShape;

/// What a decode of one frame does, decided before its first row.
pub struct FramePlan<'a, const PU: usize, const PV: usize, const N: usize> {
    /// The tile decoder, with the shear trial's disparities.
    pub decoder: HostDecoder<'a, PU, PV, N>,
    /// Which of the two models decodes the frame.
    pub pick: Pick,
    /// The patch grids: the disjoint grid's tiles row by row, the shifted grids' (with the
    /// adaptive rule: their single patches, the candidates) by first row; none at stride 5.
    pub grids: Grids,
    /// Start the shifted patches from the disjoint grid's decode.
    pub seeded: bool,
    /// Decode a shifted candidate only where its seam score is above this.
    pub adaptive: Option<f32>,
    /// The light field's rows.
    pub shape: RowShape,
    /// The sensor's range of decoded values.
    pub range: (f32, f32),
    /// How overlapping estimates are weighed.
    pub window: slf_firmware::overlap::Window,
    /// The shear trial, where it ran.
    pub shear_trial: Option<ShearTrial>,
    /// Whether the shear trial turned the half-pixel disparities off.
    pub alias: bool,
    /// The model trial, where it ran.
    pub model_trial: Option<ModelTrial>,
    /// The per-pixel flat the frames were divided by (a calibrated capture): the error
    /// estimate's noise term divides the raw noise by it.
    pub flat: Option<Map>,
}

impl<'a, const PU: usize, const PV: usize, const N: usize> FramePlan<'a, PU, PV, N> {
    /// The plan of `capture`'s decode by `first` or `second` as `pick` says, with `opts`:
    /// the checks, the decoder and the trials (which decode pilot patches of `raw`).
    ///
    /// # Errors
    /// A capture or options the decoder does not take, in one line.
    pub fn new<A, Z>(
        capture: &'a Capture,
        first: &A,
        second: &Z,
        pick: ModelPick,
        opts: &'a DecodeOptions,
        raw: &[SensorFrame<'_>],
    ) -> Result<Self>
    where
        A: HostModel<PU, PV, N>,
        Z: HostModel<PU, PV, N>,
    {
        let d = &capture.description;
        ensure!(d.bands_nm.len() == BANDS, "the decoder's patch has {BANDS} bands, the capture {}", d.bands_nm.len());
        if let Some(asked) = opts.patch_views {
            ensure!(
                asked.count() == PU && asked.count() == PV,
                "--patch-views {asked}: this decoder's patch has {PU} x {PV} views"
            );
        }
        ensure!(
            PU <= d.views[0] && PV <= d.views[1],
            "--patch-views {PU}: the capture's lenslets have {} x {} views, fewer than the patch's {PU} x {PV}",
            d.views[0],
            d.views[1]
        );
        let decoder = tile_decoder::<PU, PV, N>(capture, opts)?;
        ensure!(
            (1..=5).contains(&opts.stride.0) && (1..=5).contains(&opts.stride.1),
            "stride {:?}: each axis must be in 1..=5 lenslets",
            opts.stride
        );
        let base: Vec<Tile> = decoder.tiles(opts.tile_patches).collect();
        ensure!(
            !base.is_empty(),
            "the sensor ({} x {} lenslets) is smaller than one 5 x 5 patch",
            d.lenslets[0],
            d.lenslets[1]
        );
        let lenslets = (d.lenslets[0], d.lenslets[1]);
        let views = (d.views[0], d.views[1]);
        // The trials' pilots by the decode's patches: the disjoint grid's blocks times the
        // stride's shifts.
        let shifts = |s: u8| 5usize.div_ceil(usize::from(s));
        let blocks: usize =
            base.iter().map(|t| usize::from(t.lenslet_rows / 5) * usize::from(t.lenslet_cols / 5)).sum();
        let budget = pilot_budget(blocks * shifts(opts.stride.0) * shifts(opts.stride.1));
        // The shear trial first: half-pixel shears off for the frame where its pilots
        // estimate the whole ones clearly better (by `second`'s estimating solve, the one the
        // decode's error estimate runs: the ensemble's is its DCT on the alone schedule), so
        // the model trial's pilots are sheared as the decode will be.
        let shear_trial = (opts.shear_trial && decoder.disparities().has_halves())
            .then(|| frame_shear_trial(&decoder, second, raw, &base, budget));
        let alias = shear_trial.as_ref().is_some_and(ShearTrial::aliases);
        let decoder = if alias { decoder.with_disparities(decoder.disparities().with_halves(false)) } else { decoder };
        let (pick, model_trial) = match pick {
            ModelPick::Given(p) => (p, None),
            trial => {
                let t = frame_trial(&decoder, first, second, raw, &base, budget);
                (trial.of(&t.errors), Some(t))
            }
        };
        let halo = decoder.disparities().halo(views.0.max(views.1));
        // The shifted grids: every tile, or with the adaptive rule every single patch (the
        // candidates its seams choose from). Their canonical order is grid by grid; the
        // strip takes them by first row, the order their sums join the rows in.
        let tile = (opts.tile_patches.0.max(1), opts.tile_patches.1.max(1));
        let per = if opts.adaptive.is_some() { (1, 1) } else { tile };
        let grids = Grids::new(lenslets_u16(lenslets)?, (5, 5), opts.stride, tile, per, halo).map_err(|e| {
            anyhow!("tiles of {:?} and {per:?} patches at stride {:?}: {e}", opts.tile_patches, opts.stride)
        })?;
        let range = decoder.config().raw.range();
        Ok(Self {
            decoder,
            pick,
            grids,
            seeded: opts.seeds(),
            adaptive: opts.adaptive,
            shape: RowShape { views, rows: lenslets.0, cols: lenslets.1, bands: BANDS },
            range,
            window: opts.window,
            shear_trial,
            alias,
            model_trial,
            flat: capture.flat().cloned(),
        })
    }
}

/// Which of a decode's two models decodes the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelPick {
    /// The one named.
    Given(Pick),
    /// The one the model trial picks ([`slf_firmware::PairedErrors::pick_leaning`]): `towards` unless the
    /// other's pilots err below `margin` times its.
    Trial {
        /// The model kept on a tie or without pilots.
        towards: Pick,
        /// How far below (RMS) the other's error must be.
        margin: f32,
    },
    /// The one whose pilots err less, unless the two tie within the pilots' spread
    /// ([`slf_firmware::PairedErrors::pick_unless_tied`]); then `prior`, where there is one.
    UnlessTied {
        /// The model kept on a tie or without pilots.
        prior: Option<Pick>,
    },
}

impl ModelPick {
    /// The model this rule picks from the trial's errors `t` (the named one, whatever `t`).
    pub fn of(self, t: &PairedErrors) -> Pick {
        match self {
            Self::Given(p) => p,
            Self::Trial { towards, margin } => t.pick_leaning(towards, margin),
            Self::UnlessTied { prior } => t.pick_unless_tied(prior),
        }
    }
}

/// The firmware's tile decoder for `capture` as a decode runs it: the solver config of
/// [`DecodeOptions::solver_config`] and the band gains of [`DecodeOptions::balance`]
/// (estimated from the frame for [`Balance::GreyWorld`], as the device does).
///
/// # Errors
/// A capture the decoder cannot take, or gains outside `[1/64, 64]`.
pub fn tile_decoder<'a, const PU: usize, const PV: usize, const N: usize>(
    capture: &'a Capture,
    opts: &'a DecodeOptions,
) -> Result<HostDecoder<'a, PU, PV, N>> {
    let decoder = capture.decoder::<PU, PV, N>(opts.solver_config(capture))?;
    // The response first: the white balance's gains are of the unmixed spectrum.
    let decoder = match &opts.response {
        Some((response, model)) => {
            decoder.with_response(response, *model).map_err(|e| anyhow!("{}: {e}", capture.source()))?
        }
        None => decoder,
    };
    let gains = match opts.balance {
        Balance::Off => [1.0; BANDS],
        Balance::GreyWorld => {
            let raw = capture.raw_frames()?;
            decoder
                .estimate_gains(&mut FrameSource::new(&raw))
                .map_err(|e| anyhow!("{}: cannot read the frame for its white balance: {e:?}", capture.source()))?
        }
        Balance::Gains(g) => g,
    };
    let decoder = decoder.with_gains(&gains).map_err(|e| anyhow!("gains {gains:?}: {e}"))?;
    let decoder = decoder
        .with_error_estimate(patch_estimates(opts, &decoder).then_some(HoldOut::DEFAULT))
        .map_err(|e| anyhow!("{e}"))?
        .with_plausibility(opts.plausibility)
        .map_err(|e| anyhow!("--plausible {}:{}: {e}", opts.plausibility.factor, opts.plausibility.margin))?;
    Ok(decoder
        .with_disparities(opts.disparities_for(capture))
        .with_edge_fallback(opts.edge_fallback)
        .with_sheared_fallback(opts.sheared_fallback)
        .with_shear_check(opts.shear_check))
}

/// Whether the decode estimates each patch's error ([`EstimateBy::Patches`], or where the
/// held-out decode cannot compare samples with the light field).
pub fn patch_estimates<const PU: usize, const PV: usize, const N: usize>(
    opts: &DecodeOptions,
    decoder: &HostDecoder<'_, PU, PV, N>,
) -> bool {
    opts.error_estimate && (opts.estimate_by == EstimateBy::Patches || !decoder.samples_are_values())
}

/// The sensor's lenslets as a tile's `u16`s.
fn lenslets_u16((rows, cols): (usize, usize)) -> Result<(u16, u16)> {
    let fit = |n: usize| u16::try_from(n).map_err(|_| anyhow!("{rows} x {cols} lenslets: at most 65,535 a side"));
    Ok((fit(rows)?, fit(cols)?))
}
