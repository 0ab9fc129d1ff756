//! `slf._slf.Stack`: the client's handle on a store of many captures' light fields
//! ([`ZarrStack`]), which `slf.batch.decode_folder` makes, hands its temporary folder to the
//! tasks (each writes its capture's slot: `decode(..., output=path, slot=i)`) and puts in
//! place once every task has ended.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use slf_host::io::output::Outputs;
use slf_host::io::rows::RowShape;
use slf_host::io::zarr_stack::ZarrStack;

use crate::errors::OrPy;

/// A store of `captures` light fields of `shape` `(U, V, H, W, B)` being filled.
#[pyclass(module = "slf._slf")]
pub struct Stack {
    inner: Option<ZarrStack>,
}

#[pymethods]
impl Stack {
    /// Makes the store for `path` in a temporary folder beside it. `inputs`: the capture
    /// folders, none of which may lie inside the store (it is replaced whole).
    #[new]
    #[pyo3(signature = (path, captures, shape, bands_nm, inputs, gzip=None))]
    fn new(
        path: PathBuf,
        captures: usize,
        shape: (usize, usize, usize, usize, usize),
        bands_nm: Vec<f32>,
        inputs: Vec<PathBuf>,
        gzip: Option<u32>,
    ) -> PyResult<Self> {
        Outputs::new()
            .inputs(&inputs, "a capture folder")
            .folder_output(&path, "output")
            .check()
            .map_err(|e| PyValueError::new_err(slf_host::io::message::one_line(&e)))?;
        let (u, v, h, w, b) = shape;
        let shape = RowShape { views: (u, v), rows: h, cols: w, bands: b };
        shape.check().or_py()?;
        Ok(Self { inner: Some(ZarrStack::create(&path, captures, shape, &bands_nm, gzip).or_py()?) })
    }

    /// The temporary folder the tasks write their slots into.
    #[getter]
    fn path(&self) -> PyResult<PathBuf> {
        Ok(self.live()?.path().to_path_buf())
    }

    /// Writes the group's attributes (`attrs`: a JSON object's text) and puts the store in
    /// place whole.
    fn finish(&mut self, attrs: &str) -> PyResult<()> {
        self.live()?;
        let attrs: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(attrs).map_err(|e| PyValueError::new_err(format!("attrs: {e}")))?;
        match self.inner.take() {
            Some(stack) => stack.finish(attrs).or_py(),
            None => Err(PyValueError::new_err("the store is already finished")),
        }
    }

    /// Removes the temporary folder without putting the store in place.
    fn discard(&mut self) {
        self.inner = None;
    }
}

impl Stack {
    fn live(&self) -> PyResult<&ZarrStack> {
        self.inner.as_ref().ok_or_else(|| PyValueError::new_err("the store is already finished or discarded"))
    }
}
