//! Sensing: which band each sensor pixel measures in each snapshot.
//!
//! Every mask is one-hot (a pixel integrates exactly one of the `bands` filter types per
//! snapshot) and, over `k` snapshots, sees `k` *distinct* bands at each sensor position.
//! Three mask families (`docs/design.md`, section 3):
//!
//! | family | band chosen per | separable |
//! | --- | --- | --- |
//! | [`MaskFamily::Kronecker`] (the paper's) | patch and snapshot, plus row shuffles | yes |
//! | [`MaskFamily::Lenslet`] | lenslet and snapshot | no |
//! | [`MaskFamily::Pixel`] | sensor pixel and snapshot | no |
//!
//! A firmware cannot store a band index per pixel of a full sensor, so a mask is a small
//! description: a seed (bands are drawn by hashing the seed with the pixel's, lenslet's or
//! patch's coordinates, so any pixel's bands are computed on demand in O(k)), or for the
//! pixel and lenslet families an explicit periodic [`BandTile`], which is how a calibrated
//! real filter array is described.
//!
//! The kronecker family follows the paper exactly: for the patch-aligned block of
//! `PS x PT` lenslets, `Phi5` is `k` one-hot rows (the block's bands), and `Phi1..Phi4`
//! are row-shuffled identities ([`KroneckerPhi`]); the measurement tensor is
//! `I = L x1 Phi1 .. x5 Phi5`. The shuffles only reorder measurements: the sensor pixel
//! `(s, t, u, v)` of the block still sees `L[s, t, u, v, band]`.

use core::fmt;

use crate::sensor::extent::{Array, Extent};

/// The largest number of bands (filter types) the decoder handles. It lives with the masks,
/// the lowest layer that counts bands; the patch shape names it too.
pub const MAX_BANDS: usize = 32;

/// The bands one sensor position sees, in snapshot order (distinct).
pub type BandList = heapless::Vec<u8, MAX_BANDS>;

/// Which mask family (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MaskFamily {
    Kronecker,
    Lenslet,
    Pixel,
}

/// Errors of the sensing layer: masks, band tiles, defect lists, raw frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensingError {
    /// Zero snapshots, or more snapshots than bands (k distinct bands are needed).
    Snapshots { snapshots: u8, bands: u8 },
    /// Zero bands or more than [`MAX_BANDS`].
    Bands { bands: u8 },
    /// A lenslet, patch block or tile with a zero dimension.
    EmptySize,
    /// A band tile's data length is not `snapshots * rows * cols`.
    TileLength { expected: u32, found: u32 },
    /// A band index not below the band count, at tile cell (row, col).
    BandOutOfRange { band: u8, row: u16, col: u16 },
    /// The same band twice at one tile cell across snapshots.
    RepeatedBand { band: u8, row: u16, col: u16 },
    /// A kronecker-only request on another family.
    NotKronecker,
    /// The patch type's lenslet block differs from the kronecker mask's block.
    BlockMismatch,
    /// A defect list that is not strictly increasing at this entry.
    DefectsUnsorted { index: u32 },
    /// A raw frame whose data length is not `rows * cols`.
    FrameSize { expected: u32, found: u32 },
    /// A response matrix with an entry that is not finite, a row that does not sum to a
    /// positive amount, or a condition number above
    /// [`MAX_CONDITION`](crate::sensor::response::MAX_CONDITION).
    Response,
}

