//! A light field written a lenslet row at a time: where a streamed decode puts its finished
//! rows ([`RowSink`]), in memory ([`LightField`]) or in a file ([`crate::io::npy_rows`]).
//!
//! A row is every value of one spatial row `y` of the `(U, V, H, W, B)` light field: `U x V
//! x W x B` values, views outermost, so each view's part of the row is one contiguous run of
//! the light field's memory (and of its `.npy` file's data).

use anyhow::{Result, ensure};
pub use slf_firmware::decode::engine::rows::RowSink;

use crate::io::lightfield::LightField;

/// The host's row sinks: the firmware's [`RowSink`] (the one the decode engine puts its
/// finished rows into), failing with an `anyhow` error, taking whole rows (first column 0).
pub type Rows<'a> = dyn RowSink<Error = anyhow::Error> + 'a;

/// Puts row `y` of a whole width into `sink`.
///
/// # Errors
/// A row past the 65,535 a tile's `u16` names, or what the sink returns.
pub fn put_row(sink: &mut Rows<'_>, y: usize, row: &[f32]) -> Result<()> {
    let y = u16::try_from(y).map_err(|_| anyhow::anyhow!("lenslet row {y}: at most 65,535 rows"))?;
    sink.row(y, 0, row)
}

/// A sink that refuses the next row once `stop` is set: a run stopped from outside (Python's
/// `KeyboardInterrupt`, an exception in a progress callback) ends at its next finished row
/// with an error, and the file sink behind it is dropped unfinished (nothing written).
pub struct Stoppable<'a, 'b> {
    pub inner: &'a mut Rows<'b>,
    pub stop: &'a std::sync::atomic::AtomicBool,
}

impl RowSink for Stoppable<'_, '_> {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        ensure!(!self.stop.load(std::sync::atomic::Ordering::Relaxed), "stopped at lenslet row {y}: nothing written");
        self.inner.row(y, first_col, row)
    }
}

/// Checks that a row put to a host sink is of the whole width (first column 0).
///
/// # Errors
/// A row of a band of columns.
pub fn whole_width(first_col: u16) -> Result<()> {
    ensure!(first_col == 0, "a row from lenslet column {first_col}: this sink takes whole rows");
    Ok(())
}

/// The shape of the rows a sink takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowShape {
    /// Views: rows `U`, columns `V`.
    pub views: (usize, usize),
    /// Spatial rows `H`: rows `0..rows` are put once each, in order.
    pub rows: usize,
    /// Spatial columns `W`.
    pub cols: usize,
    /// Bands `B`.
    pub bands: usize,
}

impl RowShape {
    /// Values in one row: `U x V x W x B`.
    pub fn row_len(&self) -> usize {
        self.views.0 * self.views.1 * self.cols * self.bands
    }

    /// Values of one view in one row: `W x B`.
    pub fn run_len(&self) -> usize {
        self.cols * self.bands
    }

    /// Pixels in one row: `U x V x W`.
    pub fn pixels(&self) -> usize {
        self.views.0 * self.views.1 * self.cols
    }

    /// Index of pixel `(u, v, x)` in a row's pixels (times the bands: of its first value).
    #[inline]
    pub fn pixel(&self, u: usize, v: usize, x: usize) -> usize {
        (u * self.views.1 + v) * self.cols + x
    }

    /// Index in a row of `(u, v, x, b)`.
    #[inline]
    pub fn at(&self, u: usize, v: usize, x: usize, b: usize) -> usize {
        ((u * self.views.1 + v) * self.cols + x) * self.bands + b
    }

    /// The shape as `[U, V, H, W, B]`.
    pub fn shape(&self) -> [usize; 5] {
        [self.views.0, self.views.1, self.rows, self.cols, self.bands]
    }

    /// Checks that a light field of this shape may be held ([`LightField::check_size`]).
    ///
    /// # Errors
    /// An empty axis, or more values than [`LightField::MAX_VALUES`].
    pub fn check(&self) -> Result<()> {
        LightField::check_size(self.views, self.rows, self.cols, self.bands)
    }

    /// A light field of this shape, zeros, its size checked before it is allocated.
    ///
    /// # Errors
    /// As [`Self::check`].
    pub fn zeros(&self) -> Result<LightField> {
        self.check()?;
        Ok(LightField::zeros(self.views, self.rows, self.cols, self.bands))
    }
}

