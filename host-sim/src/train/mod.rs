//! The training layer: what the decoder learns from realistic training scenes.
//!
//! - [`ensemble`]: a dictionary ensemble (AMDE-style) into a firmware blob;
//! - [`schedule`]: the trained schedules of the solve (SL0 unrolled, its per-step
//!   parameters learned), stored with the ensemble in its blob.
//!
//! May use: io, sim, decode. Used by eval and the command line.

pub mod ensemble;
pub mod schedule;

// The ensemble's trainer by its path of before the folder, for the command line and tests.
pub use ensemble::*;
