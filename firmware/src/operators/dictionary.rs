//! Dictionaries: five small orthonormal matrices, one per mode of a patch.
//!
//! A [`Dictionary`] is one member of the signal model `X = S x1 D1 x2 D2 .. x5 D5`: `D_i`
//! is `d_i x d_i`, its *columns* are the atoms of mode `i`, and `(S x_i D)[.. a ..] =
//! sum_c D[a][c] S[.. c ..]`. It also keeps each transpose, so both synthesis (by `D_i`)
//! and analysis (by `D_i^T`) read matrix rows contiguously in the hot loop; that costs 1 KiB
//! for the paper's patch and no per-call set-up.
//!
//! Construction is checked (finite, orthonormal to [`ORTHONORMAL_TOLERANCE`]); after that
//! the transforms trust the matrices. Dictionaries come from [`Dictionary::dct`] (a
//! compile-time table) or from a blob in flash (see [`crate::operators::blob`]).

use core::fmt;

use crate::operators::mode::{Fold, Mode, ModeMatrix};
use crate::operators::shape::Shape;

/// A mode's matrix and its checks, where integrators found them before the modes had a
/// file of their own.
pub use crate::operators::mode::{Matrix, PARITY_TOLERANCE, has_parity, orthonormality_error, transpose};

/// How far from orthonormal a matrix may be: every entry of `M M^T - I` within this.
pub const ORTHONORMAL_TOLERANCE: f32 = 1e-4;

/// Errors of the dictionary layer: building a dictionary and reading or writing a blob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DictionaryError {
    /// The blob is shorter than a header and checksum.
    TooShort { len: u32 },
    /// The blob does not start with the magic bytes `SLFD`.
    BadMagic,
    /// The blob's format version is not one this decoder reads.
    UnsupportedVersion { found: u16 },
    /// A reserved header field is not zero.
    ReservedNotZero,
    /// The blob's patch dimensions differ from the decoder's patch type.
    ShapeMismatch { found: [u16; 5] },
    /// Zero members, or (for a single [`Dictionary`]) more than one.
    MemberCount { found: u16 },
    /// The blob's length differs from what its header implies.
    LengthMismatch { expected: u32, found: u32 },
    /// The CRC-32 stored in the blob differs from the one computed over it.
    Checksum { stored: u32, computed: u32 },
    /// A matrix holds NaN or infinity (`mode` is 1..=5).
    NonFinite { member: u16, mode: u8 },
    /// A matrix is not orthonormal to [`ORTHONORMAL_TOLERANCE`] (`mode` is 1..=5).
    NotOrthonormal { member: u16, mode: u8 },
    /// `member(index)` past the end of an ensemble.
    NoSuchMember { index: u16, members: u16 },
    /// The output buffer cannot hold the blob.
    BufferTooSmall { needed: u32 },
    /// A trained schedule out of range (`part`: `steps`, `start`, `sigma`, `mu` or
    /// `weights`), or a schedule section of a length its step counts do not imply.
    BadSchedule { part: &'static str },
}

impl fmt::Display for DictionaryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooShort { len } => write!(f, "dictionary blob too short ({len} bytes)"),
            Self::BadMagic => f.write_str("not a dictionary blob (bad magic)"),
            Self::UnsupportedVersion { found } => {
                write!(f, "unsupported dictionary blob version {found}")
            }
            Self::ReservedNotZero => f.write_str("dictionary blob header has a non-zero reserved field"),
            Self::ShapeMismatch { found } => write!(
                f,
                "dictionary blob is for patches of {}x{}x{}x{}x{}, not this decoder's",
                found[0], found[1], found[2], found[3], found[4]
            ),
            Self::MemberCount { found } => write!(f, "dictionary blob has {found} members"),
            Self::LengthMismatch { expected, found } => {
                write!(f, "dictionary blob is {found} bytes, its header implies {expected}")
            }
            Self::Checksum { stored, computed } => {
                write!(f, "dictionary blob checksum mismatch (stored {stored:#010x}, computed {computed:#010x})")
            }
            Self::NonFinite { member, mode } => {
                write!(f, "member {member} mode {mode} holds a non-finite value")
            }
            Self::NotOrthonormal { member, mode } => {
                write!(f, "member {member} mode {mode} is not orthonormal")
            }
            Self::NoSuchMember { index, members } => {
                write!(f, "no member {index} in an ensemble of {members}")
            }
            Self::BufferTooSmall { needed } => {
                write!(f, "output buffer too small ({needed} bytes needed)")
            }
            Self::BadSchedule { part } => write!(f, "dictionary blob's trained schedule: bad {part}"),
        }
    }
}

impl core::error::Error for DictionaryError {}

/// Five matrices, one per mode: the dimensions of a patch in the types.
#[derive(Clone, Debug, PartialEq)]
pub struct Factors<S: Shape> {
    pub m1: ModeMatrix<S::S>,
    pub m2: ModeMatrix<S::T>,
    pub m3: ModeMatrix<S::U>,
    pub m4: ModeMatrix<S::V>,
    pub m5: ModeMatrix<S::Bands>,
}

