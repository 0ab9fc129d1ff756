//! Values and argument groups that several commands share: ranges for clap, the mask
//! family, the overlap window, the basis, the preset and the white balance.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;
use slf_host::decode::cs::{Balance, Basis, read_blob};
use slf_host::decode::preset::Preset;
use slf_host::firmware::{ChoiceRule, DEFAULT_ENSEMBLE, MaskFamily, MemberChoice};
use slf_host::io::capture::MaskDescription;

/// A whole number in `LO..=HI`, for clap: the error names the range (clap names the argument).
pub fn ranged<const LO: usize, const HI: usize>(s: &str) -> Result<usize, String> {
    let v: usize = s.parse().map_err(|_| format!("{s:?} is not a whole number in {LO}..={HI}"))?;
    if (LO..=HI).contains(&v) { Ok(v) } else { Err(format!("{v} is out of range {LO}..={HI}")) }
}

/// A finite number above zero, for clap.
pub fn positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a finite number above 0")),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Family {
    Pixel,
    Lenslet,
    Kronecker,
}

impl Family {
    pub fn family(self) -> MaskFamily {
        match self {
            Family::Pixel => MaskFamily::Pixel,
            Family::Lenslet => MaskFamily::Lenslet,
            Family::Kronecker => MaskFamily::Kronecker,
        }
    }

    pub fn mask(self, seed: u64, k: u8) -> MaskDescription {
        MaskDescription::seeded(self.family(), seed, k)
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum WindowArg {
    /// Every value of a patch counts the same.
    Uniform,
    /// Lenslets weigh 1, 2, 3, 2, 1 across a patch (per axis, multiplied).
    Tapered,
}

impl WindowArg {
    pub fn window(self) -> slf_host::decode::cs::Window {
        match self {
            WindowArg::Uniform => slf_host::decode::cs::Window::Uniform,
            WindowArg::Tapered => slf_host::decode::cs::Window::Tapered,
        }
    }
}

/// `--preset`: a named point on the speed-against-error curve
/// ([`slf_host::decode::preset`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PresetArg {
    /// Fast, for the camera's screen and batch triage: the DCT on disjoint patches,
    /// whole-pixel shears without the edge fallback, SL0 from the band-gain fill at 0.03
    /// of its largest coefficient to sigma 3e-3.
    Preview,
    /// The screened ensemble at stride 3 with the capture's disparities.
    Default,
    /// The default at stride 2: slower, measured to gain.
    Best,
}

impl PresetArg {
    pub fn preset(self) -> Preset {
        match self {
            PresetArg::Preview => Preset::Preview,
            PresetArg::Default => Preset::Default,
            PresetArg::Best => Preset::Best,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DictionaryKind {
    /// The 5D DCT.
    Dct,
    /// A learned ensemble (the shipped one unless --blob says otherwise).
    Ensemble,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Choice {
    /// Solve with the DCT, pick the member that best represents it, solve with that (2
    /// solves); where the DCT's own solution is sparser, average the two.
    Screened,
    /// As screened, but where the DCT's own solution is sparser, solve with the DCT again
    /// from the member's solution (3 solves).
    ScreenedResolve,
    /// Solve with every member, keep the sparsest (K + 1 solves).
    Exhaustive,
}

#[derive(clap::Args, Clone, Debug)]
pub struct BasisArgs {
    /// Basis to decode with [default: ensemble; dct with `slf decode --preset preview`].
    #[arg(long, value_enum)]
    dictionary: Option<DictionaryKind>,
    /// How an ensemble member is chosen per patch.
    #[arg(long, value_enum, default_value_t = Choice::Screened)]
    choice: Choice,
    /// Ensemble blob (default: the shipped 8-member ensemble).
    #[arg(long)]
    blob: Option<PathBuf>,
}

impl BasisArgs {
    pub fn basis(&self) -> Result<Basis> {
        self.basis_for(Preset::Default)
    }

    /// The basis the flags name, or `preset`'s where --dictionary is not given.
    pub fn basis_for(&self, preset: Preset) -> Result<Basis> {
        let preset_kind = if preset.uses_dct() { DictionaryKind::Dct } else { DictionaryKind::Ensemble };
        Ok(match self.dictionary.unwrap_or(preset_kind) {
            DictionaryKind::Dct => Basis::Dct,
            DictionaryKind::Ensemble => {
                let blob = match &self.blob {
                    Some(p) => read_blob(p)?,
                    None => DEFAULT_ENSEMBLE.to_vec(),
                };
                let rule = ChoiceRule::DEFAULT;
                let choice = match self.choice {
                    Choice::Screened => MemberChoice::Screened(rule),
                    Choice::ScreenedResolve => MemberChoice::ScreenedResolve(rule),
                    Choice::Exhaustive => MemberChoice::Exhaustive(rule),
                };
                Basis::Ensemble { blob, choice }
            }
        })
    }
}

/// `--balance`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BalanceArg {
    /// Each band's mean over the frame (grey world).
    Grey,
    /// No white balance (gains of 1).
    Off,
}

impl BalanceArg {
    pub fn balance(self) -> Balance {
        match self {
            Self::Grey => Balance::GreyWorld,
            Self::Off => Balance::Off,
        }
    }
}
