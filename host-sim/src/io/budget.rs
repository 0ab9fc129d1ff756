//! The memory a command may take, checked before the work starts against what its inputs
//! declare (an HDF5 dataset's shape, a training's scenes x size, a calibration's captures).
//!
//! Without it an input that declares more than the machine holds is found out by the
//! allocator, which aborts the process ("memory allocation of 1872000000 bytes failed",
//! SIGABRT) after minutes of work or with nothing said about which flag to change. The cap
//! is [`DEFAULT_CAP`] unless the command line's `--max-memory GIB` sets another
//! ([`set_cap`]), and never above the process's address-space limit (`ulimit -v`), read from
//! `/proc/self/limits` where there is one.

use std::sync::atomic::{AtomicU64, Ordering};

/// The default cap: 8 GiB, a third of the 24 GB workstation the product is measured on.
pub const DEFAULT_CAP: u64 = 8 << 30;

static CAP: AtomicU64 = AtomicU64::new(DEFAULT_CAP);

/// Sets the cap for the rest of the process (`--max-memory`).
pub fn set_cap(bytes: u64) {
    CAP.store(bytes, Ordering::Relaxed);
}

/// The cap in force: the set one, or the address-space limit when that is lower.
pub fn cap() -> u64 {
    let set = CAP.load(Ordering::Relaxed);
    address_space_limit().map_or(set, |l| set.min(l))
}

/// The soft address-space limit (`ulimit -v`), where `/proc/self/limits` gives one.
fn address_space_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

/// Checks that `need` bytes (an estimate of the command's peak, made from what its inputs
/// declare) fit the cap.
///
/// # Errors
/// One line: what needs how much, the cap, and the flags that change either.
pub fn check(need: u64, what: &str, smaller: &str) -> anyhow::Result<()> {
    let cap = cap();
    anyhow::ensure!(
        need <= cap,
        "{what} needs about {} of memory, more than the {} cap ({smaller}, or raise the cap with --max-memory GIB; \
         the default is 8 GiB, and never above ulimit -v)",
        gib(need),
        gib(cap)
    );
    Ok(())
}

/// `bytes` as "1.7 GiB".
pub fn gib(bytes: u64) -> String {
    let g = bytes as f64 / f64::from(1u32 << 30);
    // Under a tenth of a GiB in MiB: a cap of 0.01 GiB against 12 MB once read "about 0.0
    // GiB of memory, more than the 0.0 GiB cap".
    if g < 0.095 { format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20)) } else { format!("{g:.1} GiB") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cap_refuses_what_is_above_it_and_names_the_flags() {
        assert!(check(1 << 20, "a thing", "make it smaller").is_ok());
        let e = check(u64::MAX, "an HDF5 dataset of 5 x 5 x 1200 x 1200 x 13", "crop it").unwrap_err().to_string();
        assert!(e.starts_with("an HDF5 dataset of 5 x 5 x 1200 x 1200 x 13 needs about"), "{e}");
        assert!(e.contains("crop it, or raise the cap with --max-memory GIB"), "{e}");
        assert_eq!(gib(3 << 29), "1.5 GiB");
        assert_eq!(gib(1 << 30 >> 3), "0.1 GiB");
        assert_eq!(gib(13 << 20), "13.0 MiB");
        assert_eq!(gib(10_737_418), "10.2 MiB");
    }
}
