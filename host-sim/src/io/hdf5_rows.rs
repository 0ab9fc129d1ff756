//! A light field's HDF5 file ([`Hdf5Rows`], `slf decode -o OUT.h5`): one chunked, optionally
//! shuffled and deflate-compressed float32 dataset `lightfield` of shape `(U, V, H, W, B)`,
//! its axes, the band centres in nm and whatever the caller adds (the capture's description,
//! the decode's settings) as attributes; readable by h5py (lazily, a chunk at a time) and by
//! `slf import hdf5 OUT.h5 --dataset lightfield --axes uvhwb`.
//!
//! Written as it goes: the rows are gathered into bands of one chunk's height
//! ([`RowBand`]) and each full band is written into the file (`rust-hdf5`'s `write_slice`),
//! so the sink holds one band, about 10 MB at 1000 lenslets across, whatever the frame's
//! height. The file is a temporary one until [`Hdf5Rows::finish`] puts it in place
//! ([`WholeFile`]).

use std::path::Path;

use anyhow::{Context, Result, ensure};
use rust_hdf5::{H5Dataset, H5File};

use crate::io::output::WholeFile;
use crate::io::row_band::{RowBand, chunk_shape};
use crate::io::rows::{RowShape, RowSink, whole_width};

/// The dataset's name.
pub const DATASET: &str = "lightfield";

/// The dataset's axes, slowest first, as `slf import hdf5 --axes` spells them.
pub const AXES: &str = "uvhwb";

/// A `(U, V, H, W, B)` light field's HDF5 file, its rows put in order ([`RowSink`]).
pub struct Hdf5Rows {
    // Declared first, so dropped (and closed) before the temporary file is removed.
    h5: H5File,
    dataset: H5Dataset,
    file: WholeFile,
    shape: RowShape,
    band: RowBand,
}

impl Hdf5Rows {
    /// The file for a light field of `shape` whose bands are centred at `bands_nm`,
    /// shuffled and compressed by deflate at `deflate` (1..=9), or stored as it is.
    ///
    /// # Errors
    /// A band count other than the shape's, a level outside 1..=9, a band that does not fit
    /// the memory cap, or a folder that takes no new file.
    pub fn create(path: &Path, shape: RowShape, bands_nm: &[f32], deflate: Option<u32>) -> Result<Self> {
        ensure!(bands_nm.len() == shape.bands, "{} band centres for {} bands", bands_nm.len(), shape.bands);
        ensure!(deflate.is_none_or(|l| (1..=9).contains(&l)), "deflate level {deflate:?}: want 1..=9");
        let band = RowBand::new(shape, path)?;
        let file = WholeFile::create(path)?;
        let failed = || format!("cannot write {}", path.display());
        let h5 = H5File::create(file.part_path()).map_err(anyhow::Error::from).with_context(failed)?;
        let mut builder = h5.new_dataset::<f32>().shape(shape.shape()).chunk(&chunk_shape(shape));
        if let Some(level) = deflate {
            builder = builder.shuffle_deflate(level);
        }
        let dataset = builder.create(DATASET).map_err(anyhow::Error::from).with_context(failed)?;
        let attrs = || -> rust_hdf5::Result<()> {
            let axes: Vec<String> = AXES.chars().map(String::from).collect();
            let axes: Vec<&str> = axes.iter().map(String::as_str).collect();
            dataset
                .new_attr::<rust_hdf5::types::VarLenUnicode>()
                .shape([5])
                .create("axes")?
                .write_string_array(&axes)?;
            dataset.new_attr::<f32>().shape([bands_nm.len()]).create("bands_nm")?.write_array(bands_nm)?;
            dataset
                .new_attr::<rust_hdf5::types::VarLenUnicode>()
                .shape(())
                .create("units")?
                .write_string("normalised (white = 1)")
        };
        attrs().map_err(anyhow::Error::from).with_context(failed)?;
        Ok(Self { h5, dataset, file, shape, band })
    }

    /// Adds a string attribute to the dataset.
    ///
    /// # Errors
    /// The writer's error.
    pub fn attr(&mut self, name: &str, value: &str) -> Result<()> {
        self.dataset
            .new_attr::<rust_hdf5::types::VarLenUnicode>()
            .shape(())
            .create(name)
            .and_then(|a| a.write_string(value))
            .map_err(anyhow::Error::from)
            .with_context(|| format!("cannot write {}: attribute {name}", self.file.path().display()))
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.band.max()
    }

    /// Closes the file and puts it in place (every band is written as it fills).
    ///
    /// # Errors
    /// Rows missing, or the writer's or the I/O error.
    pub fn finish(self) -> Result<()> {
        let path = self.file.path().display().to_string();
        let put = self.band.rows_put();
        ensure!(put == self.shape.rows, "cannot write {path}: {put} of {} rows decoded", self.shape.rows);
        let Self { h5, dataset, file, .. } = self;
        drop(dataset);
        h5.close().map_err(anyhow::Error::from).with_context(|| format!("cannot write {path}"))?;
        file.persist()
    }
}

impl RowSink for Hdf5Rows {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let Some(band) = self.band.put(usize::from(y), row, self.file.path())? else { return Ok(()) };
        let [u, v, _, w, b] = self.shape.shape();
        self.dataset
            .write_slice(&[0, 0, band.first, 0, 0], &[u, v, band.rows, w, b], band.values)
            .map_err(anyhow::Error::from)
            .with_context(|| format!("cannot write {}", self.file.path().display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::import::hdf5::{Hdf5Layout, read_hdf5};
    use crate::io::lightfield::LightField;
    use crate::io::rows::put_light_field;

    /// The file reads back through `slf import hdf5`'s reader bit for bit, compressed or
    /// not, with its attributes, over bands and chunks cut at the frame's edges (20 rows in
    /// bands of 8; 150 columns in chunks of 128); a file not finished leaves nothing.
    #[test]
    fn a_light_field_written_to_hdf5_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let (views, rows, cols, bands) = ((2, 3), 20, 150, 13);
        let lf = LightField::from_fn(views, rows, cols, bands, |u, v, y, x, b| {
            ((u * 7 + v * 5 + y * 3 + x * 2 + b) % 17) as f32 / 15.0 + 1e-7 * (x as f32)
        });
        let shape = RowShape { views, rows, cols, bands };
        let nm: Vec<f32> = (0..13).map(|i| 400.0 + 25.0 * i as f32).collect();
        for deflate in [None, Some(4)] {
            let path = dir.path().join("lf.h5");
            let mut w = Hdf5Rows::create(&path, shape, &nm, deflate).unwrap();
            w.attr("description", "{\"format\": \"test\"}").unwrap();
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
