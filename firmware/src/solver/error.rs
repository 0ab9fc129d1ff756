//! The solver layer's error: why a patch could not be decoded.
//!
//! It lives in a file of its own, below everything else in the layer, because the
//! [`Workspace`](super::workspace::Workspace) (which checks measurements as they are set)
//! and every solver path return it: with it in `sl0` the workspace and the solver it
//! serves would name each other.

use core::fmt;

/// Errors of the solver layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SolveError {
    /// The patch has no valid measurement: nothing to decode.
    NoMeasurements,
    /// A config field is out of range.
    InvalidConfig { field: &'static str },
    /// A measurement index past the end of the patch.
    IndexOutOfRange,
    /// A measurement value that is NaN or infinite.
    NonFiniteMeasurement,
    /// The solution went non-finite (not expected for finite input; reported, not output).
    NonFiniteResult,
    /// The general (pseudo-inverse) path needs every entry its kronecker `Phi` selects
    /// measured, and nothing else.
    IncompleteKronecker,
    /// The SVD behind a pseudo-inverse did not converge (`mode` 1..=5).
    PseudoInverse { mode: u8 },
    /// An ensemble member could not be read (not expected of a validated ensemble).
    NoSuchMember,
    /// Band gains that are not finite and positive, or more than `MAX_BANDS` of them.
    BadGains,
    /// Half-pixel shears (interpolating measurements) with a response matrix that mixes
    /// bands: the projection of the two together is not built.
    MixedHalfViews,
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NoMeasurements => f.write_str("patch has no valid measurement"),
            Self::InvalidConfig { field } => {
                write!(f, "solver config field `{field}` out of range")
            }
            Self::IndexOutOfRange => f.write_str("measurement index outside the patch"),
            Self::NonFiniteMeasurement => f.write_str("measurement is not finite"),
            Self::NonFiniteResult => f.write_str("solution is not finite"),
            Self::IncompleteKronecker => {
                f.write_str("general path needs exactly the entries the kronecker mask selects")
            }
            Self::PseudoInverse { mode } => {
                write!(f, "pseudo-inverse of mode {mode} did not converge")
            }
            Self::NoSuchMember => f.write_str("ensemble member could not be read"),
            Self::BadGains => f.write_str("band gains must be finite and positive, at most MAX_BANDS"),
            Self::MixedHalfViews => f.write_str("half-pixel shears with a response matrix that mixes bands"),
        }
    }
}

impl core::error::Error for SolveError {}
