//! The decode layer: whole frames, tile by tile and patch by patch.
//!
//! - [`tile`]: the [`TileDecoder`](tile::TileDecoder), a rectangle of the raw frame patch
//!   by patch from a source to a [`PatchSink`](tile::PatchSink) (`tile/sink.rs`), with its
//!   configuration and decode loop (`tile/mod.rs`), the sensor read (`tile/read.rs`), the
//!   checks on a decoded patch and the depth search per block (`tile/checks.rs`) and the
//!   reports per patch, tile and frame (`tile/report.rs`);
//! - [`engine`]: the overlapped decode, once for the host and the device: patches at a
//!   stride below the patch size, seeded from the disjoint grid's decode, averaged with a
//!   window into a caller-owned strip of lenslet rows, finished rows to a
//!   [`RowSink`](engine::rows::RowSink);
//! - [`overlap`]: the device's driver of the engine, a tile at a time, band by band;
//! - [`trial`]: the model trial, which of two models decodes a region, by their held-out
//!   errors on pilot patches.
//!
//! May use: every layer below (sensor, operators, solver). Used by the device application
//! and the host, which sit on top in crates of their own.

pub mod engine;
pub mod overlap;
pub mod tile;
pub mod trial;
