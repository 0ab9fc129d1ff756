//! The workstation side of slf. It decodes with the firmware crate's own code
//! ([`slf_firmware`]), so host results are the device's results. The method is that of
//! X. Cao, E. Miandji and J. Unger, "Multidimensional Compressed Sensing for Spectral Light
//! Field Imaging", VISAPP 2024; [`decode::paper_1d`] is that paper's 1D formulation.
//!
//! # Layers
//!
//! From files to numbers, one folder each; a layer uses only the layers before it (the
//! repository's `tests/layers.rs` checks every `crate::` path):
//!
//! - [`io`]: the files: any `.npy` read with every size checked first ([`io::npy`]), light
//!   fields ([`io::lightfield`]), the capture folder format ([`io::capture`]), and real data
//!   brought in as the camera's 13 bands ([`io::import`]: views, hyperspectral cubes, HDF5,
//!   other light fields).
//! - [`sim`]: the simulator: spectra ([`sim::spectra`]), synthetic test scenes
//!   ([`sim::scene`]) and scenes that look like the world ([`sim::realistic`]), and the
//!   camera model ([`sim::camera`]) that turns a light field into raw frames with the
//!   firmware's masks, noise, black level, quantisation, saturation and defects; the flags
//!   of `slf simulate` and `slf import` ([`sim::settings`], [`sim::import`]).
//! - [`decode`]: the firmware's tile decoder over a capture in parallel ([`decode::cs`]),
//!   the baselines a user would pick instead of compressed sensing ([`decode::baselines`]),
//!   the paper's 1D method ([`decode::paper_1d`]), the device binary's capture and check
//!   ([`decode::device`]), the named decodes `preview`, `default`, `best`
//!   ([`decode::preset`]) and `slf decode`'s flags ([`decode::settings`]).
//!
//! The `settings` types are `clap` argument groups that parse from strings as well, so the
//! `slf` command and the Python package (`python/`) take the same flags with the same
//! defaults, ranges and messages.
//! - [`train`]: learning a dictionary ensemble into a firmware blob.
//! - [`eval`]: metrics (PSNR, SSIM, SA), sRGB previews, every method on light fields a user
//!   brings ([`eval::evaluation`]), the tables of `slf demo`, `sweep` and `compare`
//!   ([`eval::report`]) and the speed against error sweep ([`eval::bench`]).
//!
//! The `slf` command (`src/bin/slf/`) sits on top: one file per command, each parsing its
//! arguments and calling the library.

pub use slf_firmware as firmware;

// First: its `outln!` is for every layer above.
#[macro_use]
pub mod io;

pub mod decode;
pub mod eval;
pub mod sim;
pub mod train;
