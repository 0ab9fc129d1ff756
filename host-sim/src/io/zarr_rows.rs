//! A light field's Zarr v3 store ([`ZarrRows`], `slf decode -o OUT.zarr`), written by the
//! `zarrs` crate as the rows come: Dask (`da.from_zarr(OUT, component="lightfield")`),
//! xarray (`xr.open_zarr(OUT)`), zarr-python and napari open it lazily, a chunk at a time.
//!
//! The store is a group:
//! - `lightfield`: float32 `(U, V, H, W, B)`, in the HDF5 output's chunks (every view and
//!   band of 8 x 128 lenslets: [`chunk_shape`]), dimension names `u, v, h, w, band`,
//!   gzip-compressed when asked; its attributes give the axes, the band centres and the units;
//! - `band`: the 13 band centres in nm, dimension name `band`, so xarray makes them the
//!   band axis's coordinate;
//! - the group's attributes: the axes, band centres and units again, and whatever the caller
//!   adds (the capture's description, the decode's command and settings).
//!
//! The rows are gathered into bands ([`RowBand`]) and each full band is written as its
//! chunks, so the sink holds one band (about 10 MB at 1000 lenslets across). The store is
//! a temporary folder until [`ZarrRows::finish`] puts it in place whole ([`WholeFolder`]).

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, ensure};
use serde_json::{Map, Value, json};
use zarrs::array::{Array, ArrayBuilder};
use zarrs::filesystem::FilesystemStore;

use crate::io::folder::{Kind, WholeFolder};
use crate::io::hdf5_rows::{AXES, DATASET};
use crate::io::row_band::{RowBand, chunk_shape};
use crate::io::rows::{RowShape, RowSink, whole_width};

/// What a folder an output store may replace holds: a store's group description and the
/// arrays' folders ([`Kind::Store`]).
pub const STORE: Kind = Kind::Store("zarr.json");

/// The dimension names of the light field's axes, slowest first.
pub const DIMENSIONS: [&str; 5] = ["u", "v", "h", "w", "band"];

/// A `(U, V, H, W, B)` light field's Zarr v3 store, its rows put in order ([`RowSink`]).
pub struct ZarrRows {
    array: Array<FilesystemStore>,
    store: Arc<FilesystemStore>,
    folder: WholeFolder,
    target: std::path::PathBuf,
    shape: RowShape,
    /// The group's attributes, written at [`Self::finish`].
    attrs: Map<String, Value>,
    band: RowBand,
}

/// A `zarrs` error with what was being written.
pub(crate) fn failed(path: &Path) -> impl Fn(String) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("cannot write {}: {e}", path.display())
}

/// The attributes of a store's light field and of its group: the axes, the band centres
/// and the units.
pub(crate) fn light_field_attrs(axes: &str, bands_nm: &[f32]) -> Map<String, Value> {
    let mut attrs = Map::new();
    attrs.insert("axes".into(), axes.into());
    attrs.insert("bands_nm".into(), json!(bands_nm));
    attrs.insert("units".into(), "normalised (white = 1)".into());
    attrs
}

/// The float32 light-field array `/lightfield` of a store: `dims` in chunks of `chunk`,
/// NaN where nothing was written, gzip-compressed at `gzip` when given.
///
/// # Errors
/// A gzip level the codec refuses, or the I/O error.
pub(crate) fn light_field_array(
    store: &Arc<FilesystemStore>,
    dims: Vec<usize>,
    chunk: Vec<usize>,
    names: &[&str],
    attrs: &Map<String, Value>,
    gzip: Option<u32>,
    path: &Path,
) -> Result<Array<FilesystemStore>> {
    let err = failed(path);
    let dims: Vec<u64> = dims.iter().map(|&d| d as u64).collect();
    let chunk: Vec<u64> = chunk.iter().map(|&d| d as u64).collect();
    let mut builder = ArrayBuilder::new(dims, chunk, zarrs::array::data_type::float32(), f32::NAN);
    builder.dimension_names(Some(names.to_vec())).attributes(attrs.clone());
    if let Some(level) = gzip {
        let codec = zarrs::array::codec::GzipCodec::new(level).map_err(|e| err(e.to_string()))?;
        builder.bytes_to_bytes_codecs(vec![Arc::new(codec)]);
    }
    let array = builder.build(store.clone(), &format!("/{DATASET}")).map_err(|e| err(e.to_string()))?;
    array.store_metadata().map_err(|e| err(e.to_string()))?;
    Ok(array)
}

