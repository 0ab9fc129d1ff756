//! A light field's HDF5 file ([`Hdf5Rows`], `slf decode -o OUT.h5`): one chunked, optionally
//! deflate-compressed float32 dataset `lightfield` of shape `(U, V, H, W, B)`, its axes, the
//! band centres in nm and whatever the caller adds (the capture's description, the decode's
//! settings) as attributes; readable by h5py and by `slf import hdf5 OUT.h5 --dataset
//! lightfield --axes uvhwb`.
//!
//! The rows are gathered as they come and the file is written at [`Hdf5Rows::finish`]:
//! `hdf5-pure` (0.47) writes a dataset from memory, and appends only to rank-1 datasets, so
//! this sink holds the light field once (as its file's bytes), where the `.npy` sink
//! ([`crate::io::npy_rows`]) holds a block of rows. Written whole ([`WholeFile`]).

use std::path::Path;

use anyhow::{Context, Result, ensure};
use hdf5_pure::{AttrValue, FileBuilder};

use crate::io::output::WholeFile;
use crate::io::rows::{RowShape, RowSink, check_row, whole_width};

/// The dataset's name.
pub const DATASET: &str = "lightfield";

/// The dataset's axes, slowest first, as `slf import hdf5 --axes` spells them.
pub const AXES: &str = "uvhwb";

/// A `(U, V, H, W, B)` light field's HDF5 file, its rows put in order ([`RowSink`]).
pub struct Hdf5Rows {
    file: WholeFile,
    shape: RowShape,
    /// The values as the file stores them (little-endian f32, `(U, V, H, W, B)`).
    bytes: Vec<u8>,
    next: usize,
    max: f32,
    deflate: Option<u32>,
    attrs: Vec<(String, AttrValue)>,
}

impl Hdf5Rows {
    /// The file for a light field of `shape` whose bands are centred at `bands_nm`,
    /// compressed by deflate at `deflate` (1..=9) or not at all.
    ///
    /// # Errors
    /// A light field too large to hold ([`RowShape::check`]), a band count other
    /// than the shape's, a level outside 1..=9, or a folder that takes no new file.
    pub fn create(path: &Path, shape: RowShape, bands_nm: &[f32], deflate: Option<u32>) -> Result<Self> {
        shape.check()?;
        ensure!(bands_nm.len() == shape.bands, "{} band centres for {} bands", bands_nm.len(), shape.bands);
        ensure!(deflate.is_none_or(|l| (1..=9).contains(&l)), "deflate level {deflate:?}: want 1..=9");
        let file = WholeFile::create(path)?;
        let n = shape.row_len() * shape.rows * 4;
        let axes = AXES.chars().map(String::from).collect();
        let attrs = vec![
            ("axes".to_string(), AttrValue::StringArray(axes)),
            ("bands_nm".to_string(), AttrValue::F32Array(bands_nm.to_vec())),
            ("units".to_string(), AttrValue::String("normalised (white = 1)".into())),
        ];
        Ok(Self { file, shape, bytes: vec![0; n], next: 0, max: 0.0, deflate, attrs })
    }

    /// Adds a string attribute to the dataset.
    pub fn attr(&mut self, name: &str, value: &str) {
        self.attrs.push((name.to_string(), AttrValue::String(value.to_string())));
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.max
    }

    /// Writes the file and puts it in place.
    ///
    /// # Errors
    /// Rows missing, or the encoder's or the I/O error.
    pub fn finish(mut self) -> Result<()> {
        let path = self.file.path().display().to_string();
        ensure!(self.next == self.shape.rows, "cannot write {path}: {} of {} rows decoded", self.next, self.shape.rows);
        let s = self.shape;
        let dims: Vec<u64> = s.shape().iter().map(|&x| x as u64).collect();
        // A chunk: every view and band of a block of up to 16 x 64 lenslets (1.3 MB at 5 x
        // 5 views): a few rows of the frame read without the rest.
        let chunks = [dims[0], dims[1], dims[2].min(16), dims[3].min(64), dims[4]];
        let values = (self.bytes.len() / 4) as u64;
        let mut builder = FileBuilder::new();
        let ds = builder.create_dataset(DATASET);
        ds.with_raw_data(hdf5_pure::make_f32_type(), std::mem::take(&mut self.bytes), values)
            .with_shape(&dims)
            .with_chunks(&chunks);
        if let Some(level) = self.deflate {
            ds.with_shuffle().with_deflate(level);
        }
        for (name, value) in self.attrs.drain(..) {
            ds.set_attr(&name, value);
        }
        builder
            .finish_to(self.file.file())
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("cannot write {path}"))?;
        self.file.persist()
    }
}

impl RowSink for Hdf5Rows {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let y = usize::from(y);
        check_row(self.shape, self.next, y, row, self.file.path())?;
        let run = self.shape.run_len();
        for (p, values) in row.chunks_exact(run).enumerate() {
            let at = (p * self.shape.rows + y) * run * 4;
            for (b, &x) in self.bytes[at..at + run * 4].chunks_exact_mut(4).zip(values) {
                self.max = self.max.max(x);
                b.copy_from_slice(&x.to_le_bytes());
            }
        }
        self.next += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::import::hdf5::{Hdf5Layout, read_hdf5};
    use crate::io::lightfield::LightField;
    use crate::io::rows::put_light_field;

    /// The file reads back through `slf import hdf5`'s reader bit for bit, compressed or
    /// not, with its attributes; a file not finished leaves nothing.
    #[test]
    fn a_light_field_written_to_hdf5_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let (views, rows, cols, bands) = ((2, 3), 20, 70, 13);
        let lf = LightField::from_fn(views, rows, cols, bands, |u, v, y, x, b| {
            ((u * 7 + v * 5 + y * 3 + x * 2 + b) % 17) as f32 / 15.0 + 1e-7 * (x as f32)
        });
        let shape = RowShape { views, rows, cols, bands };
        let nm: Vec<f32> = (0..13).map(|i| 400.0 + 25.0 * i as f32).collect();
        for deflate in [None, Some(4)] {
            let path = dir.path().join("lf.h5");
            let mut w = Hdf5Rows::create(&path, shape, &nm, deflate).unwrap();
            w.attr("description", "{\"format\": \"test\"}");
            put_light_field(&lf, &mut w).unwrap();
            assert_eq!(w.max(), lf.max());
            w.finish().unwrap();
            let back = read_hdf5(&path, &Hdf5Layout { dataset: DATASET.into(), axes: AXES.into() }, 1.0).unwrap();
            assert!(back == lf, "{deflate:?}: the light field read back differs");
            let file = hdf5_pure::File::open(&path).unwrap();
            let ds = file.dataset(DATASET).unwrap();
            let attrs = ds.attrs().unwrap();
            assert!(attrs.contains_key("axes") && attrs.contains_key("bands_nm") && attrs.contains_key("description"));
        }
        let unfinished = dir.path().join("unfinished.h5");
        let mut w = Hdf5Rows::create(&unfinished, shape, &nm, None).unwrap();
        crate::io::rows::put_row(&mut w, 0, &vec![0.5; shape.row_len()]).unwrap();
        assert!(w.finish().is_err(), "rows missing");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert!(!unfinished.exists() && left.len() == 1, "left behind: {left:?}");
    }
}
