//! The checks every file read goes through before it is opened: a regular file (a FIFO
//! blocks, a device may never end) of at most a stated size.

use std::fs;
use std::path::Path;

use anyhow::{Context, Result, anyhow, ensure};

/// Reads a regular file of at most `max` bytes as text; larger files, FIFOs and devices are
/// refused before reading.
///
/// # Errors
/// A message with the file and what is wrong.
pub fn read_small_file(path: &Path, max: u64) -> Result<String> {
    regular_file(path, max, "this file can need")?;
    fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// The size of `path`, checked before anything opens it: a regular file (opening a FIFO
/// blocks until a writer comes, a device may never end) of at most `max` bytes (`why` says
/// where the limit comes from).
///
/// # Errors
/// A message with the file and what is wrong.
pub fn regular_file(path: &Path, max: u64, why: &str) -> Result<u64> {
    let meta = fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    ensure!(meta.is_file(), "{}: not a regular file (a FIFO, device or folder is not read)", path.display());
    ensure!(meta.len() <= max, "{}: {} bytes, more than the {max} {why}", path.display(), meta.len());
    Ok(meta.len())
}

/// A frame file's size, `(rows, cols)` from its header, against the capture's (`expect`):
/// checked before its pixels are read (a sparse file or a small PNG can claim gigabytes).
///
/// # Errors
/// Another size, both named.
pub fn check_size(path: &Path, (rows, cols): (u64, u64), expect: Option<(usize, usize)>) -> Result<()> {
    match expect {
        Some((r, c)) if (rows, cols) != (r as u64, c as u64) => {
            Err(anyhow!("{}: frame is {rows} x {cols}, the capture's frames are {r} x {c}", path.display()))
        }
        _ => Ok(()),
    }
}