impl<S: Shape> Factors<S> {
    /// Every matrix transposed.
    pub fn transposed(&self) -> Self {
        Self {
            m1: S::S::transpose(&self.m1),
            m2: S::T::transpose(&self.m2),
            m3: S::U::transpose(&self.m3),
            m4: S::V::transpose(&self.m4),
            m5: S::Bands::transpose(&self.m5),
        }
    }

    /// The first mode (1..=5) whose matrix holds a non-finite value.
    pub fn first_non_finite(&self) -> Option<u8> {
        fn finite<E: Mode>(m: &ModeMatrix<E>) -> bool {
            m.as_ref().iter().all(|row| row.as_ref().iter().all(|x| x.is_finite()))
        }
        [
            finite::<S::S>(&self.m1),
            finite::<S::T>(&self.m2),
            finite::<S::U>(&self.m3),
            finite::<S::V>(&self.m4),
            finite::<S::Bands>(&self.m5),
        ]
        .iter()
        .position(|ok| !ok)
        .map(|i| i as u8 + 1)
    }

    /// Per mode, the largest entry of `|M M^T - I|`.
    pub fn orthonormality_errors(&self) -> [f32; 5] {
        [
            S::S::orthonormality_error(&self.m1),
            S::T::orthonormality_error(&self.m2),
            S::U::orthonormality_error(&self.m3),
            S::V::orthonormality_error(&self.m4),
            S::Bands::orthonormality_error(&self.m5),
        ]
    }

    /// Checks every matrix is finite and orthonormal; `member` goes into the error.
    pub fn validate(&self, member: u16) -> Result<(), DictionaryError> {
        if let Some(mode) = self.first_non_finite() {
            return Err(DictionaryError::NonFinite { member, mode });
        }
        match self.orthonormality_errors().iter().position(|&e| e.is_nan() || e > ORTHONORMAL_TOLERANCE) {
            Some(i) => Err(DictionaryError::NotOrthonormal { member, mode: i as u8 + 1 }),
            None => Ok(()),
        }
    }
}

/// One member of the signal model: an orthonormal matrix per mode, with its transposes.
#[derive(Clone, Debug, PartialEq)]
pub struct Dictionary<S: Shape> {
    /// `D_i`: synthesis matrices (columns are atoms).
    pub(crate) d: Factors<S>,
    /// `D_i^T`: analysis matrices.
    pub(crate) t: Factors<S>,
    /// Per mode 1..=4, whether `D_i^T`'s rows are even or odd about their middle (the
    /// DCT-II's symmetry), which the transforms use to halve their multiplies.
    pub(crate) parity: [bool; 4],
}

impl<S: Shape> Dictionary<S> {
    /// The separable orthonormal 5D DCT; a `const fn`, so a `static` of it is a flash table.
    pub const fn dct() -> Self {
        const { S::CHECK };
        // Synthesis is the inverse DCT: D_i = C^T (columns of D_i are the cosine atoms).
        let d = Factors { m1: S::S::DCT_T, m2: S::T::DCT_T, m3: S::U::DCT_T, m4: S::V::DCT_T, m5: S::Bands::DCT_T };
        let t = Factors { m1: S::S::DCT, m2: S::T::DCT, m3: S::U::DCT, m4: S::V::DCT, m5: S::Bands::DCT };
        Self { d, t, parity: [true; 4] }
    }

    /// A dictionary from its synthesis matrices `D_1..D_5`.
    ///
    /// # Errors
    /// [`DictionaryError::NonFinite`] or [`DictionaryError::NotOrthonormal`] (member 0).
    pub fn new(d: Factors<S>) -> Result<Self, DictionaryError> {
        d.validate(0)?;
        Ok(Self::from_validated(d))
    }

    pub(crate) fn from_validated(d: Factors<S>) -> Self {
        const { S::CHECK };
        let t = d.transposed();
        let parity =
            [S::S::has_parity(&t.m1), S::T::has_parity(&t.m2), S::U::has_parity(&t.m3), S::V::has_parity(&t.m4)];
        Self { d, t, parity }
    }

    /// How synthesis folds each of modes 1..=4 (see [`crate::operators::transform`]).
    pub(crate) fn synthesis_folds(&self) -> [Fold; 4] {
        self.parity.map(|p| if p { Fold::Columns } else { Fold::Plain })
    }

    /// How analysis folds each of modes 1..=4.
    pub(crate) fn analysis_folds(&self) -> [Fold; 4] {
        self.parity.map(|p| if p { Fold::Rows } else { Fold::Plain })
    }

    /// Per mode 1..=4, whether the analysis matrix's rows are even or odd about their middle
    /// (`M[a][D-1-c] = (-1)^a M[a][c]` to [`PARITY_TOLERANCE`]), as the DCT-II's are; the
    /// transforms then use the symmetry and do about half the multiplies.
    pub fn parity(&self) -> [bool; 4] {
        self.parity
    }

    /// The synthesis matrices `D_1..D_5`.
    pub fn synthesis(&self) -> &Factors<S> {
        &self.d
    }

    /// The analysis matrices `D_1^T..D_5^T`.
    pub fn analysis(&self) -> &Factors<S> {
        &self.t
    }
}
