//! Spectral light fields in memory and in `.npy` files.
//!
//! Axes are `(U, V, H, W, B)`: view row, view column, spatial row, spatial column, band,
//! row-major with the band fastest, the layout of the public multispectral light-field
//! dataset the paper evaluates on (Schambach and Puente Leon, 2020). Values are f32 in
//! `[0, 1]` (1 = a white surface in the brightest band); files may also hold uint16
//! (`0..=65535` maps to `[0, 1]`).

use std::fs::File;
use std::io::{BufReader, BufWriter, Read};
use std::path::Path;

use npyz::WriterBuilder;

/// A spectral light field, `(U, V, H, W, B)`, f32.
#[derive(Clone, Debug, PartialEq)]
pub struct LightField {
    /// Views: rows `U`, columns `V`.
    pub views: (usize, usize),
    /// Spatial rows `H` (lenslet rows of the camera).
    pub rows: usize,
    /// Spatial columns `W`.
    pub cols: usize,
    /// Bands `B`.
    pub bands: usize,
    /// Values, row-major `(U, V, H, W, B)`.
    pub data: Vec<f32>,
}

impl LightField {
    /// A light field of zeros.
    pub fn zeros(views: (usize, usize), rows: usize, cols: usize, bands: usize) -> Self {
        let n = views.0 * views.1 * rows * cols * bands;
        Self { views, rows, cols, bands, data: vec![0.0; n] }
    }

    /// The shape as `[U, V, H, W, B]`.
    pub fn shape(&self) -> [usize; 5] {
        [self.views.0, self.views.1, self.rows, self.cols, self.bands]
    }

    /// Index of `(u, v, y, x, b)`.
    #[inline]
    pub fn index(&self, u: usize, v: usize, y: usize, x: usize, b: usize) -> usize {
        (((u * self.views.1 + v) * self.rows + y) * self.cols + x) * self.bands + b
    }

    /// Value at `(u, v, y, x, b)`.
    #[inline]
    pub fn get(&self, u: usize, v: usize, y: usize, x: usize, b: usize) -> f32 {
        self.data[self.index(u, v, y, x, b)]
    }

    /// The spectrum at `(u, v, y, x)`.
    pub fn spectrum(&self, u: usize, v: usize, y: usize, x: usize) -> &[f32] {
        let i = self.index(u, v, y, x, 0);
        &self.data[i..i + self.bands]
    }

    /// The largest value.
    pub fn max(&self) -> f32 {
        self.data.iter().fold(0.0f32, |m, &x| m.max(x))
    }
}

/// How a light field is stored in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Dtype {
    /// float32, values in `[0, 1]`.
    F32,
    /// uint16, `[0, 1]` scaled to `0..=65535`.
    U16,
}

/// Why a `.npy` file is not a light field.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: dtype {found}, expected float32 ('<f4') or uint16 ('<u2')")]
    Dtype { path: String, found: String },
    #[error("{path}: {rank} axes {shape:?}, expected 5 (U, V, H, W, B)")]
    Rank { path: String, rank: usize, shape: Vec<u64> },
    #[error("{path}: shape {shape:?} has an empty axis")]
    Empty { path: String, shape: Vec<u64> },
    #[error("{path}: Fortran-order arrays are not supported; save with C order")]
    Order { path: String },
    #[error("{path}: truncated body: header promises {expected} values, file holds {found}")]
    Truncated { path: String, expected: u64, found: u64 },
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> NpyError + '_ {
    move |source| NpyError::Io { path: path.display().to_string(), source }
}

