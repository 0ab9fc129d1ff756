//! Patch geometry in the types.
//!
//! A patch is `PS x PT` lenslets x `PU x PV` views x `B` bands, stored row-major with the
//! band fastest: entry `(s, t, u, v, b)` is at [`PatchShape::index`]. Stable Rust cannot
//! write `[f32; PS * PT * PU * PV * B]`, so every buffer type also carries `N`, and a
//! `const { assert!(..) }` in each constructor checks `N` against the product at compile
//! time: a wrong `N` does not build.

/// The largest number of bands a patch may have: the sensor's (its filter types).
pub use crate::sensor::mask::MAX_BANDS;

/// The shape of a patch; a zero-sized marker with the constants and index arithmetic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PatchShape<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>;

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize>
    PatchShape<PS, PT, PU, PV, B, N>
{
    /// Sensor pixels of one patch (`PS * PT * PU * PV`).
    pub const PIXELS: usize = PS * PT * PU * PV;
    /// Values of one patch.
    pub const N: usize = N;
    /// The dimensions in mode order (1..=5 in the paper's numbering).
    pub const DIMS: [usize; 5] = [PS, PT, PU, PV, B];
    /// Multiply-adds of one separable transform (synthesis or analysis): `N * sum(d_i)`.
    pub const TRANSFORM_MACS: usize = N * (PS + PT + PU + PV + B);

    /// Compile-time check that the sizes agree; evaluated by every constructor.
    pub const CHECK: () = {
        assert!(PS > 0 && PT > 0 && PU > 0 && PV > 0 && B > 0, "patch dimensions must be positive");
        assert!(N == PS * PT * PU * PV * B, "N must equal PS * PT * PU * PV * B");
        assert!(B <= MAX_BANDS, "at most MAX_BANDS bands");
        assert!(N <= u16::MAX as usize, "a patch must have at most 65535 values");
    };

    /// Index of entry `(s, t, u, v, b)` in a patch buffer.
    #[inline(always)]
    pub const fn index(s: usize, t: usize, u: usize, v: usize, b: usize) -> usize {
        (((s * PT + t) * PU + u) * PV + v) * B + b
    }

    /// Index of the first band of pixel `(s, t, u, v)`; the pixel's bands follow it.
    #[inline(always)]
    pub const fn pixel_index(s: usize, t: usize, u: usize, v: usize) -> usize {
        Self::index(s, t, u, v, 0)
    }

    /// Inverse of [`index`](Self::index): `(s, t, u, v, b)` of a buffer index.
    pub const fn coordinates(index: usize) -> [usize; 5] {
        let b = index % B;
        let r = index / B;
        let v = r % PV;
        let r = r / PV;
        let u = r % PU;
        let r = r / PU;
        let t = r % PT;
        let s = r / PT;
        [s, t, u, v, b]
    }
}

/// The paper's patch: 5 x 5 lenslets x 4 x 4 views x 13 bands (N = 5200).
pub type PaperShape = PatchShape<5, 5, 4, 4, 13, 5200>;
/// Every view of a 5 x 5-pixel lenslet: 5 x 5 x 5 x 5 x 13 (N = 8125).
pub type FullViewShape = PatchShape<5, 5, 5, 5, 13, 8125>;
