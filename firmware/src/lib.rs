//! The decoder of the slf compressive multispectral light-field camera.
//!
//! A lenslet array and a one-hot spectral filter mask over a monochrome sensor record a 5D
//! light field (2 spatial, 2 angular, `B` spectral bands) as one raw frame per snapshot.
//! This crate recovers the full spectral light field patch by patch by compressed sensing
//! in the signal's own five dimensions: a small orthonormal matrix per dimension, separable
//! operators, and the nD smoothed-l0 solver of Algorithm 1 of X. Cao, E. Miandji and
//! J. Unger, "Multidimensional Compressed Sensing for Spectral Light Field Imaging",
//! VISAPP 2024 (the repository's `docs/design.md` says where slf goes past it). It is
//! `no_std`, needs no heap, and is the code the host simulator calls, so host results are
//! the device's results.
//!
//! # Layers
//!
//! From the sensor to decoded patches, one folder each; a layer uses only the layers
//! before it (the repository's `tests/layers.rs` checks every `crate::` path):
//!
//! - **sensor** ([`sensor`]: [`extent`](sensor::extent), [`raw`], [`source`](sensor::source), [`defects`], [`grid`], [`spi`],
//!   [`mask`], [`gains`], [`response`]): an extent (bands, views, lenslets) as a type; samples, which of them are measurements, frames in memory or
//!   flash, a frame buffer read over `embedded-hal` SPI, the [`TileSource`] trait they all
//!   implement; the lenslet grid (where a real, turned lenslet array puts each view); which band each pixel sees in each snapshot (the three mask families
//!   `kronecker`, `lenslet`, `pixel`); the white balance, a gain per band that the decode
//!   divides out of the measurements and multiplies back; and the filters' [`response`]
//!   matrix, what a real filter lets through of each band.
//! - **operators** ([`operators`]: [`mode`], [`shape`], [`disparity`], [`dct`], [`dictionary`],
//!   [`schedule`], [`blob`], [`transform`]): the patch geometry as one type ([`Shape`], the one
//!   parameter of every solver function), one mode's matrix and the products by it, sheared patches that align
//!   the views on a depth, dictionaries (the 5D DCT and blobs in flash, with the trained
//!   schedules of their solves) and the separable
//!   synthesis and analysis transforms.
//! - **solver** ([`solver`]: [`error`](solver::error), [`workspace`], [`sl0`], [`ascent`],
//!   [`ball`], [`projection`], [`mixing`], [`fractional`], [`shares`], [`pinv`], [`fill`](solver::fill), [`choice`],
//!   [`picked`], [`interpolate`], [`plausible`], [`holdout`]): the caller-owned workspace every path works in, nD SL0 (its hand-set
//!   schedule, or the trained ones a blob carries) with the
//!   orthonormal fast path and its cold start from the band-gain fill, the
//!   noise ball a projection moves onto, the projection for filters whose response mixes
//!   bands (a `k x k` solve per pixel), the projection of half-pixel sheared patches (whose
//!   measurements interpolate them) and of patches behind a turned lenslet grid (whose
//!   pixels share view cells), the paper's general pseudo-inverse path for kronecker
//!   masks, the choice of an ensemble member per patch (exhaustive or screened, or seeded:
//!   one solve from an estimate of the patch), and per-pixel spectral interpolation for
//!   patches that measure too few distinct bands; the plausibility check of a decoded
//!   patch against what its measurements allow; a patch's estimate of its own error
//!   from measurements held out of a solve; and two models, one of which decodes.
//! - **decode** ([`decode`]: [`tile`], [`overlap`], [`trial`]): a rectangle of the raw frame, patch by
//!   patch, from a [`TileSource`] to a [`PatchSink`], into a caller-owned [`Workspace`]
//!   (each patch from nothing, or from a [`PatchSeed`]'s estimate); and
//!   patches at a stride below the patch size, averaged with a [`Window`] into a
//!   caller-owned strip of lenslet rows, finished rows to a [`RowSink`]; and the model
//!   trial, which of two models decodes a frame by their held-out errors on pilot patches.
//!
//! Each module is also at the crate root under its name of before the folders
//! (`slf_firmware::transform`, `slf_firmware::tile`, ...), so integrators' paths still hold.
//!
//! The device application sits on top of the tile decoder, in a crate of its own
//! (`slf-device`, in `firmware/device/` of the repository), so that this library depends on
//! nothing Cortex-M specific: no runtime, no critical-section implementation, no panic
//! handler. [`prelude`] is the front door: `use slf_firmware::prelude::*;` brings what an
//! integrator needs, with names for the paper's patch ([`PaperDecoder`], [`PaperPatch`]).
//!
//! # Panics
//!
//! None on any input: the decode path compiles to no panic call (CI counts the panic call
//! sites of a release device image that links every public decode entry point). The one
//! exception is set-up code, not decoding: [`pinv::PinvOperator::new`] runs nalgebra's SVD.
//!
//! # Example
//!
//! Decode one patch whose every pixel saw three bands, with the 5D DCT:
//!
//! ```
//! use slf_firmware::{Dictionary, PaperShape, PaperWorkspace, Shape, Sl0Config, solve};
//!
//! static DCT: Dictionary<PaperShape> = Dictionary::dct(); // a table in flash
//! let mut ws = PaperWorkspace::new(); // 66 KiB; on a device, a `static`
//! let truth = |b: usize| 0.2 + 0.05 * b as f32; // a smooth spectrum everywhere
//! for p in 0..PaperShape::PIXELS {
//!     for b in [(p * 5) % 13, (p * 5 + 4) % 13, (p * 5 + 9) % 13] {
//!         ws.measurements_mut().set(p * 13 + b, truth(b))?;
//!     }
//! }
//! let outcome = solve(&DCT, &Sl0Config::DEFAULT, &mut ws)?;
//! assert!(!outcome.hit_bound());
//! let worst = (0..5200).map(|i| (ws.patch()[i] - truth(i % 13)).abs()).fold(0.0, f32::max);
//! assert!(worst < 0.01, "max error {worst}");
//! # Ok::<(), slf_firmware::SolveError>(())
//! ```
//!
//! # Memory
//!
//! Configuration (dictionaries, masks, defect lists, solver parameters) is immutable and
//! can live in flash; all mutable state is one caller-owned [`Workspace`], whose size is the
//! decoder's whole RAM need besides the stack: four patch buffers (coefficients, signal,
//! measurements and their weights in a noise ball), a flag per value, a gain per band, the
//! filters' response matrix with its inverse and each pixel's place in its view cell behind a
//! lenslet grid, 91,176 bytes for the paper's 5 x 5 x 4 x 4 x 13 patch and 140,900 for the
//! full-view 5 x 5 x 5 x 5 x 13 patch ([`FullViewWorkspace`], the device's). Overlapping patches
//! ([`OverlapDecoder`], the device's driver of [`decode::engine`]) add a caller-owned strip
//! of lenslet rows: per lenslet column of 5 x 5 views and row held, 1,400 bytes (13 sums and
//! a weight a view), 2,700 seeded (and 13 seeds); the rows held are the schedule's
//! ([`OverlapDecoder::slots`]: 5 on the device's 5-row capture, 17 on a tall sensor with
//! the default shears), and a strip narrower than the sensor decodes it in bands
//! ([`OverlapDecoder::strip_len`]).
//!
//! # Errors
//!
//! One small `Copy` error enum per layer ([`DictionaryError`], [`SensingError`],
//! [`SolveError`], [`ConfigError`], [`TileError`]), each with `Display`,
//! `core::error::Error`, and `defmt::Format` with the `defmt` feature. Nothing reachable
//! from the public API panics on any input, and every loop is bounded: a solve that does
//! not converge says so in its [`Outcome`].
//!
//! # Features
//!
//! - `defmt`: log through defmt and derive `defmt::Format` on errors and reports. Off by
//!   default (host builds that call defmt need a global logger to link).
#![no_std]
#![forbid(unsafe_code)]

