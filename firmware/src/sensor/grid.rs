//! The lenslet grid: where a real lenslet array puts each (lenslet, view) on the sensor.
//!
//! A real lenslet array is glued on turned by a few tenths of a degree, its pitch a
//! non-integer number of pixels, its first lenslet off pixel (0, 0). Lenslet `(s, t)`'s
//! micro-image is centred at `offset + s * pitch.0 * (cos, -sin) + t * pitch.1 * (sin, cos)`
//! (sensor `(row, col)`, pixel `(r, c)` covering `[r, r + 1) x [c, c + 1)`), and divided
//! into `U x V` equal view cells. The decoder reads view `(u, v)` of lenslet `(s, t)` from
//! the pixel that holds its view cell's centre ([`LensletGrid::pixel`]): the pixel's own
//! measurement, through its own filter, never a resampling of neighbours behind other
//! filters. The pixel lies within half a pixel of the cell's centre on each axis; where
//! exactly ([`LensletGrid::cell_position`]) tells the solve which cells its square covers
//! (`crate::solver::shares`).
//!
//! The host finds the grid (`slf calibrate`, from the flats) and gives its rotation as a
//! cosine and sine: the device does the same `f32` arithmetic as the host, in the same
//! order, so both read the same pixels. A hexagonal grid would shift every other lenslet
//! row by half a pitch along it; [`LensletGrid::pixel`] and [`LensletGrid::view_of`] are
//! the only places that map, so such a grid changes them and the lenslet counts.

use core::fmt;

/// How far `cos^2 + sin^2` may be from 1.
const UNIT_TOLERANCE: f32 = 1e-4;

/// Why a grid is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GridError {
    /// A number that is not finite.
    NotFinite,
    /// A cosine and sine that are not a rotation's.
    Rotation,
    /// A pitch outside `[views / 2, views * 2]`, or no views.
    Pitch,
    /// A sensor of no pixels.
    Sensor,
}

impl fmt::Display for GridError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotFinite => "a lenslet grid number is not finite",
            Self::Rotation => "the lenslet grid's cosine and sine are not a rotation's",
            Self::Pitch => "the lenslet grid's pitch must be within half and twice the views",
            Self::Sensor => "the lenslet grid's sensor has no pixels",
        })
    }
}

/// A checked lenslet grid (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LensletGrid {
    cos: f32,
    sin: f32,
    pitch: (f32, f32),
    offset: (f32, f32),
    views: (u8, u8),
    sensor: (u16, u16),
}

impl LensletGrid {
    /// The grid of a rotation `(cos, sin)`, `pitch` (pixels per lenslet, rows and
    /// columns), `offset` (lenslet (0, 0)'s micro-image centre), for lenslets of `views`
    /// views on a sensor of `sensor` pixels.
    ///
    /// # Errors
    /// [`GridError`], naming what is out of range.
    pub fn new(
        (cos, sin): (f32, f32),
        pitch: (f32, f32),
        offset: (f32, f32),
        views: (u8, u8),
        sensor: (u16, u16),
    ) -> Result<Self, GridError> {
        let all = [cos, sin, pitch.0, pitch.1, offset.0, offset.1];
        if !all.iter().all(|x| x.is_finite()) {
            return Err(GridError::NotFinite);
        }
        if (cos * cos + sin * sin - 1.0).abs() > UNIT_TOLERANCE {
            return Err(GridError::Rotation);
        }
        let fits = |p: f32, n: u8| n > 0 && p >= f32::from(n) / 2.0 && p <= f32::from(n) * 2.0;
        if !fits(pitch.0, views.0) || !fits(pitch.1, views.1) {
            return Err(GridError::Pitch);
        }
        if sensor.0 == 0 || sensor.1 == 0 {
            return Err(GridError::Sensor);
        }
        Ok(Self { cos, sin, pitch, offset, views, sensor })
    }

    /// The sensor's size `(rows, cols)`: the frames'.
    pub fn sensor(&self) -> (usize, usize) {
        (usize::from(self.sensor.0), usize::from(self.sensor.1))
    }

    /// The views of a lenslet.
    pub fn views(&self) -> (u8, u8) {
        self.views
    }

    /// The rotation's `(cos, sin)`.
    pub fn rotation(&self) -> (f32, f32) {
        (self.cos, self.sin)
    }

