//! The decode layer: whole frames, tile by tile and patch by patch.
//!
//! - [`tile`]: the [`TileDecoder`](tile::TileDecoder), a rectangle of the raw frame patch
//!   by patch from a source to a [`PatchSink`](tile::PatchSink), with its configuration,
//!   the depth search per block and the reports per patch, tile and frame;
//! - [`overlap`]: patches at a stride below the patch size, averaged with a window into a
//!   caller-owned strip of lenslet rows, finished rows to a [`RowSink`](overlap::RowSink);
//! - [`trial`]: the model trial, which of two models decodes a region, by their held-out
//!   errors on pilot patches.
//!
//! May use: every layer below (sensor, operators, solver). Used by the device application
//! and the host, which sit on top in crates of their own.

pub mod overlap;
pub mod tile;
pub mod trial;