mod log;

pub mod decode;
pub mod operators;
pub mod sensor;
pub mod solver;

// Every module by its path of before the layer folders, for integrators' code.
pub use decode::{overlap, tile, trial};
pub use operators::{blob, dct, dictionary, disparity, mode, schedule, shape, transform};
pub use sensor::{defects, gains, grid, mask, raw, response, spi};
pub use solver::{
    ascent, ball, choice, fractional, holdout, interpolate, mixing, picked, pinv, plausible, projection, shares, sl0,
    workspace,
};

pub mod prelude;

// The public API at the root: what decoding needs, by layer. The operators' and the
// solver's internals (`transform::synthesize`, `projection::project_coefficients`,
// `blob::write_blob`, `pinv::solve_pinv`, `sl0::solve_warm`, ...) stay in their modules.
pub use decode::overlap::{Overlap, OverlapDecoder, OverlapError, OverlapReport, RowSink, Window};
pub use decode::tile::{
    Checked, ConfigError, DecoderConfig, FrameReport, NoSeed, PatchFlags, PatchOrigin, PatchReport, PatchSeed,
    PatchSink, ResponseModel, SensorGeometry, Tile, TileDecoder, TileError, TileReport,
};
pub use decode::trial::{ModelTrial, PairedErrors, ShearTrial, TIE_SPREAD, dct_where_tied, tie_prior};
pub use operators::blob::{DEFAULT_ENSEMBLE, DEFAULT_FULL_VIEW_ENSEMBLE, Ensemble};
pub use operators::dictionary::{Dictionary, DictionaryError};
pub use operators::disparity::{Disparity, DisparityRange};
pub use operators::shape::{FullViewShape, PaperShape, PatchShape, Shape};
pub use prelude::{PAPER_N, PaperDecoder, PaperDictionary, PaperEnsemble, PaperEnsembleModel, PaperPatch, SetupError};
pub use sensor::defects::{DefectList, Pixel};
pub use sensor::extent::{Array, BandCount, Bands, Extent, Fixed};
pub use sensor::grid::{GridError, LensletGrid};
pub use sensor::mask::{BandTile, LensletSize, Mask, MaskFamily, SensingError};
pub use sensor::raw::{Frame, FrameSource, LeU16Frame, RawFormat, RawFrame};
pub use sensor::response::Response;
pub use sensor::source::TileSource;
pub use sensor::spi::{SpiFrameBuffer, SpiSourceError};
pub use solver::choice::{ChoiceRule, EnsembleModel, MemberChoice, ModelOutcome, PatchModel, ScheduledDictionary};
pub use solver::holdout::HoldOut;
pub use solver::picked::{Pick, Picked};
pub use solver::plausible::Plausibility;
pub use solver::sl0::{Ended, Outcome, Sl0Config, SolveError, solve};
pub use solver::workspace::{FullViewWorkspace, Measurements, PaperWorkspace, Workspace};