    /// Pixels per lenslet, `(rows, cols)`.
    pub fn pitch(&self) -> (f32, f32) {
        self.pitch
    }

    /// Lenslet (0, 0)'s micro-image centre `(row, col)`.
    pub fn offset(&self) -> (f32, f32) {
        self.offset
    }

    /// The sensor pixel `(row, col)` holding the centre of view `(u, v)`'s cell of lenslet
    /// `(s, t)`; `None` off the sensor. Not inlined: the aligned decode's reads keep their
    /// size (inlined, choosing a block's disparity took 8 % more instructions).
    #[inline(never)]
    pub fn pixel(&self, (s, t): (isize, isize), (u, v): (usize, usize)) -> Option<(usize, usize)> {
        let (nu, nv) = (f32::from(self.views.0), f32::from(self.views.1));
        // The cell's centre from the lenslet's, in lenslets along each axis.
        let a = s as f32 + ((u as f32 + 0.5) / nu - 0.5);
        let b = t as f32 + ((v as f32 + 0.5) / nv - 0.5);
        let (da, db) = (a * self.pitch.0, b * self.pitch.1);
        let row = self.offset.0 + (da * self.cos + db * self.sin);
        let col = self.offset.1 + (db * self.cos - da * self.sin);
        let (rows, cols) = (f32::from(self.sensor.0), f32::from(self.sensor.1));
        // `as usize` of a float in [0, 65535) is exact after floor.
        (row >= 0.0 && col >= 0.0 && row < rows && col < cols).then(|| (floor(row) as usize, floor(col) as usize))
    }

    /// The lenslet `(s, t)` and view `(u, v)` whose cell holds sensor pixel `(row, col)`'s
    /// centre; `None` for a pixel before lenslet (0, 0)'s row or column.
    #[inline(never)]
    pub fn view_of(&self, row: usize, col: usize) -> Option<((usize, usize), (usize, usize))> {
        let (a, b) = self.cell_position(row, col)?;
        let (i, j) = (floor(a) as usize, floor(b) as usize);
        let (nu, nv) = (usize::from(self.views.0), usize::from(self.views.1));
        // Views are above 0 by `new`; `checked_*` says so without a panic path.
        let (s, u) = (i.checked_div(nu)?, i.checked_rem(nu)?);
        let (t, v) = (j.checked_div(nv)?, j.checked_rem(nv)?);
        Some(((s, t), (u, v)))
    }

    /// Where sensor pixel `(row, col)`'s centre lies in view cells, `(rows, cols)`: view
    /// cell `(s * U + u, t * V + v)` (view `(u, v)` of lenslet `(s, t)`) spans
    /// `[s U + u, s U + u + 1) x [t V + v, t V + v + 1)`. `None` before lenslet (0, 0)'s
    /// row or column.
    #[inline(always)]
    pub fn cell_position(&self, row: usize, col: usize) -> Option<(f32, f32)> {
        let (nu, nv) = (f32::from(self.views.0), f32::from(self.views.1));
        let (dr, dc) = (row as f32 + 0.5 - self.offset.0, col as f32 + 0.5 - self.offset.1);
        // The inverse rotation, then lenslets, then view cells from the micro-image's corner.
        let a = (dr * self.cos - dc * self.sin) / self.pitch.0 + 0.5;
        let b = (dr * self.sin + dc * self.cos) / self.pitch.1 + 0.5;
        if !(a >= 0.0 && b >= 0.0) {
            return None;
        }
        Some((a * nu, b * nv))
    }

    /// Whether the grid is the aligned sensor's: not turned, a pitch of whole views, and
    /// every view cell exactly one pixel (lenslet (0, 0)'s corner on a pixel corner).
    pub fn is_aligned(&self) -> bool {
        let (nu, nv) = (f32::from(self.views.0), f32::from(self.views.1));
        let whole = |x: f32| floor(x) == x;
        self.cos == 1.0
            && self.sin == 0.0
            && self.pitch == (nu, nv)
            && self.offset.0 >= nu / 2.0
            && self.offset.1 >= nv / 2.0
            && whole(self.offset.0 - nu / 2.0)
            && whole(self.offset.1 - nv / 2.0)
    }

