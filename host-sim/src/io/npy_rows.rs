//! A light field's `.npy` file written as its rows come ([`NpyRows`]): the header first,
//! with the whole shape, then each block of rows at its place in every view's run of the
//! data, so the file is the one [`crate::io::lightfield::write_npy`] writes of the whole
//! light field, byte for byte, and `np.load(path, mmap_mode="r")` reads it without loading
//! it. Written whole ([`WholeFile`]): the destination changes only when the last row is in.

use std::io::{Seek, SeekFrom, Write};
use std::path::Path;

use anyhow::{Context, Result, ensure};
use npyz::WriterBuilder;

use crate::io::lightfield::Dtype;
use crate::io::output::WholeFile;
use crate::io::rows::{RowShape, RowSink, check_row, whole_width};

/// Bytes of rows gathered before they are written: each write is then one run per view
/// of many rows, not of one.
const BLOCK_BYTES: usize = 8 << 20;

/// A `(U, V, H, W, B)` light field's `.npy` file, its rows put in order ([`RowSink`]).
pub struct NpyRows {
    file: WholeFile,
    shape: RowShape,
    dtype: Dtype,
    /// Where the values start (the header's length).
    data: u64,
    /// Rows gathered, from `first`, each [`RowShape::row_len`] values as they are stored.
    block: Vec<u8>,
    first: usize,
    /// Rows put so far.
    next: usize,
    /// The largest value put (as decoded, before a uint16 file's rounding).
    max: f32,
}

impl NpyRows {
    /// The file for a light field of `shape`, stored as `dtype`: its header written.
    ///
    /// # Errors
    /// The file cannot be made in the destination's folder.
    pub fn create(path: &Path, shape: RowShape, dtype: Dtype) -> Result<Self> {
        let mut file = WholeFile::create(path)?;
        let dims: Vec<u64> = shape.shape().iter().map(|&x| x as u64).collect();
        let failed = || format!("cannot write {}", path.display());
        let f = file.file();
        match dtype {
            Dtype::F32 => {
                npyz::WriteOptions::<f32>::new().default_dtype().shape(&dims).writer(&mut *f).write_header_only()
            }
            Dtype::U16 => {
                npyz::WriteOptions::<u16>::new().default_dtype().shape(&dims).writer(&mut *f).write_header_only()
            }
        }
        .with_context(failed)?;
        let data = f.stream_position().with_context(failed)?;
        Ok(Self { file, shape, dtype, data, block: Vec::new(), first: 0, next: 0, max: 0.0 })
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.max
    }

    fn element(&self) -> usize {
        match self.dtype {
            Dtype::F32 => 4,
            Dtype::U16 => 2,
        }
    }

    /// Writes the gathered rows: per view, one run at its offset.
    fn flush_block(&mut self) -> Result<()> {
        let rows = self.next - self.first;
        if rows == 0 {
            return Ok(());
        }
        let run = self.shape.run_len() * self.element();
        let row_bytes = self.shape.row_len() * self.element();
        let views = self.shape.views.0 * self.shape.views.1;
        let mut out = Vec::with_capacity(rows * run);
        let path = self.file.path().display().to_string();
        for p in 0..views {
            out.clear();
            for r in 0..rows {
                out.extend_from_slice(&self.block[r * row_bytes + p * run..r * row_bytes + (p + 1) * run]);
            }
            let at = self.data + ((p * self.shape.rows + self.first) * run) as u64;
            let f = self.file.file();
            f.seek(SeekFrom::Start(at))
                .and_then(|_| f.write_all(&out))
                .with_context(|| format!("cannot write {path}"))?;
        }
        self.block.clear();
        self.first = self.next;
        Ok(())
    }

    /// Writes what is left and puts the file in place.
    ///
    /// # Errors
    /// Rows missing, or the I/O error.
    pub fn finish(mut self) -> Result<()> {
        ensure!(
            self.next == self.shape.rows,
            "cannot write {}: {} of {} rows decoded",
            self.file.path().display(),
            self.next,
            self.shape.rows
        );
        self.flush_block()?;
        self.file.persist()
    }
}

impl RowSink for NpyRows {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let y = usize::from(y);
        check_row(self.shape, self.next, y, row, self.file.path())?;
        // One pass a purpose, each a loop the compiler vectorises (a value at a time, the
        // maximum and the bytes together, this was 2 % of a preview's one-thread time).
        self.max = row.iter().fold(self.max, |m, &x| m.max(x));
        match self.dtype {
            Dtype::F32 => {
                self.block.reserve(4 * row.len());
                self.block.extend(row.iter().flat_map(|x| x.to_le_bytes()));
            }
            Dtype::U16 => {
                self.block.reserve(2 * row.len());
                self.block
                    .extend(row.iter().flat_map(|x| ((x.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes()));
            }
        }
        self.next += 1;
        if self.block.len() >= BLOCK_BYTES {
            self.flush_block()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::lightfield::{LightField, write_npy};

    /// The streamed file equals the one written whole, byte for byte, for both dtypes and
    /// for blocks of one row and of many; a file not finished leaves nothing.
    #[test]
    fn rows_written_as_they_come_make_the_file_written_whole() {
        let dir = tempfile::tempdir().unwrap();
        let (views, rows, cols, bands) = ((2, 3), 7, 5, 13);
        let lf = LightField::from_fn(views, rows, cols, bands, |u, v, y, x, b| {
            ((u * 7 + v * 5 + y * 3 + x * 2 + b) % 17) as f32 / 15.0
        });
        let shape = RowShape { views, rows, cols, bands };
        for dtype in [Dtype::F32, Dtype::U16] {
            let whole = dir.path().join("whole.npy");
            write_npy(&whole, &lf, dtype).unwrap();
            let streamed = dir.path().join("streamed.npy");
            let mut w = NpyRows::create(&streamed, shape, dtype).unwrap();
            for y in 0..rows {
                let mut row = vec![0.0; shape.row_len()];
                for u in 0..views.0 {
                    for v in 0..views.1 {
                        for x in 0..cols {
                            row[shape.at(u, v, x, 0)..][..bands].copy_from_slice(lf.spectrum(u, v, y, x));
                        }
                    }
                }
                crate::io::rows::put_row(&mut w, y, &row).unwrap();
                // Blocks of one row and of three, besides the default's one block.
                if y % 3 == 2 {
                    w.flush_block().unwrap();
                }
            }
            assert!(crate::io::rows::put_row(&mut w, rows, &vec![0.0; shape.row_len()]).is_err(), "a row past the end");
            w.finish().unwrap();
            assert_eq!(std::fs::read(&streamed).unwrap(), std::fs::read(&whole).unwrap(), "{dtype:?}");
        }
        let unfinished = dir.path().join("unfinished.npy");
        let mut w = NpyRows::create(&unfinished, shape, Dtype::F32).unwrap();
        crate::io::rows::put_row(&mut w, 0, &vec![0.5; shape.row_len()]).unwrap();
        assert!(crate::io::rows::put_row(&mut w, 2, &vec![0.5; shape.row_len()]).is_err(), "a row skipped");
        assert!(w.finish().is_err(), "rows missing");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert!(!unfinished.exists() && left.len() == 2, "left behind: {left:?}");
    }
}
