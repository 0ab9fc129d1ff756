//! Many captures' light fields in one Zarr v3 store, along a capture axis
//! (`slf.batch.decode_folder(..., "OUT.zarr")`): `lightfield` is float32
//! `(N, U, V, H, W, B)`, dimension names `capture, u, v, h, w, band`, in chunks of one
//! capture ([`chunk_shape`] after a 1), so each capture's decode writes chunks no other
//! writes: Dask workers in other processes fill their slots at once, each holding one band
//! of rows ([`ZarrSlot`]).
//!
//! The client makes the store in a temporary folder ([`ZarrStack::create`]), the workers
//! open it by its path and write their slots ([`ZarrSlot::open`]), and the client puts it in
//! place whole with the group's attributes (the captures' names and outcomes) once every
//! task has ended ([`ZarrStack::finish`]). A capture that failed leaves its slot unwritten:
//! NaN, the array's fill value, and its error in the attributes.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, ensure};
use serde_json::{Map, Value};
use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;

use crate::io::folder::WholeFolder;
use crate::io::hdf5_rows::DATASET;
use crate::io::row_band::{RowBand, chunk_shape};
use crate::io::rows::{RowShape, RowSink, whole_width};
use crate::io::zarr_rows::{DIMENSIONS, STORE, band_array, failed, light_field_array, light_field_attrs, store_group};

/// The axes of a stack's light field, slowest first: the capture, then a light field's.
pub const STACK_AXES: &str = "cuvhwb";

/// The most captures one store takes (a capture's slot index is a `u32` in the chunk keys
/// of every reader; a million light fields is past any folder of captures).
pub const MAX_CAPTURES: usize = 1 << 20;

/// A store of `N` light fields of one shape, being filled (the client's side).
pub struct ZarrStack {
    folder: WholeFolder,
    store: Arc<FilesystemStore>,
    target: PathBuf,
    /// The light field's attributes, which the group repeats.
    attrs: Map<String, Value>,
}

impl ZarrStack {
    /// A store at `path` for `captures` light fields of `shape` whose bands are centred at
    /// `bands_nm`, gzip-compressed at `gzip` (1..=9) or not, made in a temporary folder
    /// beside `path`.
    ///
    /// # Errors
    /// No capture or too many, a band count other than the shape's, a level outside 1..=9,
    /// a band of rows past the memory cap, a target that is not a store this may replace, or
    /// the I/O error.
    pub fn create(path: &Path, captures: usize, shape: RowShape, bands_nm: &[f32], gzip: Option<u32>) -> Result<Self> {
        ensure!((1..=MAX_CAPTURES).contains(&captures), "{captures} captures: want 1..={MAX_CAPTURES} in one store");
        ensure!(bands_nm.len() == shape.bands, "{} band centres for {} bands", bands_nm.len(), shape.bands);
        ensure!(gzip.is_none_or(|l| (1..=9).contains(&l)), "gzip level {gzip:?}: want 1..=9");
        RowBand::new(shape, path)?;
        let folder = WholeFolder::create(path, STORE)?;
        let store = Arc::new(FilesystemStore::new(folder.path()).map_err(|e| failed(path)(e.to_string()))?);
        let dims = [&[captures][..], &shape.shape()].concat();
        let chunk = [&[1][..], &chunk_shape(shape)].concat();
        let names = [&["capture"][..], &DIMENSIONS].concat();
        let attrs = light_field_attrs(STACK_AXES, bands_nm);
        light_field_array(&store, dims, chunk, &names, &attrs, gzip, path)?;
        band_array(&store, bands_nm, path)?;
        Ok(Self { folder, store, target: path.to_path_buf(), attrs })
    }

    /// The temporary folder the workers write their slots into.
    pub fn path(&self) -> &Path {
        self.folder.path()
    }

    /// Writes the group's attributes (the axes, bands and units, and `attrs`: the captures'
    /// names and outcomes) and puts the store in place whole.
    ///
    /// # Errors
    /// The I/O error.
    pub fn finish(self, attrs: Map<String, Value>) -> Result<()> {
        let Self { folder, store, target, attrs: mut all } = self;
        all.extend(attrs);
        store_group(&store, all, &target)?;
        drop(store);
        folder.persist().with_context(|| format!("cannot write {}", target.display()))
    }
}

/// One capture's slot of a [`ZarrStack`], its rows put in order ([`RowSink`]): the worker's
/// side.
pub struct ZarrSlot {
    array: Array<FilesystemStore>,
    index: u64,
    shape: RowShape,
    band: RowBand,
    path: PathBuf,
}