    /// A pixel's side in view cells, `(rows, cols)`: the views over the pitch.
    pub fn pixel_width(&self) -> (f32, f32) {
        (f32::from(self.views.0) / self.pitch.0, f32::from(self.views.1) / self.pitch.1)
    }
}

/// `x` rounded down, for `x` in `[0, 2^23)` (no `floor` in `core`).
#[inline(always)]
fn floor(x: f32) -> f32 {
    let t = x as u32 as f32;
    if t > x { t - 1.0 } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_aligned_grid_reads_each_view_from_its_own_pixel() {
        let g = LensletGrid::new((1.0, 0.0), (5.0, 5.0), (2.5, 2.5), (5, 5), (50, 60)).unwrap();
        for s in 0..10isize {
            for t in 0..12isize {
                for u in 0..5 {
                    for v in 0..5 {
                        let p = (s as usize * 5 + u, t as usize * 5 + v);
                        assert_eq!(g.pixel((s, t), (u, v)), Some(p));
                        assert_eq!(g.view_of(p.0, p.1), Some(((s as usize, t as usize), (u, v))));
                    }
                }
            }
        }
        assert_eq!(g.pixel((10, 0), (0, 0)), None);
        assert_eq!(g.pixel((-1, 0), (4, 0)), None);
    }

    #[test]
    fn a_turned_grid_reads_the_pixel_under_each_cell_centre() {
        let deg = 0.8f64.to_radians();
        let (pitch, offset) = ((5.1f32, 4.95f32), (3.2f32, 1.9f32));
        let g = LensletGrid::new((deg.cos() as f32, deg.sin() as f32), pitch, offset, (5, 5), (400, 400)).unwrap();
        for (s, t, u, v) in [(0, 0, 2, 2), (13, 40, 0, 4), (70, 5, 4, 1)] {
            // The cell centre in f64, from the module docs' formula.
            let a = s as f64 + (u as f64 + 0.5) / 5.0 - 0.5;
            let b = t as f64 + (v as f64 + 0.5) / 5.0 - 0.5;
            let (da, db) = (a * f64::from(pitch.0), b * f64::from(pitch.1));
            let row = f64::from(offset.0) + da * deg.cos() + db * deg.sin();
            let col = f64::from(offset.1) - da * deg.sin() + db * deg.cos();
            assert_eq!(g.pixel((s, t), (u, v)), Some((row.floor() as usize, col.floor() as usize)));
        }
        // And a pixel's own cell: its centre turned back, in view cells, in f64.
        for (r, c) in [(0usize, 0usize), (3, 250), (211, 17), (399, 399)] {
            let (dr, dc) = (r as f64 + 0.5 - f64::from(offset.0), c as f64 + 0.5 - f64::from(offset.1));
            let a = (dr * deg.cos() - dc * deg.sin()) / f64::from(pitch.0) + 0.5;
            let b = (dr * deg.sin() + dc * deg.cos()) / f64::from(pitch.1) + 0.5;
            let want = (a >= 0.0 && b >= 0.0).then(|| {
                let (i, j) = ((a * 5.0).floor() as usize, (b * 5.0).floor() as usize);
                ((i / 5, j / 5), (i % 5, j % 5))
            });
            assert_eq!(g.view_of(r, c), want, "pixel ({r}, {c})");
        }
    }

    #[test]
    fn grids_out_of_range_are_refused() {
        let ok = ((1.0, 0.0), (5.0, 5.0), (2.5, 2.5), (5, 5), (10, 10));
        assert!(LensletGrid::new(ok.0, ok.1, ok.2, ok.3, ok.4).is_ok());
        assert_eq!(LensletGrid::new((1.0, 0.1), ok.1, ok.2, ok.3, ok.4), Err(GridError::Rotation));
        assert_eq!(LensletGrid::new(ok.0, (2.0, 5.0), ok.2, ok.3, ok.4), Err(GridError::Pitch));
        assert_eq!(LensletGrid::new(ok.0, ok.1, (f32::NAN, 0.0), ok.3, ok.4), Err(GridError::NotFinite));
        assert_eq!(LensletGrid::new(ok.0, ok.1, ok.2, (0, 5), ok.4), Err(GridError::Pitch));
        assert_eq!(LensletGrid::new(ok.0, ok.1, ok.2, ok.3, (0, 10)), Err(GridError::Sensor));
    }
}
