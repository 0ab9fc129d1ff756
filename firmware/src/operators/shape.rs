//! Patch geometry in the types.
//!
//! A patch is `PS x PT` lenslets x `PU x PV` views x `B` bands, stored row-major with the
//! band fastest: entry `(s, t, u, v, b)` is at [`Shape::index`]. A [`Shape`] names the five
//! extents once; every buffer, dictionary and solve takes it as its one type parameter.

/// The largest number of bands a patch may have: the sensor's (its filter types).
pub use crate::sensor::mask::MAX_BANDS;

use core::fmt::Debug;

use crate::operators::mode::{Fold, Matrix, Mode, ModeMatrix, mode_pixel};
use crate::sensor::extent::{Extent, Fixed};
use crate::sensor::response::StaticIdentity;

/// `N` patch values: the count of a patch's values is an extent too
/// ([`crate::sensor::extent`]), what the buffers of one patch's values are generic over.
pub type ValueCount<const N: usize> = Fixed<N>;

/// The shape of a patch: its five extents and its value count, named once, with the checks
/// and the index arithmetic. What every buffer, dictionary and solve is generic over (one
/// parameter, as nalgebra's matrices carry their dimensions); [`PatchShape`] is the one
/// implementation.
pub trait Shape: Copy + Debug + Default + PartialEq + Eq + Send + Sync + 'static {
    /// Lenslet rows (mode 1).
    type S: Mode;
    /// Lenslet columns (mode 2).
    type T: Mode;
    /// View rows (mode 3).
    type U: Mode;
    /// View columns (mode 4).
    type V: Mode;
    /// Bands (mode 5).
    type Bands: Mode + StaticIdentity;
    /// The values of one patch.
    type Values: Extent;
    /// One spatial slice of a patch (its values with the first index fixed, `N / PS` of
    /// them): the stack scratch of the slice-wise transforms.
    type Slice: Scratch;
    /// One lenslet of a patch (its views and bands, `PU * PV * B` values): a stack scratch
    /// of per-lenslet factors.
    type Lenslet: Scratch;
    /// One `T` a pixel of a patch, `[s][t][u][v]`.
    type PerPixel<T: Copy + Debug + PartialEq>: Pixels<T>;

    /// Lenslet rows of a patch.
    const PS: usize = <Self::S as Extent>::D;
    /// Lenslet columns.
    const PT: usize = <Self::T as Extent>::D;
    /// View rows.
    const PU: usize = <Self::U as Extent>::D;
    /// View columns.
    const PV: usize = <Self::V as Extent>::D;
    /// Bands.
    const B: usize = <Self::Bands as Extent>::D;
    /// Values of one patch.
    const N: usize = <Self::Values as Extent>::D;
    /// Sensor pixels of one patch (`PS * PT * PU * PV`).
    const PIXELS: usize = Self::PS * Self::PT * Self::PU * Self::PV;
    /// The dimensions in mode order (1..=5 in the paper's numbering).
    const DIMS: [usize; 5] = [Self::PS, Self::PT, Self::PU, Self::PV, Self::B];
    /// Multiply-adds of one separable transform (synthesis or analysis): `N * sum(d_i)`.
    const TRANSFORM_MACS: usize = Self::N * (Self::PS + Self::PT + Self::PU + Self::PV + Self::B);

    /// Compile-time check that the sizes agree. Evaluated where the state a solve needs is
    /// made ([`crate::solver::workspace::Workspace::new`] and every
    /// [`crate::operators::dictionary::Dictionary`]'s constructor), so no solve, transform
    /// or decode compiles for a shape that fails it.
    const CHECK: () = {
        assert!(
            Self::PS > 0 && Self::PT > 0 && Self::PU > 0 && Self::PV > 0 && Self::B > 0,
            "patch dimensions must be positive"
        );
        assert!(Self::N == Self::PIXELS * Self::B, "N must equal PS * PT * PU * PV * B");
        assert!(Self::B <= MAX_BANDS, "at most MAX_BANDS bands");
        assert!(Self::N <= u16::MAX as usize, "a patch must have at most 65535 values");
    };

    /// Index of entry `(s, t, u, v, b)` in a patch buffer.
    #[inline(always)]
    fn index(s: usize, t: usize, u: usize, v: usize, b: usize) -> usize {
        (((s * Self::PT + t) * Self::PU + u) * Self::PV + v) * Self::B + b
    }

    /// Index of the first band of pixel `(s, t, u, v)`; the pixel's bands follow it.
    #[inline(always)]
    fn pixel_index(s: usize, t: usize, u: usize, v: usize) -> usize {
        Self::index(s, t, u, v, 0)
    }

    /// Inverse of [`index`](Self::index): `(s, t, u, v, b)` of a buffer index.
    fn coordinates(index: usize) -> [usize; 5] {
        let b = index % Self::B;
        let r = index / Self::B;
        let v = r % Self::PV;
        let r = r / Self::PV;
        let u = r % Self::PU;
        let r = r / Self::PU;
        let t = r % Self::PT;
        let s = r / Self::PT;
        [s, t, u, v, b]
    }

    /// `dst = src x4 M` for the view-column mode, the one just before the bands: its
    /// kernel (`mode_pixel`) needs both extents as constants.
    fn pixel(m: &ModeMatrix<Self::V>, fold: Fold, src: &[f32], dst: &mut [f32]);
}

