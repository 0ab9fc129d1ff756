//! Speed against error: `slf bench`.
//!
//! For each mask family and k, a one-factor-at-a-time sweep around the default solver:
//! `sigma_f`, `L`, `sigma_min`, the noise-aware stop, the basis (DCT, ensemble exhaustive,
//! ensemble screened) and the precision (the f32 decoder against an f64 reference that
//! runs through the same tile pipeline). Every point records PSNR / SSIM / SA (mean over the
//! scenes) and time per patch on one thread and on all threads. Output: a CSV, a markdown
//! table with the Pareto front (per mask family: no other point is both faster and better)
//! marked, and a PNG plot of PSNR against time per patch, one curve per mask family, on
//! which the presets (`slf decode --preset`) and the baselines are labelled by name.
//!
//! Each point also gives a frame figure: the seconds a 512 x 512-pixel-per-view frame
//! (the paper's scale, 5 x 5 views) takes on one core at that point's time per patch of
//! the disjoint grid; with the device's counts ([`crate::eval::device_frame`]) the table
//! also gives the projected seconds of a 100 x 100-lenslet frame on the device.
//!
//! - [`model`]: the f64 reference decoder the precision points compare with;
//! - [`run`](mod@run): the sweep's settings and their decodes, timed;
//! - [`table`]: the points as CSV and markdown, the Pareto front, read back;
//! - [`plot`]: PSNR against time per patch as PNG.

pub mod model;
pub mod plot;
pub mod run;
pub mod table;

pub use model::F64Dct;
pub use run::{BenchOptions, paper_scale, run};
pub use table::{mark_pareto, read_points, redraw, write};

use crate::decode::baselines::Baseline;

/// One point of the sweep.
#[derive(Clone, Debug)]
pub struct Point {
    pub mask: String,
    pub k: u8,
    pub setting: String,
    pub psnr: f64,
    pub ssim: f64,
    pub sa: f64,
    /// Milliseconds per patch of the disjoint grid (a frame's cost over its disjoint
    /// patches) on one thread.
    pub ms_one: f64,
    /// Milliseconds of wall time per patch of the disjoint grid on all threads.
    pub ms_all: f64,
    /// Solves per patch of the disjoint grid.
    pub solves: f64,
    /// Seconds for a [`FRAME_LENSLETS`]-square frame (5 x 5 views) on one thread, at
    /// [`Self::ms_one`] per patch of its disjoint grid.
    pub frame_s: f64,
    pub pareto: bool,
}

/// Lenslets per side of the frame figure: 512 x 512 pixels per view, the paper's scale.
pub const FRAME_LENSLETS: u64 = 512;

/// Patches of the disjoint grid of a [`FRAME_LENSLETS`]-square frame with `windows`
/// angular windows: the decoder's 5 x 5-lenslet blocks that fit, as [`patch_count`] counts
/// them.
pub fn frame_patches(windows: u64) -> u64 {
    (FRAME_LENSLETS / 5).pow(2) * windows
}

/// The name a point is labelled with on the plot: a preset's or a baseline's; other
/// points are the sweep around them and stay unlabelled.
pub fn label(setting: &str) -> Option<&str> {
    setting.strip_prefix("preset ").or_else(|| Baseline::ALL.iter().map(|b| b.name()).find(|&n| n == setting))
}

/// A label as the plot prints it: a baseline without its "baseline: " and its reference
/// ("PPID", not "baseline: PPID (Mihoubi et al. 2017)"); the colour names the series.
pub(crate) fn short(label: &str) -> &str {
    let name = label.strip_prefix("baseline: ").unwrap_or(label);
    name.split(" (").next().unwrap_or(name)
}

/// The PSNRs a bench table may hold, in dB: a plot's axis spans them in bounded time.
pub(crate) const PSNR_DB: (f64, f64) = (-1000.0, 1000.0);
/// The times per patch a bench table may hold, in ms: 1 ps to 11 days, 21 decades on the
/// plot's log axis.
pub(crate) const TIME_MS: (f64, f64) = (1e-9, 1e12);