/// Reads a 5-axis `(U, V, H, W, B)` float32 or uint16 `.npy` file.
///
/// # Errors
/// [`NpyError`] saying what is wrong: I/O, dtype, rank, empty axis, order, truncation.
pub fn read_npy(path: &Path) -> Result<LightField, NpyError> {
    let p = path.display().to_string();
    let file = File::open(path).map_err(io_err(path))?;
    let npy = npyz::NpyFile::new(BufReader::new(file)).map_err(io_err(path))?;
    let shape = npy.shape().to_vec();
    if shape.len() != 5 {
        return Err(NpyError::Rank { path: p, rank: shape.len(), shape });
    }
    if shape.contains(&0) {
        return Err(NpyError::Empty { path: p, shape });
    }
    if npy.order() != npyz::Order::C {
        return Err(NpyError::Order { path: p });
    }
    let descr = npy.dtype().descr();
    let expected: u64 = shape.iter().product();
    let s: Vec<usize> = shape.iter().map(|&x| x as usize).collect();
    let mut lf = LightField { views: (s[0], s[1]), rows: s[2], cols: s[3], bands: s[4], data: Vec::new() };
    let (item, f32_data) = match descr.as_str() {
        "'<f4'" => (4, true),
        "'<u2'" => (2, false),
        _ => {
            return Err(NpyError::Dtype { path: p, found: descr });
        }
    };
    // Read the whole body and check its length before converting: a short body is reported
    // as truncation, with counts, not as an I/O error in the middle of a value.
    let mut body = Vec::new();
    npy.into_inner().read_to_end(&mut body).map_err(io_err(path))?;
    let found = body.len() as u64 / item;
    if found < expected {
        return Err(NpyError::Truncated { path: p, expected, found });
    }
    let body = &body[..(expected * item) as usize];
    lf.data = if f32_data {
        body.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
    } else {
        body.chunks_exact(2).map(|c| f32::from(u16::from_le_bytes([c[0], c[1]])) / 65535.0).collect()
    };
    Ok(lf)
}

/// Writes a light field as a 5-axis `.npy` file of `dtype` (uint16 clamps to `[0, 1]`).
///
/// # Errors
/// I/O errors, with the path.
pub fn write_npy(path: &Path, lf: &LightField, dtype: Dtype) -> Result<(), NpyError> {
    let shape: Vec<u64> = lf.shape().iter().map(|&x| x as u64).collect();
    let file = BufWriter::new(File::create(path).map_err(io_err(path))?);
    match dtype {
        Dtype::F32 => {
            let mut w = npyz::WriteOptions::new()
                .default_dtype()
                .shape(&shape)
                .writer(file)
                .begin_nd()
                .map_err(io_err(path))?;
            w.extend(lf.data.iter().copied()).map_err(io_err(path))?;
            w.finish().map_err(io_err(path))
        }
        Dtype::U16 => {
            let mut w = npyz::WriteOptions::new()
                .default_dtype()
                .shape(&shape)
                .writer(file)
                .begin_nd()
                .map_err(io_err(path))?;
            w.extend(lf.data.iter().map(|&x| (x.clamp(0.0, 1.0) * 65535.0).round() as u16)).map_err(io_err(path))?;
            w.finish().map_err(io_err(path))
        }
    }
}

/// Writes a uint16 2D array (a raw frame) as `.npy`.
///
/// # Errors
/// I/O errors.
pub fn write_npy_u16_2d(path: &Path, data: &[u16], rows: usize, cols: usize) -> std::io::Result<()> {
    let file = BufWriter::new(File::create(path)?);
    let mut w = npyz::WriteOptions::new().default_dtype().shape(&[rows as u64, cols as u64]).writer(file).begin_nd()?;
    w.extend(data.iter().copied())?;
    w.finish()
}

/// Reads a uint16 2D `.npy` array (a raw frame): `(data, rows, cols)`.
///
/// # Errors
/// A message saying what is wrong.
pub fn read_npy_u16_2d(path: &Path) -> anyhow::Result<(Vec<u16>, usize, usize)> {
    let file = File::open(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let npy = npyz::NpyFile::new(BufReader::new(file)).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let shape = npy.shape().to_vec();
    anyhow::ensure!(shape.len() == 2, "{}: raw frame must have 2 axes, found {shape:?}", path.display());
    let descr = npy.dtype().descr();
    anyhow::ensure!(descr == "'<u2'", "{}: raw frame dtype {descr}, expected uint16 ('<u2')", path.display());
    anyhow::ensure!(npy.order() == npyz::Order::C, "{}: Fortran order not supported", path.display());
    let data: Vec<u16> =
        npy.into_vec().map_err(|e| anyhow::anyhow!("{}: truncated or unreadable body: {e}", path.display()))?;
    Ok((data, shape[0] as usize, shape[1] as usize))
}
