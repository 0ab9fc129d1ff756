//! The sensor layer: raw frames and what the camera's filters make of them.
//!
//! - [`extent`]: an extent (the bands, or the views or lenslets along an axis) as a type
//!   ([`Extent`](extent::Extent), [`Fixed`](extent::Fixed)), which containers sized by it
//!   are generic over;
//! - [`raw`]: samples and which of them are measurements (finite, not negative, not
//!   saturated), frames in RAM or flash, one [`FrameSource`](raw::FrameSource) per capture;
//! - [`source`]: the [`TileSource`](source::TileSource) trait every frame source implements;
//! - [`spi`]: a frame buffer read over `embedded-hal` SPI;
//! - [`defects`]: the sensor's defect list;
//! - [`mask`]: which band each pixel sees in each snapshot (the three mask families), and
//!   [`MAX_BANDS`](mask::MAX_BANDS);
//! - [`grid`]: the lenslet grid, where a real lenslet array puts each (lenslet, view);
//! - [`gains`]: the white balance, a gain per band;
//! - [`response`]: the filters' response matrix (what each filter lets through of each
//!   band), checked and inverted.
//!
//! May use: nothing of the crate but the logging shim. Everything above (operators, solver,
//! decode) may use it.

pub mod defects;
pub mod extent;
pub mod gains;
pub mod grid;
pub mod mask;
pub mod raw;
pub mod response;
pub mod source;
pub mod spi;