/// Checks that `row` is row `y` of `shape` and the one a file sink of `path` takes next
/// (`next`), and that every value is finite: slf writes no light field it would refuse to
/// read (as [`crate::io::lightfield::write_npy`]).
///
/// # Errors
/// A row out of order, of the wrong length, or holding a NaN or an infinity.
pub fn check_row(shape: RowShape, next: usize, y: usize, row: &[f32], path: &std::path::Path) -> Result<()> {
    ensure!(
        y == next && y < shape.rows && row.len() == shape.row_len(),
        "row {y} of {} values put out of order (row {next} next, {} values a row)",
        row.len(),
        shape.row_len()
    );
    if let Some(i) = row.iter().position(|x| !x.is_finite()) {
        anyhow::bail!("cannot write {}: a value that is not finite in row {y} (at {i})", path.display());
    }
    Ok(())
}

/// A light field in memory, filled a row at a time (a decode into memory: the Python
/// package's return value, the evaluations').
impl RowSink for LightField {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        whole_width(first_col)?;
        let y = usize::from(y);
        let shape = RowShape { views: self.views, rows: self.rows, cols: self.cols, bands: self.bands };
        ensure!(y < self.rows && row.len() == shape.row_len(), "row {y} of {} values does not fit", row.len());
        let run = shape.run_len();
        for (p, values) in row.chunks_exact(run).enumerate() {
            let at = (p * self.rows + y) * run;
            self.data[at..at + run].copy_from_slice(values);
        }
        Ok(())
    }
}

/// Puts every row of `lf` into `sink`, in order (a decode made whole, a baseline's).
///
/// # Errors
/// What the sink returns.
pub fn put_light_field(lf: &LightField, sink: &mut Rows<'_>) -> Result<()> {
    let shape = RowShape { views: lf.views, rows: lf.rows, cols: lf.cols, bands: lf.bands };
    let run = shape.run_len();
    let mut row = vec![0.0; shape.row_len()];
    for y in 0..lf.rows {
        for (p, values) in row.chunks_exact_mut(run).enumerate() {
            let at = (p * lf.rows + y) * run;
            values.copy_from_slice(&lf.data[at..at + run]);
        }
        put_row(sink, y, &row)?;
    }
    Ok(())
}

/// A sink that passes each row on after `f` has changed it in place (a calibrated decode's
/// unmixing of every spectrum).
pub struct MapRows<'a, F> {
    inner: &'a mut Rows<'a>,
    f: F,
    row: Vec<f32>,
}

impl<'a, F: FnMut(&mut [f32])> MapRows<'a, F> {
    /// Rows through `f` into `inner`.
    pub fn new(inner: &'a mut Rows<'a>, f: F) -> Self {
        Self { inner, f, row: Vec::new() }
    }
}

impl<F: FnMut(&mut [f32])> RowSink for MapRows<'_, F> {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, first_col: u16, row: &[f32]) -> Result<()> {
        self.row.clear();
        self.row.extend_from_slice(row);
        (self.f)(&mut self.row);
        self.inner.row(y, first_col, &self.row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_put_into_a_light_field_land_where_its_index_says() {
        let (views, rows, cols, bands) = ((2, 3), 4, 5, 3);
        let want = LightField::from_fn(views, rows, cols, bands, |u, v, y, x, b| {
            (u * 10_000 + v * 1000 + y * 100 + x * 10 + b) as f32
        });
        let shape = RowShape { views, rows, cols, bands };
        let mut got = LightField::zeros(views, rows, cols, bands);
        for y in 0..rows {
            let mut row = vec![0.0; shape.row_len()];
            for u in 0..views.0 {
                for v in 0..views.1 {
                    for x in 0..cols {
                        for b in 0..bands {
                            row[shape.at(u, v, x, b)] = want.get(u, v, y, x, b);
                        }
                    }
                }
            }
            put_row(&mut got, y, &row).unwrap();
        }
        assert_eq!(got, want);
        assert!(put_row(&mut got, rows, &vec![0.0; shape.row_len()]).is_err());
        assert!(put_row(&mut got, 0, &[0.0; 3]).is_err());
        assert!(got.row(0, 1, &vec![0.0; shape.row_len()]).is_err(), "a band's row");
    }
}
