//! The overlapped decode, once for the host and the device: patches at a stride below the
//! patch's size, each estimate weighed by a [`Window`](window::Window) and averaged, the
//! shifted grids' patches started from the disjoint grid's decode (their seeds), a frame
//! decoded down its rows in bounded memory.
//!
//! Disjoint patches leave a grid at their borders, where each side was solved from a
//! different patch's measurements; overlapping patches averaged remove it (issue 17,
//! `docs/results-real.md`). The pieces, each a file, from the plan to the rows:
//!
//! - [`plan`]: where the tiles sit and the canonical order their sums join in ([`plan::Grids`]);
//! - [`schedule`]: which tiles are ready and which rows are final ([`schedule::Schedule`]);
//! - [`tile_sums`]: a tile's weighted sums on caller-owned slices, and the weighing of a
//!   patch's estimates;
//! - [`strip`]: the rows held, in one caller-owned buffer (sums, weights, seeds), finished
//!   into a [`rows::RowSink`];
//! - [`rows`]: the rows' layout, how a row is finished, the sink;
//! - [`band`]: a band of the sensor's columns decoded on its own, for a strip narrower than
//!   the sensor;
//! - [`window`]: how overlapping estimates are weighed;
//! - [`error`]: what the engine refuses.
//!
//! The drivers sit on top: the host decodes the ready tiles of a batch in parallel, each
//! into its [`tile_sums::TileSums`], and joins them in the plan's order; the device
//! ([`crate::decode::overlap::OverlapDecoder`]) decodes one tile at a time straight into
//! the strip, band by band. Both give each value the same estimates in the same order of
//! tiles; within a tile the host sums a tile's patches before they join the rows and the
//! device adds each patch to the rows, so the two agree to float rounding.

pub mod band;
pub mod error;
pub mod plan;
pub mod rows;
pub mod schedule;
pub mod strip;
pub mod tile_sums;
pub mod window;
