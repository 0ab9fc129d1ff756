//! Measuring decodes: quality, previews, tables and speed against error.
//!
//! - [`metrics`]: PSNR, SSIM and spectral angle;
//! - [`preview`]: sRGB PNGs (CIE 1931 observer, D65);
//! - [`evaluation`]: every decode method on light fields a user brings (`slf evaluate`);
//! - [`report`]: the tables of `slf demo`, `slf sweep` and `slf compare`;
//! - [`mod@bench`]: the speed against error sweep (`slf bench`);
//! - [`device_frame`]: the device's frame figure beside it, from instruction counts.
//!
//! May use: every layer below (io, sim, decode, train). The top of the library.

pub mod bench;
pub mod device_frame;
pub mod evaluation;
pub mod metrics;
pub mod preview;
pub mod report;
