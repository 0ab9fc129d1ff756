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

use crate::operators::dct::dct_matrix;

/// Which symmetry of a mode's matrix a mode product uses; found when its dictionary is
/// built ([`Dictionary::dct`], or checked in [`Dictionary::new`]).
///
/// The DCT-II's rows are even or odd about their middle, `C[a][D-1-c] = (-1)^a C[a][c]`.
/// A product by such a matrix first adds and subtracts the input's mirrored rows and then
/// needs about half the multiplies (13 instead of 25 for `D = 5`, 8 instead of 16 for
/// `D = 4`); on a core whose multiplier is the bottleneck that is about half the time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Fold {
    /// No symmetry used: `D^2` multiply-adds per column.
    Plain,
    /// Rows even or odd, `M[a][D-1-c] = (-1)^a M[a][c]` (the DCT-II: analysis).
    Rows,
    /// Columns even or odd, `M[D-1-n][k] = (-1)^k M[n][k]` (its transpose: synthesis).
    Columns,
}

/// A `D x D` matrix, row-major.
pub type Matrix<const D: usize> = [[f32; D]; D];

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
pub struct Factors<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize> {
    pub m1: Matrix<PS>,
    pub m2: Matrix<PT>,
    pub m3: Matrix<PU>,
    pub m4: Matrix<PV>,
    pub m5: Matrix<B>,
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize> Factors<PS, PT, PU, PV, B> {
    /// Every matrix transposed.
    pub const fn transposed(&self) -> Self {
        Self {
            m1: transpose(&self.m1),
            m2: transpose(&self.m2),
            m3: transpose(&self.m3),
            m4: transpose(&self.m4),
            m5: transpose(&self.m5),
        }
    }

    /// The first mode (1..=5) whose matrix holds a non-finite value.
    pub fn first_non_finite(&self) -> Option<u8> {
        let finite = |m: &[f32]| m.iter().all(|x| x.is_finite());
        [
            finite(self.m1.as_flattened()),
            finite(self.m2.as_flattened()),
            finite(self.m3.as_flattened()),
            finite(self.m4.as_flattened()),
            finite(self.m5.as_flattened()),
        ]
        .iter()
        .position(|ok| !ok)
        .map(|i| i as u8 + 1)
    }

    /// Per mode, the largest entry of `|M M^T - I|`.
    pub fn orthonormality_errors(&self) -> [f32; 5] {
        [
            orthonormality_error(&self.m1),
            orthonormality_error(&self.m2),
            orthonormality_error(&self.m3),
            orthonormality_error(&self.m4),
            orthonormality_error(&self.m5),
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

/// How far from even / odd a row may be for the transforms to use the symmetry: the
/// symmetric half of the row is what they read, so this bounds what they change.
pub const PARITY_TOLERANCE: f32 = 1e-6;

/// Whether every row `a` of `m` is even (`a` even) or odd about its middle to
/// [`PARITY_TOLERANCE`]: `m[a][D-1-c] = (-1)^a m[a][c]`, and so the middle entry of an odd
/// row of odd length is 0.
pub fn has_parity<const D: usize>(m: &Matrix<D>) -> bool {
    m.iter().enumerate().all(|(a, row)| {
        let sign = if a % 2 == 0 { 1.0 } else { -1.0 };
        (0..D).all(|c| (row[D - 1 - c] - sign * row[c]).abs() <= PARITY_TOLERANCE)
    })
}

/// The transpose of a square matrix.
pub const fn transpose<const D: usize>(m: &Matrix<D>) -> Matrix<D> {
    let mut t = [[0.0f32; D]; D];
    let mut i = 0;
    while i < D {
        let mut j = 0;
        while j < D {
            t[j][i] = m[i][j];
            j += 1;
        }
        i += 1;
    }
    t
}

/// The largest entry of `|M M^T - I|` (NaN if `M` holds NaN).
pub fn orthonormality_error<const D: usize>(m: &Matrix<D>) -> f32 {
    let mut worst = 0.0f32;
    for (i, ri) in m.iter().enumerate() {
        for (j, rj) in m.iter().enumerate() {
            let dot: f32 = ri.iter().zip(rj).map(|(a, b)| a * b).sum();
            let target = if i == j { 1.0 } else { 0.0 };
            let e = (dot - target).abs();
            if e.is_nan() || e > worst {
                worst = e; // also carries NaN out
            }
        }
    }
    worst
}

/// One member of the signal model: an orthonormal matrix per mode, with its transposes.
#[derive(Clone, Debug, PartialEq)]
pub struct Dictionary<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize> {
    /// `D_i`: synthesis matrices (columns are atoms).
    pub(crate) d: Factors<PS, PT, PU, PV, B>,
    /// `D_i^T`: analysis matrices.
    pub(crate) t: Factors<PS, PT, PU, PV, B>,
    /// Per mode 1..=4, whether `D_i^T`'s rows are even or odd about their middle (the
    /// DCT-II's symmetry), which the transforms use to halve their multiplies.
    pub(crate) parity: [bool; 4],
}

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize> Dictionary<PS, PT, PU, PV, B> {
    /// The separable orthonormal 5D DCT; a `const fn`, so a `static` of it is a flash table.
    pub const fn dct() -> Self {
        // Synthesis is the inverse DCT: D_i = C^T (columns of D_i are the cosine atoms).
        let c = Factors {
            m1: dct_matrix::<PS>(),
            m2: dct_matrix::<PT>(),
            m3: dct_matrix::<PU>(),
            m4: dct_matrix::<PV>(),
            m5: dct_matrix::<B>(),
        };
        Self { d: c.transposed(), t: c, parity: [true; 4] }
    }

    /// A dictionary from its synthesis matrices `D_1..D_5`.
    ///
    /// # Errors
    /// [`DictionaryError::NonFinite`] or [`DictionaryError::NotOrthonormal`] (member 0).
    pub fn new(d: Factors<PS, PT, PU, PV, B>) -> Result<Self, DictionaryError> {
        d.validate(0)?;
        Ok(Self::from_validated(d))
    }

    pub(crate) fn from_validated(d: Factors<PS, PT, PU, PV, B>) -> Self {
        let t = d.transposed();
        let parity = [has_parity(&t.m1), has_parity(&t.m2), has_parity(&t.m3), has_parity(&t.m4)];
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
    pub fn synthesis(&self) -> &Factors<PS, PT, PU, PV, B> {
        &self.d
    }

    /// The analysis matrices `D_1^T..D_5^T`.
    pub fn analysis(&self) -> &Factors<PS, PT, PU, PV, B> {
        &self.t
    }
}
