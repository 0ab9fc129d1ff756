//! Decoding captures: compressed sensing with the firmware's decoder, and the methods it
//! is measured against.
//!
//! - [`calibrate`]: a sensor's calibration from its calibration captures (`slf calibrate`);
//! - [`correction`]: a capture corrected by its calibration as its rows are read;
//! - [`grid_fit`]: the lenslet grid found from the calibration's flats (micro-image
//!   centres, then a least-squares grid);
//! - [`cs`]: the firmware's tile decoder over a capture in parallel (rayon), with
//!   overlapping patches, white balance, the noise model and the depth search, as asked by
//!   its [`options`]: a frame's [`plan`] made once, then its rows decoded down the frame by
//!   the [`strip`] (each tile's patches into `tile_sums`, the adaptive rule's [`seams`])
//!   and put to a sink as they are finished; what it did in its [`report`]; the error
//!   estimate of that decode from a second one with samples [`held_out`]; on a kronecker
//!   mask, each block mixed with PPID's by their held-out errors ([`blend`]);
//! - [`baselines`]: decode methods without compressed sensing (per-pixel interpolation, a
//!   neighbourhood demosaic, PPID);
//! - [`paper_1d`]: the paper's 1D method (explicit Kronecker matrices) and a 5D SL0 in f64,
//!   the references for the equivalence, speed and memory claims;
//! - [`device`]: the device binary's capture, and the check of its log against the host;
//! - [`preset`]: the named decodes (`preview`, `default`, `best`) on the speed-error curve;
//! - [`trial`]: the model trial, the DCT or the ensemble per region of the frame by
//!   their held-out errors on pilot patches;
//! - [`settings`]: what a user asks of a decode (`slf decode`'s flags, `slf.decode`'s
//!   keywords), parsed once and resolved to a basis and options;
//! - [`pipeline`]: those settings run on a capture: the checks that they fit it, the
//!   calibration's correction, then compressed sensing or a baseline into a sink.
//!
//! May use: [`crate::io`], [`crate::sim`]. Used by the train and eval layers.

pub mod baselines;
pub mod blend;
pub mod calibrate;
pub mod correction;
pub mod cs;
pub mod device;
pub mod grid_fit;
pub mod held_out;
pub mod options;
pub mod paper_1d;
pub mod pipeline;
pub mod plan;
pub mod preset;
pub mod report;
pub mod seams;
pub mod settings;
pub mod strip;
pub(crate) mod tile_sums;
pub mod trial;