impl fmt::Display for SensingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Snapshots { snapshots, bands } => {
                write!(f, "{snapshots} snapshots with {bands} bands (need 1..=bands distinct bands per pixel)")
            }
            Self::Bands { bands } => write!(f, "{bands} bands (need 1..={MAX_BANDS})"),
            Self::EmptySize => f.write_str("a lenslet, block or tile size is zero"),
            Self::TileLength { expected, found } => {
                write!(f, "band tile holds {found} entries, expected {expected}")
            }
            Self::BandOutOfRange { band, row, col } => {
                write!(f, "band {band} out of range at tile cell ({row}, {col})")
            }
            Self::RepeatedBand { band, row, col } => {
                write!(f, "band {band} repeated across snapshots at tile cell ({row}, {col})")
            }
            Self::NotKronecker => f.write_str("not a kronecker mask"),
            Self::BlockMismatch => f.write_str("patch block differs from the kronecker mask's"),
            Self::DefectsUnsorted { index } => {
                write!(f, "defect list not strictly increasing at entry {index}")
            }
            Self::FrameSize { expected, found } => {
                write!(f, "raw frame holds {found} samples, expected {expected}")
            }
            Self::Response => f.write_str(
                "response matrix not finite, a row not summing to a positive amount, or a condition number above 1e3",
            ),
        }
    }
}

impl core::error::Error for SensingError {}

/// Pixels under one lenslet: `rows x cols` views (`U x V`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LensletSize {
    pub rows: u8,
    pub cols: u8,
}

/// An explicit periodic pattern of band indices, layout `[snapshot][row][col]`.
///
/// For the pixel family the period is in sensor pixels, for the lenslet family in
/// lenslets. Checked at construction: every band is in range and the bands of one cell
/// are distinct across snapshots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BandTile<'a> {
    rows: u16,
    cols: u16,
    snapshots: u8,
    bands: &'a [u8],
}

impl<'a> BandTile<'a> {
    /// # Errors
    /// [`SensingError`] for a zero size, a wrong length, an out-of-range or repeated band.
    pub fn new(rows: u16, cols: u16, snapshots: u8, band_count: u8, bands: &'a [u8]) -> Result<Self, SensingError> {
        check_counts(snapshots, band_count)?;
        if rows == 0 || cols == 0 {
            return Err(SensingError::EmptySize);
        }
        let cells = rows as usize * cols as usize;
        let expected = cells * snapshots as usize;
        if bands.len() != expected {
            return Err(SensingError::TileLength { expected: expected as u32, found: bands.len() as u32 });
        }
        for cell in 0..cells {
            let (row, col) = ((cell / cols as usize) as u16, (cell % cols as usize) as u16);
            let mut seen = 0u32;
            for j in 0..snapshots as usize {
                // In range: the length was checked above (`get` says so without a panic path).
                let band = bands.get(j * cells + cell).copied().unwrap_or(u8::MAX);
                if band >= band_count {
                    return Err(SensingError::BandOutOfRange { band, row, col });
                }
                if seen & (1 << band) != 0 {
                    return Err(SensingError::RepeatedBand { band, row, col });
                }
                seen |= 1 << band;
            }
        }
        Ok(Self { rows, cols, snapshots, bands })
    }