/// The band centres as an array of their own, `/band`: xarray's coordinate of the band
/// axis.
///
/// # Errors
/// The I/O error.
pub(crate) fn band_array(store: &Arc<FilesystemStore>, bands_nm: &[f32], path: &Path) -> Result<()> {
    let err = failed(path);
    let n = bands_nm.len() as u64;
    let mut nm = ArrayBuilder::new(vec![n], vec![n], zarrs::array::data_type::float32(), f32::NAN);
    let mut units = Map::new();
    units.insert("units".into(), "nm".into());
    units.insert("long_name".into(), "band centre".into());
    nm.dimension_names(Some(["band"])).attributes(units);
    let nm = nm.build(store.clone(), "/band").map_err(|e| err(e.to_string()))?;
    nm.store_metadata().map_err(|e| err(e.to_string()))?;
    nm.store_chunk(&[0], bands_nm).map_err(|e| err(e.to_string()))
}

/// Writes the group's description, its attributes `attrs`, at the store's root, with the
/// arrays' metadata consolidated into it (zarr-python's and xarray's one read of a store's
/// layout; without it xarray warns and reads every array's `zarr.json`).
///
/// # Errors
/// The I/O error.
pub(crate) fn store_group(store: &Arc<FilesystemStore>, attrs: Map<String, Value>, path: &Path) -> Result<()> {
    use zarrs::metadata_ext::group::consolidated_metadata::{ConsolidatedMetadata, ConsolidatedMetadataKind};
    let err = failed(path);
    let mut group = zarrs::group::GroupBuilder::new();
    group.attributes(attrs);
    let mut group = group.build(store.clone(), "/").map_err(|e| err(e.to_string()))?;
    group.store_metadata().map_err(|e| err(e.to_string()))?;
    let node = zarrs::node::Node::open(store, "/").map_err(|e| err(e.to_string()))?;
    let metadata = node.consolidate_metadata().unwrap_or_default();
    group.set_consolidated_metadata(Some(ConsolidatedMetadata { metadata, kind: ConsolidatedMetadataKind::Inline }));
    group.store_metadata().map_err(|e| err(e.to_string()))
}

impl ZarrRows {
    /// The store for a light field of `shape` whose bands are centred at `bands_nm`, its
    /// chunks compressed by gzip at `gzip` (1..=9) or stored as they are.
    ///
    /// # Errors
    /// A band count other than the shape's, a level outside 1..=9, a band that does not fit
    /// the memory cap, a target that is not a store this may replace, or the I/O error.
    pub fn create(path: &Path, shape: RowShape, bands_nm: &[f32], gzip: Option<u32>) -> Result<Self> {
        ensure!(bands_nm.len() == shape.bands, "{} band centres for {} bands", bands_nm.len(), shape.bands);
        ensure!(gzip.is_none_or(|l| (1..=9).contains(&l)), "gzip level {gzip:?}: want 1..=9");
        let band = RowBand::new(shape, path)?;
        let folder = WholeFolder::create(path, STORE)?;
        let err = failed(path);
        let store = Arc::new(FilesystemStore::new(folder.path()).map_err(|e| err(e.to_string()))?);
        let attrs = light_field_attrs(AXES, bands_nm);
        let array = light_field_array(
            &store,
            shape.shape().to_vec(),
            chunk_shape(shape).to_vec(),
            &DIMENSIONS,
            &attrs,
            gzip,
            path,
        )?;
        band_array(&store, bands_nm, path)?;
        Ok(Self { array, store, folder, target: path.to_path_buf(), shape, attrs, band })
    }

    /// Adds an attribute to the store's group (JSON: the capture's description is an
    /// object there, not a string holding one).
    pub fn attr(&mut self, name: &str, value: Value) {
        self.attrs.insert(name.to_string(), value);
    }

    /// The largest value put so far.
    pub fn max(&self) -> f32 {
        self.band.max()
    }

    /// Writes the group's description and puts the store in place (every band is written
    /// as it fills).
    ///
    /// # Errors
    /// Rows missing, or the writer's or the I/O error.
    pub fn finish(mut self) -> Result<()> {
        let path = self.target.display().to_string();
        let put = self.band.rows_put();
        ensure!(put == self.shape.rows, "cannot write {path}: {put} of {} rows decoded", self.shape.rows);
        store_group(&self.store, std::mem::take(&mut self.attrs), &self.target)?;
        let Self { array, store, folder, .. } = self;
        drop((array, store));
        folder.persist().with_context(|| format!("cannot write {path}"))
    }
}

impl RowSink for ZarrRows {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let Some(band) = self.band.put(usize::from(y), row, &self.target)? else { return Ok(()) };
        let [u, v, _, w, b] = self.shape.shape();
        let (y0, y1) = (band.first as u64, (band.first + band.rows) as u64);
        let subset = [0..u as u64, 0..v as u64, y0..y1, 0..w as u64, 0..b as u64];
        self.array.store_array_subset(&subset, band.values).map_err(|e| failed(&self.target)(e.to_string()))
    }
}
