//! A per-pixel map of a sensor (a calibration's dark levels or flats) as a decode reads it,
//! a few rows at a time ([`Map`]): held, or read from its `.npy` file. Apart from
//! [`crate::io::calibration`], which opens the maps, so a capture can name the flat its
//! frames were divided by ([`crate::io::capture::Capture::flat`]) without naming the
//! calibration.

use std::cell::RefCell;
use std::sync::Arc;

use anyhow::{Result, anyhow};
use slf_firmware::Frame;

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

    /// Rows.
    pub fn rows(&self) -> usize {
        match self {
            Self::Held(v, cols) => v.len() / (*cols).max(1),
            Self::File(f) => f.size().0,
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

/// A map as a frame the decoder reads a sample at a time ([`Frame`]: the flat a corrected
/// capture's frames were divided by, for the per-patch error estimate's noise term through
/// [`slf_firmware::FrameSource::with_flat`]). It holds a band of [`MAP_BAND_ROWS`] rows about
/// the last sample asked for, read again when a sample falls outside it: one a decode
/// thread, the band its own. A read that fails reads as no sample (the source takes the
/// flat as 1 there; the frames' correction reads the same file and fails the decode).
#[derive(Debug)]
pub struct MapFrame<'a> {
    map: &'a Map,
    /// The band's first row and its values.
    band: RefCell<(usize, Vec<f32>)>,
}

impl<'a> MapFrame<'a> {
    /// `map`, no row read yet.
    pub fn new(map: &'a Map) -> Self {
        Self { map, band: RefCell::new((0, Vec::new())) }
    }
}

impl Frame for MapFrame<'_> {
    fn size(&self) -> (usize, usize) {
        (self.map.rows(), self.map.cols())
    }

    fn sample(&self, i: usize) -> Option<f32> {
        let ((rows, cols), mut band) = (self.size(), self.band.try_borrow_mut().ok()?);
        let (row, col) = (i / cols.max(1), i % cols.max(1));
        if row >= rows {
            return None;
        }
        let (first, values) = &mut *band;
        if row < *first || (row - *first) * cols >= values.len() {
            let n = MAP_BAND_ROWS.min(rows);
            *first = row.saturating_sub(n / 2).min(rows - n);
            values.resize(n * cols, 0.0);
            if self.map.read_rows(*first, values).is_err() {
                values.clear();
                return None;
            }
        }
        values.get((row - *first) * cols + col).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map read as a frame, held or from its file: every sample, asked for in an order
    /// that jumps up and down the rows (each jump out of the band reads it again), is the
    /// map's value; past the end is no sample.
    #[test]
    fn a_map_frame_reads_every_sample_as_the_map_holds_it() {
        let (rows, cols) = (200, 3);
        let values: Vec<f32> = (0..rows * cols).map(|i| 0.3 + (i % 17) as f32 * 0.04).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("flat.npy");
        crate::io::lightfield::write_npy_f32_2d(&path, &values, rows, cols).unwrap();
        let file = RowReader::open_npy(&path, |_, _| Ok(())).unwrap().unwrap();
        for map in [Map::Held(values.clone().into(), cols), Map::File(file)] {
            let frame = MapFrame::new(&map);
            assert_eq!(frame.size(), (rows, cols));
            for k in 0..rows * cols {
                let i = (k * 7919) % (rows * cols);
                assert_eq!(frame.sample(i), Some(values[i]), "{map:?}: sample {i}");
            }
            assert_eq!(frame.sample(rows * cols), None);
        }
    }
}
