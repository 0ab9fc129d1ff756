//! The solver layer: one patch's measurements to one decoded patch.
//!
//! - [`error`]: [`SolveError`](error::SolveError), why a patch could not be decoded;
//! - [`workspace`]: the caller-owned [`Workspace`](workspace::Workspace), the decoder's
//!   whole RAM need, and the patch's [`Measurements`](workspace::Measurements). It lives
//!   here, not with the tile decoder, because every solver path works in it;
//! - [`ball`]: the noise ball a projection moves onto (per-measurement variance);
//! - [`ascent`]: SL0's ascent step on the coefficients;
//! - [`projection`]: the orthonormal fast path's projection onto the measurements;
//! - [`mixing`]: the projection for filters whose response matrix mixes bands (a pixel
//!   measures `k` rows of it: a `k x k` solve per pixel);
//! - [`fractional`]: the projection of half-pixel sheared patches, whose measurements
//!   interpolate the patch;
//! - [`shares`]: the projection behind a turned lenslet grid, whose measurements are the
//!   shares of the view cells their pixels cover;
//! - [`pinv`]: the paper's general pseudo-inverse path for kronecker masks;
//! - [`fill`]: the band-gain fill, a start for the cold solve that holds the patch's
//!   brightness and colour;
//! - [`holdout`]: held-out measurements, a patch's estimate of its own decode's error;
//! - [`plausible`]: the plausibility check, a decoded patch against the brightest
//!   measurements of its lenslets' neighbourhoods;
//! - [`sl0`]: Algorithm 1;
//! - [`sl0_config`]: its configuration and how a solve ended;
//! - [`choice`]: the ensemble's member choice per patch (exhaustive or screened);
//! - [`picked`]: two models, one of which decodes (the model trial's pick);
//! - [`interpolate`]: per-pixel spectral interpolation, for a patch that measures too few
//!   bands for SL0.
//!
//! May use: the sensor and operators layers. Used by the decode layer.

pub mod ascent;
pub mod ball;
pub mod choice;
pub mod error;
pub mod fill;
pub mod fractional;
pub mod holdout;
pub mod interpolate;
pub mod mixing;
pub mod picked;
pub mod pinv;
pub mod plausible;
pub mod projection;
pub mod shares;
pub mod sl0;
pub mod sl0_config;
pub mod workspace;
