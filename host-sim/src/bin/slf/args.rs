//! Values that several commands share: ranges for clap. The mask family and the decode's
//! groups (basis, window, preset, white balance) are the library's
//! ([`slf_host::sim::settings`], [`slf_host::decode::settings`]), shared with the Python
//! package.

use anyhow::Result;

pub use slf_host::sim::flags::positive;
pub use slf_host::sim::settings::Family;

/// A whole number in `LO..=HI`, for clap: the error names the range (clap names the argument).
pub fn ranged<const LO: usize, const HI: usize>(s: &str) -> Result<usize, String> {
    let v: usize = s.parse().map_err(|_| format!("{s:?} is not a whole number in {LO}..={HI}"))?;
    if (LO..=HI).contains(&v) { Ok(v) } else { Err(format!("{v} is out of range {LO}..={HI}")) }
}
