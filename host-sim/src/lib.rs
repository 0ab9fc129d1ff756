//! The workstation side of slf. It decodes with the firmware crate's own code
//! ([`slf_firmware`]), so host results are the device's results. The method is that of
//! X. Cao, E. Miandji and J. Unger, "Multidimensional Compressed Sensing for Spectral Light
//! Field Imaging", VISAPP 2024; [`baseline`] is that paper's 1D formulation.
//!
//! From a scene to numbers:
//!
//! - [`import`] brings real data in (views, hyperspectral cubes, other light fields) as
//!   the camera's 13 bands.
//! - [`scene`] renders synthetic spectral light fields ([`spectra`] holds measured and
//!   synthetic spectra), [`realistic`] draws scenes that look like the world; [`lightfield`] reads and writes them as `.npy` ([`npy`] reads
//!   any `.npy` with every size checked first).
//! - [`camera`] turns a light field into raw frames with the firmware's masks, noise,
//!   black level, quantisation, saturation and defects; [`capture`] is the folder format.
//! - [`decode`] runs the firmware's tile decoder over a capture in parallel; [`demosaic`]
//!   holds the baselines a user would pick instead of compressed sensing.
//! - [`metrics`] (PSNR, SSIM, SA), [`preview`] (sRGB PNGs) and [`baseline`] (the paper's 1D
//!   method) evaluate it.
//!
//! [`evaluation`] runs every method a user could pick (baselines, DCT, ensemble) on light
//! fields they bring. [`report`] holds the tables of `slf demo`, `sweep` and `compare`, [`mod@bench`] the speed
//! against error sweep; the `slf` command (`src/main.rs`) parses arguments and calls them.

pub use slf_firmware as firmware;

pub mod baseline;
pub mod bench;
pub mod camera;
pub mod capture;
pub mod decode;
pub mod demosaic;
pub mod device;
pub mod evaluation;
pub mod import;
pub mod lightfield;
pub mod metrics;
pub mod npy;
pub mod preview;
pub mod realistic;
pub mod report;
pub mod scene;
pub mod spectra;
pub mod spectra_data;
pub mod train;
