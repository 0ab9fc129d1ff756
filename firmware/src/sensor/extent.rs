//! An extent as a type: what a container sized by the bands, the views or the lenslets of
//! a patch is generic over (nalgebra's `Const<D>` and `Dim`).
//!
//! Stable Rust cannot size an array by an associated constant (`[f32; S::B]` needs
//! `generic_const_exprs`), so a type that carries a count also names its arrays: [`Extent`]
//! has `Per<T>`, which is `[T; D]` for [`Fixed<D>`]. Code generic over an extent indexes and
//! iterates those arrays through [`Array`]; after monomorphisation they are the same
//! fixed-size arrays, with the same loops (the decode's bits and instruction counts do not
//! move). A patch shape ([`crate::operators::shape::Shape`]) is five extents and its value
//! count, named once.

use core::fmt::Debug;
use core::ops::{Index, IndexMut};
use core::slice::SliceIndex;

/// A fixed-size array of `T`: `[T; K]` for some `K`, seen from code that cannot name `K`.
pub trait Array<T: Copy>:
    Copy + Debug + PartialEq + AsRef<[T]> + AsMut<[T]> + Index<usize, Output = T> + IndexMut<usize>
{
    /// Every entry `x`.
    fn splat(x: T) -> Self;

    // The slice methods generic code uses, which an array reaches by unsizing and a type
    // that only names an array cannot (each is the slice's own).

    /// The entries.
    #[inline(always)]
    fn iter(&self) -> core::slice::Iter<'_, T> {
        self.as_ref().iter()
    }
    /// The entries, to write.
    #[inline(always)]
    fn iter_mut(&mut self) -> core::slice::IterMut<'_, T> {
        self.as_mut().iter_mut()
    }
    /// Entry or entries `i`, if there are.
    #[inline(always)]
    fn get<'a, I: SliceIndex<[T]>>(&'a self, i: I) -> Option<&'a I::Output>
    where
        T: 'a,
    {
        self.as_ref().get(i)
    }
    /// Entry or entries `i`, if there are, to write.
    #[inline(always)]
    fn get_mut<'a, I: SliceIndex<[T]>>(&'a mut self, i: I) -> Option<&'a mut I::Output>
    where
        T: 'a,
    {
        self.as_mut().get_mut(i)
    }
    /// The number of entries.
    #[inline(always)]
    fn len(&self) -> usize {
        self.as_ref().len()
    }
    /// Whether there are none.
    #[inline(always)]
    fn is_empty(&self) -> bool {
        self.as_ref().is_empty()
    }
    /// Whether `x` is an entry.
    #[inline(always)]
    fn contains(&self, x: &T) -> bool
    where
        T: PartialEq,
    {
        self.as_ref().contains(x)
    }
    /// Runs of `n` entries (a shorter tail left out).
    #[inline(always)]
    fn chunks_exact(&self, n: usize) -> core::slice::ChunksExact<'_, T> {
        self.as_ref().chunks_exact(n)
    }
    /// Runs of `n` entries (a shorter tail left out), to write.
    #[inline(always)]
    fn chunks_exact_mut(&mut self, n: usize) -> core::slice::ChunksExactMut<'_, T> {
        self.as_mut().chunks_exact_mut(n)
    }
    /// Every entry `x`, in place.
    #[inline(always)]
    fn fill(&mut self, x: T) {
        self.as_mut().fill(x);
    }
    /// Copies `src` (of the same length) in.
    #[inline(always)]
    fn copy_from_slice(&mut self, src: &[T]) {
        self.as_mut().copy_from_slice(src);
    }
}

impl<T: Copy + Debug + PartialEq, const K: usize> Array<T> for [T; K] {
    #[inline(always)]
    fn splat(x: T) -> Self {
        [x; K]
    }
}

/// The extent of one mode of a patch (its bands, or the views or lenslets along one axis),
/// as a type.
pub trait Extent: Copy + Debug + Default + PartialEq + Eq + Send + Sync + 'static {
    /// The count.
    const D: usize;
    /// One `T` an index: `[T; D]`.
    type Per<T: Copy + Debug + PartialEq>: Array<T>;
    /// Every entry 0, for `const` constructors.
    const ZEROS: Self::Per<f32>;
    /// Every entry 1, for `const` constructors.
    const ONES: Self::Per<f32>;
    /// Every entry `false` (no value flagged), for `const` constructors.
    const NONE: Self::Per<bool>;
    /// The `D x D` zero matrix, for `const` constructors.
    const ZERO_MATRIX: Square<Self, f32>;
    /// `v` as whole runs of `D` (a shorter tail left out): a patch's pixels, when `Self`
    /// is its bands.
    fn chunks<T: Copy + Debug + PartialEq>(v: &[T]) -> &[Self::Per<T>];
    /// [`Self::chunks`], to write.
    fn chunks_mut<T: Copy + Debug + PartialEq>(v: &mut [T]) -> &mut [Self::Per<T>];
}

/// The extent `D`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Fixed<const D: usize>;

impl<const D: usize> Extent for Fixed<D> {
    const D: usize = D;
    type Per<T: Copy + Debug + PartialEq> = [T; D];
    const ZEROS: [f32; D] = [0.0; D];
    const ONES: [f32; D] = [1.0; D];
    const NONE: [bool; D] = [false; D];
    const ZERO_MATRIX: [[f32; D]; D] = [[0.0; D]; D];
    #[inline(always)]
    fn chunks<T: Copy + Debug + PartialEq>(v: &[T]) -> &[[T; D]] {
        v.as_chunks::<D>().0
    }
    #[inline(always)]
    fn chunks_mut<T: Copy + Debug + PartialEq>(v: &mut [T]) -> &mut [[T; D]] {
        v.as_chunks_mut::<D>().0
    }
}

/// The bands of a patch are an extent: a container over them is generic over `C: Bands`.
pub use self::Extent as Bands;

/// `B` bands.
pub type BandCount<const B: usize> = Fixed<B>;

/// One `T` an index of `E`.
pub type Per<E, T> = <E as Extent>::Per<T>;

/// A `D x D` matrix of `T` over `E` (rows, then columns): a mode's matrix.
pub type Square<E, T> = <E as Extent>::Per<<E as Extent>::Per<T>>;
