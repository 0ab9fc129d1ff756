//! Spectral light fields in memory and in `.npy` files.
//!
//! Axes are `(U, V, H, W, B)`: view row, view column, spatial row, spatial column, band,
//! row-major with the band fastest, the layout of the public multispectral light-field
//! dataset the paper evaluates on (Schambach and Puente Leon, 2020). Values are f32 in
//! normalised units (1 = a white surface in the brightest band; a decode's lie in the
//! sensor's physical range, 0 to its brightest measurable value, a little above 1); files
//! may also hold uint16 (`0..=65535` maps to `[0, 1]`).

use std::path::Path;

use npyz::WriterBuilder;

use crate::io::output::{WholeFile, stage, write_whole};

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
    /// The most values a light field made in memory may hold (a render, an import, a
    /// resample): 2^30, 4 GiB of f32. Sizes are checked against it before anything is
    /// allocated ([`Self::check_size`]).
    pub const MAX_VALUES: usize = 1 << 30;

    /// Checks that a `(U, V, H, W, B)` light field of these sizes has no empty axis and
    /// stays within [`Self::MAX_VALUES`], before it is allocated.
    ///
    /// # Errors
    /// The sizes, their product (or "more than 2^64") and the limit, in one line.
    pub fn check_size(views: (usize, usize), rows: usize, cols: usize, bands: usize) -> anyhow::Result<()> {
        anyhow::ensure!(
            views.0 > 0 && views.1 > 0 && rows > 0 && cols > 0 && bands > 0,
            "a light field of {} x {} views, {rows} x {cols} pixels a view and {bands} bands is empty",
            views.0,
            views.1
        );
        let n = [views.0, views.1, rows, cols, bands].iter().try_fold(1usize, |n, &d| n.checked_mul(d));
        match n {
            Some(n) if n <= Self::MAX_VALUES => Ok(()),
            n => anyhow::bail!(
                "{} x {} views of {rows} x {cols} pixels and {bands} bands is {} values ({:.1} GiB of f32), more than \
                 the {} (4 GiB) a light field may hold",
                views.0,
                views.1,
                n.map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
                n.map_or(f64::INFINITY, |n| n as f64 * 4.0 / f64::from(1u32 << 30)),
                Self::MAX_VALUES
            ),
        }
    }

    /// Checks that every value is finite.
    ///
    /// # Errors
    /// How many are not (NaN or infinite) and where the first is, one line.
    pub fn check_finite(&self) -> Result<(), String> {
        let Some(first) = self.data.iter().position(|x| !x.is_finite()) else { return Ok(()) };
        let bad = self.data.iter().filter(|x| !x.is_finite()).count();
        let (u, v, y, x, b) = self.coordinates(first);
        Err(format!(
            "{bad} of {} values are not finite (NaN or infinite), the first at (u, v, y, x, b) = ({u}, {v}, {y}, {x}, {b})",
            self.data.len()
        ))
    }

    /// A light field of zeros.
    pub fn zeros(views: (usize, usize), rows: usize, cols: usize, bands: usize) -> Self {
        let n = views.0 * views.1 * rows * cols * bands;
        Self { views, rows, cols, bands, data: vec![0.0; n] }
    }

    /// A light field whose value at `(u, v, y, x, b)` is `f(u, v, y, x, b)`.
    pub fn from_fn(
        views: (usize, usize),
        rows: usize,
        cols: usize,
        bands: usize,
        f: impl Fn(usize, usize, usize, usize, usize) -> f32,
    ) -> Self {
        let mut lf = Self::zeros(views, rows, cols, bands);
        for i in 0..lf.data.len() {
            let (u, v, y, x, b) = lf.coordinates(i);
            lf.data[i] = f(u, v, y, x, b);
        }
        lf
    }

    /// The spatial window `rows x cols` from `(row, col)` of every view (inside the field).
    pub fn window(&self, row: usize, col: usize, rows: usize, cols: usize) -> Self {
        let mut out = Self::zeros(self.views, rows, cols, self.bands);
        let n = cols * self.bands;
        for u in 0..self.views.0 {
            for v in 0..self.views.1 {
                for y in 0..rows {
                    let src = self.index(u, v, row + y, col, 0);
                    let dst = out.index(u, v, y, 0, 0);
                    out.data[dst..dst + n].copy_from_slice(&self.data[src..src + n]);
                }
            }
        }
        out
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

    /// The `(u, v, y, x, b)` of a data index.
    pub fn coordinates(&self, i: usize) -> (usize, usize, usize, usize, usize) {
        let b = i % self.bands;
        let i = i / self.bands;
        let x = i % self.cols;
        let i = i / self.cols;
        let y = i % self.rows;
        let i = i / self.rows;
        (i / self.views.1, i % self.views.1, y, x, b)
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
    /// float32, values as they are (a decode's: 0 to the sensor's brightest measurable
    /// value, white = 1).
    F32,
    /// uint16, `[0, 1]` scaled to `0..=65535` (values above white clip at 65535).
    U16,
}

use crate::io::npy::{self, Values};
pub use crate::io::npy::{NpyError, NpyErrorKind};

/// Reads a 5-axis `(U, V, H, W, B)` light field from `.npy` (float32, float64 or uint16;
/// C or Fortran order) and prints to stderr, as `note: FILE: ...`, any conversion made.
///
/// # Errors
/// [`NpyError`] saying what is wrong and where: I/O, header, dtype, rank, an empty axis,
/// truncation, values that are not finite.
pub fn read_npy(path: &Path) -> Result<LightField, NpyError> {
    noted(path, read_npy_held(path, None))
}

/// The light field of a read, its conversion notes printed to stderr.
fn noted(path: &Path, read: Result<(LightField, Vec<String>), NpyError>) -> Result<LightField, NpyError> {
    let (lf, notes) = read?;
    for n in notes {
        eprintln!("note: {}: {n}", path.display());
    }
    Ok(lf)
}

/// As [`read_npy`], returning the conversion notes instead of printing them.
///
/// # Errors
/// As [`read_npy`].
pub fn read_npy_with_notes(path: &Path) -> Result<(LightField, Vec<String>), NpyError> {
    read_npy_held(path, None)
}

/// As [`read_npy`], for a light field read while another is held (`held`: what, and its bytes; `slf eval`'s
/// second file): the two together are checked against the memory cap before this one's
/// values are read (each alone once passed the check, and the second allocation aborted).
///
/// # Errors
/// As [`read_npy`], and the two past the cap.
pub fn read_npy_beside(path: &Path, held: (&str, u64)) -> Result<LightField, NpyError> {
    noted(path, read_npy_held(path, Some(held)))
}

fn read_npy_held(path: &Path, held: Option<(&str, u64)>) -> Result<(LightField, Vec<String>), NpyError> {
    // The shape is checked from the header, before the body is read: a sparse file can
    // claim more values than memory holds.
    let a = npy::read_checked(path, |s, _| {
        if s.len() != 5 {
            return Err(format!("{} axes {s:?}, expected 5 (U, V, H, W, B)", s.len()));
        }
        if s.contains(&0) {
            return Err(format!("shape {s:?} has an empty axis"));
        }
        LightField::check_size((s[0], s[1]), s[2], s[3], s[4]).map_err(|e| format!("shape {s:?}: {e}"))?;
        if let Some((what, bytes)) = held {
            // Bounded by `check_size`: the product fits.
            let own = s.iter().map(|&d| d as u64).product::<u64>().saturating_mul(4);
            crate::io::budget::check(
                own.saturating_add(bytes),
                &format!("reading shape {s:?} beside {what}"),
                "smaller light fields",
            )
            .map_err(|e| e.to_string())?;
        }
        Ok(())
    })?;
    let shape_err = |what: String| NpyError::new(path, NpyErrorKind::Shape(what));
    let s = &a.shape;
    let data = a.values.into_f32();
    let lf = LightField { views: (s[0], s[1]), rows: s[2], cols: s[3], bands: s[4], data };
    lf.check_finite().map_err(shape_err)?;
    Ok((lf, a.notes))
}

/// Writes a light field as a 5-axis `.npy` file of `dtype` (uint16 clamps to `[0, 1]`),
/// whole or not at all ([`write_whole`]).
///
/// # Errors
/// A value that is not finite (nothing is written); I/O errors, with the path.
pub fn write_npy(path: &Path, lf: &LightField, dtype: Dtype) -> anyhow::Result<()> {
    // slf writes no light field it would refuse to read: NaN or infinity is a fault of
    // what made it (an import's --white of 1e-40), not a value to store.
    lf.check_finite().map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    let shape: Vec<u64> = lf.shape().iter().map(|&x| x as u64).collect();
    write_whole(path, |out| {
        match dtype {
            Dtype::F32 => {
                let mut w = npyz::WriteOptions::new().default_dtype().shape(&shape).writer(out).begin_nd()?;
                w.extend(lf.data.iter().copied())?;
                w.finish()?;
            }
            Dtype::U16 => {
                let mut w = npyz::WriteOptions::new().default_dtype().shape(&shape).writer(out).begin_nd()?;
                w.extend(lf.data.iter().map(|&x| (x.clamp(0.0, 1.0) * 65535.0).round() as u16))?;
                w.finish()?;
            }
        }
        Ok(())
    })
}

/// Writes a uint16 2D array (a raw frame) as `.npy`, whole or not at all.
///
/// # Errors
/// I/O errors, with the path.
pub fn write_npy_u16_2d(path: &Path, data: &[u16], rows: usize, cols: usize) -> anyhow::Result<()> {
    write_npy_2d(path, data, rows, cols)
}

/// Writes an f32 2D `.npy` array (a disparity map), whole or not at all.
///
/// # Errors
/// I/O errors, with the path.
pub fn write_npy_f32_2d(path: &Path, data: &[f32], rows: usize, cols: usize) -> anyhow::Result<()> {
    write_npy_2d(path, data, rows, cols)
}

/// As [`write_npy_f32_2d`], left in its temporary file to be persisted with the run's other
/// outputs ([`crate::io::output::stage`]).
///
/// # Errors
/// The I/O error, with the path.
pub fn stage_npy_f32_2d(path: &Path, data: &[f32], rows: usize, cols: usize) -> anyhow::Result<WholeFile> {
    stage(path, |out| npy_2d(out, data, rows, cols))
}

fn write_npy_2d<T: npyz::AutoSerialize + Copy>(
    path: &Path,
    data: &[T],
    rows: usize,
    cols: usize,
) -> anyhow::Result<()> {
    write_whole(path, |out| npy_2d(out, data, rows, cols))
}

fn npy_2d<T: npyz::AutoSerialize + Copy>(
    out: &mut dyn std::io::Write,
    data: &[T],
    rows: usize,
    cols: usize,
) -> anyhow::Result<()> {
    let mut w = npyz::WriteOptions::new().default_dtype().shape(&[rows as u64, cols as u64]).writer(out).begin_nd()?;
    w.extend(data.iter().copied())?;
    w.finish()?;
    Ok(())
}

/// Reads an f32 2D `.npy` array of `rows x cols` (an error map `slf decode` wrote); a
/// header of another rank, type or size is refused before the body is read.
///
/// # Errors
/// [`NpyError`]: what is wrong and where.
pub fn read_npy_f32_2d(path: &Path, (rows, cols): (usize, usize)) -> Result<Vec<f32>, NpyError> {
    let a = npy::read_checked(path, |s, element| {
        if s != [rows, cols] {
            return Err(format!("want a map of {rows} x {cols} lenslets, this array is {s:?}"));
        }
        if element == npy::Element::U16 {
            return Err("a map holds float32 ('<f4') values, this array uint16".into());
        }
        Ok(())
    })?;
    match a.values {
        Values::F32(v) => Ok(v),
        Values::U16(_) => Err(NpyError::new(path, NpyErrorKind::Shape("a map holds float32 ('<f4') values".into()))),
    }
}

/// Whether a `.npy` header's `shape` and `element` are a raw frame's: `uint16`, two axes,
/// `expect` (rows, cols) where given. Shared by the whole read and the paged one
/// ([`crate::io::paged_frame`]).
///
/// # Errors
/// What differs, in the words of the capture.
pub fn check_frame_header(s: &[usize], element: npy::Element, expect: Option<(usize, usize)>) -> Result<(), String> {
    if s.len() != 2 {
        return Err(format!("a raw frame has 2 axes (H, W), this array {s:?}"));
    }
    if element != npy::Element::U16 {
        return Err("a raw frame holds uint16 ('<u2') values, this array floats".into());
    }
    match expect {
        Some((rows, cols)) if (s[0], s[1]) != (rows, cols) => {
            Err(format!("frame is {} x {}, the capture's frames are {rows} x {cols}", s[0], s[1]))
        }
        _ => Ok(()),
    }
}

/// Reads a uint16 2D `.npy` array (a raw frame): `(data, rows, cols)`; with `expect`, a
/// header of another size is refused before the body is read.
///
/// # Errors
/// [`NpyError`]: what is wrong and where.
pub fn read_npy_u16_2d(path: &Path, expect: Option<(usize, usize)>) -> Result<(Vec<u16>, usize, usize), NpyError> {
    // Rank, type and size from the header, before the body is read.
    let a = npy::read_checked(path, |s, element| check_frame_header(s, element, expect))?;
    match a.values {
        Values::U16(v) => Ok((v, a.shape[0], a.shape[1])),
        Values::F32(_) => {
            Err(NpyError::new(path, NpyErrorKind::Shape("a raw frame holds uint16 ('<u2') values".into())))
        }
    }
}
