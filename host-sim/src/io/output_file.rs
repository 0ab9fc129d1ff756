//! A decode's light field written to its file as the rows come ([`OutputFile`]), whichever
//! file it is: a `.npy` file, an HDF5 file, a Zarr store of its own, or one capture's slot
//! of the store `slf.batch` writes for many. `slf decode -o` and Python's `output=` make it
//! the same way, put the decode's rows into [`OutputFile::sink`], and [`OutputFile::finish`]
//! it once the decode is done; dropped unfinished, it leaves nothing.

use std::path::Path;

use anyhow::Result;

use crate::io::capture::CaptureDescription;
use crate::io::hdf5_rows::Hdf5Rows;
use crate::io::lightfield::Dtype;
use crate::io::npy_rows::NpyRows;
use crate::io::rows::{RowShape, Rows};
use crate::io::zarr_rows::ZarrRows;
use crate::io::zarr_stack::ZarrSlot;

/// Which file a light field goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// A `.npy` file of `f32` or `u16` values.
    Npy(Dtype),
    /// An HDF5 file, deflated at the level given.
    Hdf5(Option<u32>),
    /// A Zarr v3 store (a folder), gzipped at the level given.
    Zarr(Option<u32>),
    /// Capture `index`'s slot of a store made for many ([`crate::io::zarr_stack`]).
    Slot(usize),
}

/// A light field's file, being written.
pub enum OutputFile {
    Npy(NpyRows),
    Hdf5(Hdf5Rows),
    /// Boxed: the array's description is a kilobyte, the other sinks a few hundred bytes.
    Zarr(Box<ZarrRows>),
    Slot(Box<ZarrSlot>),
}

impl OutputFile {
    /// Creates the file of `kind` at `path` for a light field of `shape` decoded from a
    /// capture described by `description`; an HDF5 file or Zarr store records the
    /// description and `command` (what was run) as attributes.
    ///
    /// # Errors
    /// A file that cannot be created, or a slot of another shape.
    pub fn create(
        kind: OutputKind,
        path: &Path,
        shape: RowShape,
        description: &CaptureDescription,
        command: &str,
    ) -> Result<Self> {
        Ok(match kind {
            OutputKind::Npy(dtype) => Self::Npy(NpyRows::create(path, shape, dtype)?),
            OutputKind::Hdf5(deflate) => {
                let mut f = Hdf5Rows::create(path, shape, &description.bands_nm, deflate)?;
                f.attr("description", &serde_json::to_string(description)?)?;
                f.attr("command", command)?;
                Self::Hdf5(f)
            }
            OutputKind::Zarr(gzip) => {
                let mut f = ZarrRows::create(path, shape, &description.bands_nm, gzip)?;
                // Through its text, as capture.json holds it: a value from the f32 fields
                // directly would carry their binary expansion (3691.89990234375 for 3691.9).
                f.attr("description", serde_json::from_str(&serde_json::to_string(description)?)?);
                f.attr("command", command.into());
                Self::Zarr(Box::new(f))
            }
            OutputKind::Slot(index) => Self::Slot(Box::new(ZarrSlot::open(path, index, shape)?)),
        })
    }

    /// Where the decode puts its rows.
    pub fn sink(&mut self) -> &mut Rows<'static> {
        match self {
            Self::Npy(f) => f,
            Self::Hdf5(f) => f,
            Self::Zarr(f) => &mut **f,
            Self::Slot(f) => &mut **f,
        }
    }

    /// The largest value put so far (the estimated PSNR's data range).
    pub fn max(&self) -> f32 {
        match self {
            Self::Npy(f) => f.max(),
            Self::Hdf5(f) => f.max(),
            Self::Zarr(f) => f.max(),
            Self::Slot(f) => f.max(),
        }
    }

    /// Puts the file in place; an HDF5 file or Zarr store records `settings` (the decode's,
    /// resolved) first. A slot is the batch store's, which records the run's settings.
    ///
    /// # Errors
    /// A write or rename that fails.
    pub fn finish(self, settings: &str) -> Result<()> {
        match self {
            Self::Npy(f) => f.finish(),
            Self::Hdf5(mut f) => {
                f.attr("settings", settings)?;
                f.finish()
            }
            Self::Zarr(mut f) => {
                f.attr("settings", settings.into());
                f.finish()
            }
            Self::Slot(f) => f.finish(),
        }
    }
}
