//! Rows gathered into bands of whole chunks ([`RowBand`]): what the chunked outputs (HDF5,
//! Zarr) write at a time, so a file sink holds one band of rows, not the light field.

use std::path::Path;

use anyhow::Result;

use crate::io::rows::{RowShape, check_row};

/// Lenslet rows in a chunk of the chunked outputs, and in the band gathered before a write.
pub const BAND_ROWS: usize = 8;

/// Lenslet columns in a chunk: a chunk is every view and band of 8 x 128 lenslets (1.3 MB
/// at 5 x 5 views), so a reader takes a few rows of the frame without the rest.
pub const CHUNK_COLS: usize = 128;

/// The chunk shape of a `(U, V, H, W, B)` light field's chunked outputs.
pub fn chunk_shape(shape: RowShape) -> [usize; 5] {
    let [u, v, h, w, b] = shape.shape();
    [u, v, h.min(BAND_ROWS), w.min(CHUNK_COLS), b]
}

/// The rows of one band, laid out as the outputs store them: `(U, V, rows, W, B)`.
pub struct RowBand {
    shape: RowShape,
    values: Vec<f32>,
    /// The band's first row, and the next row to put.
    first: usize,
    next: usize,
    max: f32,
}

/// A full band, ready to write: rows `first..first + rows` of every view.
pub struct Band<'a> {
    pub first: usize,
    pub rows: usize,
    /// `U x V x rows x W x B` values.
    pub values: &'a [f32],
}

impl RowBand {
    /// An empty band for rows of `shape`, its size checked against the memory cap (`path`
    /// names the output in the message).
    ///
    /// # Errors
    /// An empty axis, or a band past the cap.
    pub fn new(shape: RowShape, path: &Path) -> Result<Self> {
        anyhow::ensure!(
            shape.shape().iter().all(|&d| d > 0),
            "cannot write {}: an empty axis in {:?}",
            path.display(),
            shape.shape()
        );
        let values = BAND_ROWS.min(shape.rows) * shape.row_len();
        crate::io::budget::check(
            values as u64 * 4,
            &format!("writing {} a band of {BAND_ROWS} rows at a time", path.display()),
            "decode a narrower frame",
        )?;
        Ok(Self { shape, values: vec![0.0; values], first: 0, next: 0, max: 0.0 })
    }

    /// Rows put so far.
    pub fn rows_put(&self) -> usize {
        self.next
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.max
    }

    /// Puts row `y` (the next, whole and finite: [`check_row`]); returns the band once it is
    /// full (its last rows at the frame's end), which is then written and done.
    ///
    /// # Errors
    /// As [`check_row`].
    pub fn put(&mut self, y: usize, row: &[f32], path: &Path) -> Result<Option<Band<'_>>> {
        check_row(self.shape, self.next, y, row, path)?;
        let run = self.shape.run_len();
        let rows = BAND_ROWS.min(self.shape.rows - self.first);
        let in_band = y - self.first;
        for (p, values) in row.chunks_exact(run).enumerate() {
            let at = (p * rows + in_band) * run;
            self.values[at..at + run].copy_from_slice(values);
            self.max = values.iter().fold(self.max, |m, &x| m.max(x));
        }
        self.next += 1;
        if self.next - self.first < rows {
            return Ok(None);
        }
        let first = self.first;
        self.first = self.next;
        let n = self.shape.views.0 * self.shape.views.1 * rows * run;
        Ok(Some(Band { first, rows, values: &self.values[..n] }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each band holds its rows at the places `(U, V, rows, W, B)` gives them, the last band
    /// is cut at the frame's end, and rows out of order are refused.
    #[test]
    fn bands_hold_their_rows_in_the_stored_order() {
        let shape = RowShape { views: (2, 1), rows: 11, cols: 3, bands: 2 };
        let path = Path::new("x");
        let mut band = RowBand::new(shape, path).unwrap();
        let value = |u: usize, y: usize, x: usize, b: usize| (1000 * u + 10 * y + x) as f32 + b as f32 / 10.0;
        let mut seen = Vec::new();
        for y in 0..11 {
            let row: Vec<f32> =
                (0..2).flat_map(|u| (0..3).flat_map(move |x| (0..2).map(move |b| value(u, y, x, b)))).collect();
            if let Some(full) = band.put(y, &row, path).unwrap() {
                for u in 0..2 {
                    for r in 0..full.rows {
                        for x in 0..3 {
                            for b in 0..2 {
                                let got = full.values[((u * full.rows + r) * 3 + x) * 2 + b];
                                assert_eq!(got, value(u, full.first + r, x, b));
                            }
                        }
                    }
                }
                seen.push((full.first, full.rows));
            }
        }
        assert_eq!(seen, [(0, 8), (8, 3)]);
        assert_eq!(band.rows_put(), 11);
        assert_eq!(band.max(), value(1, 10, 2, 1));
        let mut fresh = RowBand::new(shape, path).unwrap();
        assert!(fresh.put(1, &vec![0.0; shape.row_len()], path).is_err(), "row 1 before row 0");
        assert_eq!(chunk_shape(shape), [2, 1, 8, 3, 2]);
    }
}