/// A stack scratch of patch values, zeroed, seen as its values in patch order.
pub trait Scratch: Copy {
    /// Every value zero.
    const ZERO: Self;
    /// The values in patch order.
    fn values(&mut self) -> &mut [f32];
}

impl<const PT: usize, const PU: usize, const PV: usize, const B: usize> Scratch for [[[[f32; B]; PV]; PU]; PT] {
    const ZERO: Self = [[[[0.0; B]; PV]; PU]; PT];
    #[inline(always)]
    fn values(&mut self) -> &mut [f32] {
        self.as_flattened_mut().as_flattened_mut().as_flattened_mut()
    }
}

impl<const PU: usize, const PV: usize, const B: usize> Scratch for [[[f32; B]; PV]; PU] {
    const ZERO: Self = [[[0.0; B]; PV]; PU];
    #[inline(always)]
    fn values(&mut self) -> &mut [f32] {
        self.as_flattened_mut().as_flattened_mut()
    }
}

/// One `T` a pixel of a patch, `[s][t][u][v]`, seen flat in the patch's pixel order.
pub trait Pixels<T>: Copy + Debug {
    /// Every entry `x`.
    fn splat(x: T) -> Self;
    /// The entries in pixel order.
    fn flat(&self) -> &[T];
    /// The entries in pixel order, to write.
    fn flat_mut(&mut self) -> &mut [T];
}

impl<T: Copy + Debug, const PS: usize, const PT: usize, const PU: usize, const PV: usize> Pixels<T>
    for [[[[T; PV]; PU]; PT]; PS]
{
    #[inline(always)]
    fn splat(x: T) -> Self {
        [[[[x; PV]; PU]; PT]; PS]
    }
    #[inline(always)]
    fn flat(&self) -> &[T] {
        self.as_flattened().as_flattened().as_flattened()
    }
    #[inline(always)]
    fn flat_mut(&mut self) -> &mut [T] {
        self.as_flattened_mut().as_flattened_mut().as_flattened_mut()
    }
}

/// The shape of a patch with its extents as constants: the [`Shape`] every decoder names.
/// `N` is carried beside the five extents because stable Rust cannot write
/// `[f32; PS * PT * PU * PV * B]`; [`Shape::CHECK`], evaluated by every constructor,
/// refuses a wrong `N` at compile time:
///
/// ```compile_fail
/// use slf_firmware::{PatchShape, Workspace};
/// let ws = Workspace::<PatchShape<5, 5, 4, 4, 13, 5199>>::new(); // 5 * 5 * 4 * 4 * 13 is 5200
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PatchShape<
    const PS: usize,
    const PT: usize,
    const PU: usize,
    const PV: usize,
    const B: usize,
    const N: usize,
>;

impl<const PS: usize, const PT: usize, const PU: usize, const PV: usize, const B: usize, const N: usize> Shape
    for PatchShape<PS, PT, PU, PV, B, N>
{
    type S = Fixed<PS>;
    type T = Fixed<PT>;
    type U = Fixed<PU>;
    type V = Fixed<PV>;
    type Bands = Fixed<B>;
    type Values = Fixed<N>;
    type Slice = [[[[f32; B]; PV]; PU]; PT];
    type Lenslet = [[[f32; B]; PV]; PU];
    type PerPixel<T: Copy + Debug + PartialEq> = [[[[T; PV]; PU]; PT]; PS];

    #[inline(always)]
    fn pixel(m: &Matrix<PV>, fold: Fold, src: &[f32], dst: &mut [f32]) {
        mode_pixel::<PV, B>(m, fold, src.as_chunks::<B>().0, dst.as_chunks_mut::<B>().0);
    }
}

/// One `T` a value of a patch of shape `S`: `[T; N]`.
pub type PerValue<S, T> = <<S as Shape>::Values as Extent>::Per<T>;

/// One `T` a band of a patch of shape `S`: `[T; B]`.
pub type PerBand<S, T> = <<S as Shape>::Bands as Extent>::Per<T>;

/// The paper's patch: 5 x 5 lenslets x 4 x 4 views x 13 bands (N = 5200).
pub type PaperShape = PatchShape<5, 5, 4, 4, 13, 5200>;
/// Every view of a 5 x 5-pixel lenslet: 5 x 5 x 5 x 5 x 13 (N = 8125).
pub type FullViewShape = PatchShape<5, 5, 5, 5, 13, 8125>;