impl ZarrSlot {
    /// Slot `index` of the store in folder `path` (a [`ZarrStack::path`]), for a light field
    /// of `shape`.
    ///
    /// # Errors
    /// No such store, a slot past its captures, a shape other than the store's, or the I/O
    /// error.
    pub fn open(path: &Path, index: usize, shape: RowShape) -> Result<Self> {
        let err = failed(path);
        let store = Arc::new(FilesystemStore::new(path).map_err(|e| err(e.to_string()))?);
        let array = Array::open(store, &format!("/{DATASET}"))
            .map_err(|e| anyhow::anyhow!("{}: no light-field store of slf.batch: {e}", path.display()))?;
        let dims: Vec<usize> = array.shape().iter().map(|&d| d as usize).collect();
        let [n, light_field @ ..] = dims.as_slice() else {
            anyhow::bail!("{}: a light field of {} axes, not a stack of captures", path.display(), dims.len())
        };
        ensure!(index < *n, "{}: capture {index} of a store of {n}", path.display());
        ensure!(
            light_field == shape.shape(),
            "{}: the store holds light fields of shape {light_field:?}, this capture's is {:?}",
            path.display(),
            shape.shape()
        );
        Ok(Self { array, index: index as u64, shape, band: RowBand::new(shape, path)?, path: path.to_path_buf() })
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.band.max()
    }

    /// Checks that every row was written (each band is written as it fills).
    ///
    /// # Errors
    /// Rows missing.
    pub fn finish(self) -> Result<()> {
        let put = self.band.rows_put();
        ensure!(
            put == self.shape.rows,
            "cannot write capture {} of {}: {put} of {} rows decoded",
            self.index,
            self.path.display(),
            self.shape.rows
        );
        Ok(())
    }
}

impl RowSink for ZarrSlot {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let Some(band) = self.band.put(usize::from(y), row, &self.path)? else { return Ok(()) };
        let [u, v, _, w, b] = self.shape.shape();
        let (y0, y1) = (band.first as u64, (band.first + band.rows) as u64);
        let i = self.index;
        let subset = [i..i + 1, 0..u as u64, 0..v as u64, y0..y1, 0..w as u64, 0..b as u64];
        self.array.store_array_subset(&subset, band.values).map_err(|e| failed(&self.path)(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_fill_their_captures_and_leave_the_others_nan() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("stack.zarr");
        let shape = RowShape { views: (2, 1), rows: 11, cols: 3, bands: 2 };
        let stack = ZarrStack::create(&path, 3, shape, &[450.0, 550.0], None).unwrap();
        let value = |i: usize, y: usize, k: usize| (i * 1000 + y * 10 + k) as f32;
        for i in [0, 2] {
            let mut slot = ZarrSlot::open(stack.path(), i, shape).unwrap();
            for y in 0..shape.rows {
                let row: Vec<f32> = (0..shape.row_len()).map(|k| value(i, y, k)).collect();
                slot.row(y as u16, 0, &row).unwrap();
            }
            slot.finish().unwrap();
        }
        let wrong = RowShape { rows: 12, ..shape };
        let e = format!("{:#}", ZarrSlot::open(stack.path(), 1, wrong).err().unwrap());
        assert!(e.contains("[2, 1, 11, 3, 2]") && e.contains("[2, 1, 12, 3, 2]"), "{e}");
        assert!(ZarrSlot::open(stack.path(), 3, shape).is_err());
        let mut attrs = Map::new();
        attrs.insert("captures".into(), serde_json::json!(["a", "b", "c"]));
        stack.finish(attrs).unwrap();
        // Read back through zarrs, value for value.
        let store = Arc::new(FilesystemStore::new(&path).unwrap());
        let array = Array::open(store.clone(), "/lightfield").unwrap();
        assert_eq!(array.shape(), [3, 2, 1, 11, 3, 2]);
        let all: Vec<f32> = array.retrieve_array_subset(&array.subset_all()).unwrap();
        let per = shape.row_len() * shape.rows;
        for i in 0..3 {
            for (n, &x) in all[i * per..(i + 1) * per].iter().enumerate() {
                if i == 1 {
                    assert!(x.is_nan(), "capture 1 was not written: {x}");
                    continue;
                }
                // Index n over (u, v, y, w, b); the row put held (u, v, w, b) at k.
                let [u, v, _, w, b] = shape.shape();
                let (uv, rest) = (n / (shape.rows * w * b), n % (shape.rows * w * b));
                let (y, wb) = (rest / (w * b), rest % (w * b));
                assert_eq!(x, value(i, y, uv * w * b + wb), "capture {i}, value {n} ({u} x {v} views)");
            }
        }
        let group = zarrs::group::Group::open(store, "/").unwrap();
        assert_eq!(group.attributes()["captures"], serde_json::json!(["a", "b", "c"]));
        assert_eq!(group.attributes()["axes"], serde_json::json!(STACK_AXES));
    }
}
