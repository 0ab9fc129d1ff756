//! A per-pixel map of a sensor (a calibration's dark levels or flats) as a decode reads it,
//! a few rows at a time ([`Map`]): held, or read from its `.npy` file. Apart from
//! [`crate::io::calibration`], which opens the maps, so a capture can name the flat its
//! frames were divided by ([`crate::io::capture::Capture::flat`]) without naming the
//! calibration.

use std::sync::Arc;

use anyhow::{Result, anyhow};

use crate::io::row_reader::{RowReader, by_bands};

/// A calibration's dark levels or flats as a corrected decode reads them, a few rows at a
/// time: held, or read from the calibration's file (a decode never holds its 8 bytes a
/// pixel).
#[derive(Clone, Debug)]
pub enum Map {
    /// Row-major, `cols` a row.
    Held(Arc<[f32]>, usize),
    File(RowReader),
}

impl Map {
    /// Values a row.
    pub fn cols(&self) -> usize {
        match self {
            Self::Held(_, cols) => *cols,
            Self::File(f) => f.size().1,
        }
    }

    /// Rows `first..first + out.len() / cols` into `out`.
    ///
    /// # Errors
    /// Rows past the end, or a read that fails, naming the file.
    pub fn read_rows(&self, first: usize, out: &mut [f32]) -> Result<()> {
        match self {
            Self::Held(v, cols) => {
                let at = first * cols;
                let part = v.get(at..at + out.len()).ok_or_else(|| anyhow!("rows {first}.. past the map's end"))?;
                out.copy_from_slice(part);
                Ok(())
            }
            Self::File(f) => f.read_f32(first, out),
        }
    }

    /// Calls `f(first row, values)` on the map's rows `rows x cols`, a band at a time.
    ///
    /// # Errors
    /// A read that fails, or what `f` returns.
    pub fn visit(&self, (rows, cols): (usize, usize), f: impl FnMut(usize, &[f32]) -> Result<()>) -> Result<()> {
        by_bands((rows, cols), MAP_BAND_ROWS, |first, part| self.read_rows(first, part), f)
    }
}

/// The rows of a map read at once where it is streamed (its checks, a corrected frame
/// held whole).
pub const MAP_BAND_ROWS: usize = 64;
