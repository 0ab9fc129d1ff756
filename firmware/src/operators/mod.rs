//! The operators layer: the patch and the dictionaries it is sparse in.
//!
//! - [`mode`]: one mode's matrix as a type ([`mode::Mode`], for every
//!   [`Fixed`](crate::sensor::extent::Fixed) extent) and the mode products every transform
//!   is built of;
//! - [`shape`]: the patch geometry as one type ([`shape::Shape`]: `PS x PT` lenslets,
//!   `PU x PV` views, `B` bands, named once), which every buffer, dictionary and solve takes
//!   as its one type parameter, and its index arithmetic;
//! - [`disparity`]: sheared patches, whose views are shifted to align on a depth, and the
//!   consistency score that chooses the shear;
//! - [`dct`]: the orthonormal DCT-II matrices as compile-time tables;
//! - [`dictionary`]: one member, five small orthonormal matrices, checked when built;
//! - [`schedule`]: a trained schedule, SL0 unrolled to a fixed number of steps with
//!   learned parameters, which a blob carries with its dictionaries;
//! - [`blob`]: the ensemble's file format in flash (write, validate, read);
//! - [`transform`]: the separable synthesis and analysis transforms.
//!
//! May use: the sensor layer (band counts). Used by the solver and decode layers.

pub mod blob;
pub mod dct;
pub mod dictionary;
pub mod disparity;
pub mod mode;
pub mod schedule;
pub mod shape;
pub mod transform;
