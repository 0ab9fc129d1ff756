//! Presets: named points on the speed-against-error curve, so a user picks a decode by
//! what it is for instead of by a dozen solver flags.
//!
//! - [`Preset::Preview`]: the camera's screen and batch triage. The 5D DCT on the grid of
//!   disjoint patches, sheared to whole-pixel disparities (-1..=1) per block, every sheared
//!   block decoded unsheared as well for the values between blocks no sheared patch reached
//!   (the sheared fallback, which covers the edge fallback's), one solve a patch with the
//!   shipped blob's trained `alone` schedule (24 steps from the band-gain fill,
//!   [`slf_firmware::solver::fill`], sigma floored at `sigma_min = 3e-3`): a quarter of
//!   the default's patches, no half-pixel shears (their projection costs about 1.5 times a
//!   whole one's). With `--schedule annealed` it is the preview before the trained schedule:
//!   SL0 from the fill at 0.03 of its largest coefficient, about 50 steps. The model trial ([`crate::decode::trial`]) gives the
//!   frame to the screened ensemble where its pilots' held-out error is below
//!   [`crate::decode::trial::DCT_LEAN`] times the DCT's (leaning to the DCT, which costs
//!   about 0.6 of the ensemble's time on these patches).
//! - [`Preset::Default`]: the screened ensemble on full-view patches at stride 2 with the
//!   tapered window, the capture's disparities (half pixels at one snapshot), seeded, with
//!   the blob's trained schedules (24 steps the DCT's cold solve, 16 a member's or a seeded
//!   solve), the frame given to the DCT instead where the model trial's pilots say it
//!   predicts held-out measurements better ([`crate::decode::trial`]), and on a kronecker
//!   mask each block mixed with the PPID baseline's by their held-out errors
//!   ([`crate::decode::blend`]): what `slf decode` does unless told.
//! - [`Preset::Best`]: the default at stride 1, where every lenslet is covered by every
//!   patch that holds it: 25 instead of 9 times the disjoint grid's patches.
//!
//! Every preset decodes with the patch that fits the capture (the full-view patch on 5 x 5
//! views) unless `--patch-views` says otherwise.
//!
//! What each costs and gains is measured, not assumed: `slf bench` plots the presets as
//! named points, and `docs/bench/README.md` gives their table (PSNR, SSIM, SA and time on
//! the same scenes in one run).

use crate::decode::cs::{Basis, DecodeOptions, Window};
use slf_firmware::{DisparityRange, Sl0Config};

/// A named decode configuration: a basis and decode options.
///
/// The variants' docs are `slf decode --help`'s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// Fast, for the camera's screen and batch triage: the DCT on disjoint patches,
    /// whole-pixel shears with every sheared block decoded unsheared as well, one trained
    /// solve a patch from the band-gain fill (sigma floored at 3e-3); by the screened
    /// ensemble where pilot patches say it predicts clearly better.
    Preview,
    /// The screened ensemble at stride 2 with the capture's disparities (or the DCT, where
    /// the model trial's pilots favour it).
    Default,
    /// The default at stride 1: slower, measured to gain.
    Best,
}

impl Preset {
    /// Every preset, fastest first.
    pub const ALL: [Self; 3] = [Self::Preview, Self::Default, Self::Best];

    /// The preset's lower-case name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Preview => "preview",
            Self::Default => "default",
            Self::Best => "best",
        }
    }

    /// The decode options (progress off; callers set it).
    pub fn options(self) -> DecodeOptions {
        match self {
            Self::Preview => DecodeOptions {
                sl0: Sl0Config { sigma_min: 3e-3, cold_start: 0.03, ..Sl0Config::DEFAULT },
                stride: (5, 5),
                window: Window::Uniform,
                disparities: Some(DisparityRange::DEFAULT),
                edge_fallback: false,
                sheared_fallback: true,
                model_trial: true,
                ..DecodeOptions::default()
            },
            Self::Default => {
                DecodeOptions { model_trial: true, shear_trial: true, baseline_blend: true, ..DecodeOptions::default() }
            }
            Self::Best => DecodeOptions {
                stride: (1, 1),
                model_trial: true,
                shear_trial: true,
                baseline_blend: true,
                ..DecodeOptions::default()
            },
        }
    }

    /// The basis: the 5D DCT for the preview, the shipped ensemble of the decode's patch
    /// (screened) otherwise.
    pub fn basis(self) -> Basis {
        self.basis_with(None)
    }

    /// Whether the preset decodes with the 5D DCT (else with an ensemble).
    pub fn uses_dct(self) -> bool {
        self == Self::Preview
    }

    /// [`Self::basis`] with the ensemble `blob` in place of the shipped one (`None`: the
    /// shipped one).
    pub fn basis_with(self, blob: Option<&[u8]>) -> Basis {
        if self.uses_dct() {
            return Basis::Dct;
        }
        Basis::Ensemble {
            blob: blob.map(<[u8]>::to_vec),
            choice: slf_firmware::MemberChoice::Screened(slf_firmware::ChoiceRule::DEFAULT),
        }
    }
}