    fn bands_at(&self, row: usize, col: usize) -> BandList {
        let cells = self.rows as usize * self.cols as usize;
        // `rows`, `cols` > 0 by construction; `checked_rem` says so without a panic path.
        let (r, c) = (row.checked_rem(self.rows as usize), col.checked_rem(self.cols as usize));
        let cell = r.unwrap_or(0) * self.cols as usize + c.unwrap_or(0);
        let mut list = BandList::new();
        for j in 0..self.snapshots as usize {
            let _ = list.push(self.bands.get(j * cells + cell).copied().unwrap_or(0));
        }
        list
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pattern<'a> {
    Seeded(u64),
    Tile(BandTile<'a>),
}

/// A one-hot spectral mask over the whole sensor, for `k` snapshots. Immutable: config.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mask<'a> {
    family: MaskFamily,
    pattern: Pattern<'a>,
    snapshots: u8,
    bands: u8,
    lenslet: LensletSize,
    /// Lenslets per kronecker block (the patch's `PS x PT`); (1, 1) otherwise.
    block: (u8, u8),
}

fn check_counts(snapshots: u8, bands: u8) -> Result<(), SensingError> {
    if bands == 0 || bands as usize > MAX_BANDS {
        return Err(SensingError::Bands { bands });
    }
    if snapshots == 0 || snapshots > bands {
        return Err(SensingError::Snapshots { snapshots, bands });
    }
    Ok(())
}

fn check_lenslet(l: LensletSize) -> Result<(), SensingError> {
    if l.rows == 0 || l.cols == 0 {
        return Err(SensingError::EmptySize);
    }
    Ok(())
}

/// SplitMix64's finaliser: a fast, well-mixed 64-bit hash step.
const fn mix(z: u64) -> u64 {
    let z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A deterministic stream of random numbers for one key under one seed.
struct Stream(u64);

impl Stream {
    fn new(seed: u64, tag: u64, a: usize, b: usize) -> Self {
        Self(mix(seed ^ mix((tag << 56) ^ ((a as u64) << 28) ^ b as u64)))
    }

    /// Uniform in `0..n` (n > 0; the modulo bias is below 2^-58).
    fn below(&mut self, n: usize) -> usize {
        self.0 = mix(self.0);
        self.0.checked_rem(n as u64).unwrap_or(0) as usize
    }

    /// The first `k` entries of a random permutation of `0..n` (partial Fisher-Yates).
    fn distinct(&mut self, k: usize, n: usize) -> BandList {
        let mut out = BandList::new();
        if k == 1 && n > 0 {
            // One draw: the permutation's first entry is where its first swap goes (the
            // loop below without its table, for a camera's single snapshot).
            let _ = out.push(self.below(n.min(MAX_BANDS)) as u8);
            return out;
        }
        let mut all = [0u8; MAX_BANDS];
        for (i, b) in all.iter_mut().enumerate() {
            *b = i as u8;
        }
        let n = n.min(MAX_BANDS);
        for j in 0..k.min(n) {
            // r < n <= MAX_BANDS; the `min` lets the compiler see it (no panic path).
            let r = (j + self.below(n - j)).min(MAX_BANDS - 1);
            all.swap(j, r);
            let _ = out.push(all[j]);
        }
        out
    }
}

const TAG_PIXEL: u64 = 1;
const TAG_LENSLET: u64 = 2;
const TAG_BLOCK: u64 = 3;
const TAG_SHUFFLE: u64 = 4;

impl<'a> Mask<'a> {
    /// `pixel` family from a seed: each sensor pixel draws its own `snapshots` bands.
    ///
    /// # Errors
    /// [`SensingError`] for bad counts or an empty lenslet.
    pub fn pixel(seed: u64, snapshots: u8, bands: u8, lenslet: LensletSize) -> Result<Self, SensingError> {
        Self::seeded(MaskFamily::Pixel, seed, snapshots, bands, lenslet, (1, 1))
    }

    /// `lenslet` family from a seed: every pixel under a lenslet shares its bands.
    ///
    /// # Errors
    /// [`SensingError`] for bad counts or an empty lenslet.
    pub fn lenslet(seed: u64, snapshots: u8, bands: u8, lenslet: LensletSize) -> Result<Self, SensingError> {
        Self::seeded(MaskFamily::Lenslet, seed, snapshots, bands, lenslet, (1, 1))
    }

    /// `kronecker` family (the paper's) from a seed, for patches of `block` = `(PS, PT)`
    /// lenslets: every pixel of a block shares the block's bands.
    ///
    /// # Errors
    /// [`SensingError`] for bad counts or an empty lenslet or block.
    pub fn kronecker(
        seed: u64,
        snapshots: u8,
        bands: u8,
        lenslet: LensletSize,
        block: (u8, u8),
    ) -> Result<Self, SensingError> {
        if block.0 == 0 || block.1 == 0 {
            return Err(SensingError::EmptySize);
        }
        Self::seeded(MaskFamily::Kronecker, seed, snapshots, bands, lenslet, block)
    }

    fn seeded(
        family: MaskFamily,
        seed: u64,
        snapshots: u8,
        bands: u8,
        lenslet: LensletSize,
        block: (u8, u8),
    ) -> Result<Self, SensingError> {
        check_counts(snapshots, bands)?;
        check_lenslet(lenslet)?;
        Ok(Self { family, pattern: Pattern::Seeded(seed), snapshots, bands, lenslet, block })
    }

    /// `pixel` family from an explicit tile whose period is in sensor pixels.
    ///
    /// # Errors
    /// [`SensingError::EmptySize`] for an empty lenslet.
    pub fn pixel_tile(tile: BandTile<'a>, bands: u8, lenslet: LensletSize) -> Result<Self, SensingError> {
        Self::tiled(MaskFamily::Pixel, tile, bands, lenslet)
    }

    /// `lenslet` family from an explicit tile whose period is in lenslets.
    ///
    /// # Errors
    /// [`SensingError::EmptySize`] for an empty lenslet.
    pub fn lenslet_tile(tile: BandTile<'a>, bands: u8, lenslet: LensletSize) -> Result<Self, SensingError> {
        Self::tiled(MaskFamily::Lenslet, tile, bands, lenslet)
    }

    fn tiled(family: MaskFamily, tile: BandTile<'a>, bands: u8, lenslet: LensletSize) -> Result<Self, SensingError> {
        check_counts(tile.snapshots, bands)?;
        check_lenslet(lenslet)?;
        // The tile was checked against its own band count; re-check against this one.
        let tile = BandTile::new(tile.rows, tile.cols, tile.snapshots, bands, tile.bands)?;
        Ok(Self { family, pattern: Pattern::Tile(tile), snapshots: tile.snapshots, bands, lenslet, block: (1, 1) })
    }

    /// The mask family.
    pub fn family(&self) -> MaskFamily {
        self.family
    }

    /// The lenslets `(rows, cols)` that see the same bands in a snapshot: a kronecker
    /// mask's block, `(1, 1)` on the others.
    pub fn block(&self) -> (u8, u8) {
        self.block
    }

    /// Snapshots `k`.
    pub fn snapshots(&self) -> usize {
        self.snapshots as usize
    }

    /// Band (filter type) count.
    pub fn bands(&self) -> usize {
        self.bands as usize
    }

    /// Views per lenslet.
    pub fn lenslet_size(&self) -> LensletSize {
        self.lenslet
    }

    /// The seed of a seeded mask.
    pub fn seed(&self) -> Option<u64> {
        match self.pattern {
            Pattern::Seeded(s) => Some(s),
            Pattern::Tile(_) => None,
        }
    }

    /// The `k` distinct bands sensor pixel `(row, col)` sees, in snapshot order.
    pub fn bands_at(&self, row: usize, col: usize) -> BandList {
        // Lenslet and block sizes are > 0 by construction; `checked_div` says so without a
        // panic path in the decoder.
        let div = |a: usize, b: u8| a.checked_div(b as usize).unwrap_or(0);
        let (lr, lc) = (div(row, self.lenslet.rows), div(col, self.lenslet.cols));
        let k = self.snapshots as usize;
        let n = self.bands as usize;
        match (self.pattern, self.family) {
            (Pattern::Tile(t), MaskFamily::Pixel) => t.bands_at(row, col),
            (Pattern::Tile(t), _) => t.bands_at(lr, lc),
            (Pattern::Seeded(seed), MaskFamily::Pixel) => Stream::new(seed, TAG_PIXEL, row, col).distinct(k, n),
            (Pattern::Seeded(seed), MaskFamily::Lenslet) => Stream::new(seed, TAG_LENSLET, lr, lc).distinct(k, n),
            (Pattern::Seeded(seed), MaskFamily::Kronecker) => {
                let (br, bc) = (div(lr, self.block.0), div(lc, self.block.1));
                Stream::new(seed, TAG_BLOCK, br, bc).distinct(k, n)
            }
        }
    }

    /// The band sensor pixel `(row, col)` sees in `snapshot` (`None` past the last).
    pub fn band(&self, snapshot: usize, row: usize, col: usize) -> Option<u8> {
        self.bands_at(row, col).get(snapshot).copied()
    }

    /// The paper's `Phi1..Phi5` for the kronecker block that holds sensor pixel `(row, col)`.
    ///
    /// # Errors
    /// [`SensingError::NotKronecker`] on another family, [`SensingError::BlockMismatch`] if
    /// `(PS, PT)` is not the mask's block.
    pub fn kronecker_phi<S: Extent, T: Extent, U: Extent, V: Extent>(
        &self,
        row: usize,
        col: usize,
    ) -> Result<KroneckerPhi<S, T, U, V>, SensingError> {
        let Pattern::Seeded(seed) = self.pattern else {
            return Err(SensingError::NotKronecker);
        };
        if self.family != MaskFamily::Kronecker {
            return Err(SensingError::NotKronecker);
        }
        if (self.block.0 as usize, self.block.1 as usize) != (S::D, T::D) {
            return Err(SensingError::BlockMismatch);
        }
        Ok(KroneckerPhi {
            shuffle1: shuffle::<S>(seed, 1),
            shuffle2: shuffle::<T>(seed, 2),
            shuffle3: shuffle::<U>(seed, 3),
            shuffle4: shuffle::<V>(seed, 4),
            bands: self.bands_at(row, col),
        })
    }
}

/// A seeded permutation of `0..D`: the row shuffle of `Phi_mode`, the same for every block.
fn shuffle<E: Extent>(seed: u64, mode: usize) -> E::Per<u8> {
    let mut p = E::Per::<u8>::splat(0);
    for (i, x) in p.as_mut().iter_mut().enumerate() {
        *x = i as u8;
    }
    let mut stream = Stream::new(seed, TAG_SHUFFLE, mode, E::D);
    for i in (1..E::D).rev() {
        let j = stream.below(i + 1);
        p.as_mut().swap(i, j);
    }
    p
}

/// The paper's separable sensing matrices for one patch-aligned block.
///
/// `Phi_i` (i = 1..4) is the identity with its rows shuffled: row `r` of `Phi_i` selects
/// column `shuffle_i[r]`. `Phi5` is `k x B`: row `j` is one-hot at `bands[j]`. So
/// `I[s, t, u, v, j] = L[shuffle1[s], shuffle2[t], shuffle3[u], shuffle4[v], bands[j]]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KroneckerPhi<S: Extent, T: Extent, U: Extent, V: Extent> {
    pub shuffle1: S::Per<u8>,
    pub shuffle2: T::Per<u8>,
    pub shuffle3: U::Per<u8>,
    pub shuffle4: V::Per<u8>,
    pub bands: BandList,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The partial Fisher-Yates over a whole table, as written before the one-draw path.
    fn reference(stream: &mut Stream, k: usize, n: usize) -> BandList {
        let mut all: [u8; MAX_BANDS] = core::array::from_fn(|i| i as u8);
        let n = n.min(MAX_BANDS);
        let mut out = BandList::new();
        for j in 0..k.min(n) {
            let r = (j + stream.below(n - j)).min(MAX_BANDS - 1);
            all.swap(j, r);
            let _ = out.push(all[j]);
        }
        out
    }

    /// Every count of draws and bands gives the table's bands, and leaves the stream where
    /// the table's walk leaves it.
    #[test]
    fn the_one_draw_path_is_the_permutations_first_entry() {
        for key in 0..2_000usize {
            for n in 0..=MAX_BANDS + 2 {
                for k in 0..=3 {
                    let (mut a, mut b) = (Stream::new(7, TAG_PIXEL, key, n), Stream::new(7, TAG_PIXEL, key, n));
                    assert_eq!(a.distinct(k, n), reference(&mut b, k, n), "key {key}, k {k}, n {n}");
                    assert_eq!(a.0, b.0, "key {key}, k {k}, n {n}: the streams part");
                }
            }
        }
    }
}
