//! The lenslet grid: where a real lenslet array sits on the sensor (issue 52).
//!
//! A lenslet array is glued on with a rotation of a few tenths of a degree, its pitch is a
//! non-integer number of pixels, and its first lenslet is not on pixel (0, 0). A
//! [`GridDescription`] says all three, as `capture.json` and `calibration.json` record it
//! (`lenslet_grid`), and maps a point of the sensor to its place in the light field.
//!
//! Coordinates. A sensor point is `(row, col)` in pixels, `(0, 0)` the top-left corner of
//! pixel `(0, 0)` (its centre is `(0.5, 0.5)`). Lenslet `(s, t)`'s micro-image is centred
//! at `offset + R (s * pitch[0], t * pitch[1])`, where `R` turns the lenslet columns' axis
//! `(0, 1)` to `(sin a, cos a)` and the rows' axis `(1, 0)` to `(cos a, -sin a)`:
//! `rotation_deg` positive tilts the lenslet rows down to the right, as a frame is shown
//! (row 0 on top). The grid's *view cells* divide each micro-image into `U x V` equal
//! cells, the views: a sensor point lies in view cell `(i, j)` = `(s U + u, t V + v)`, at
//! cell coordinates `q = (d_row / pitch[0] * U + U / 2, d_col / pitch[1] * V + V / 2)`,
//! `d = R^T (point - offset)`. On the aligned grid (no rotation, pitch `(U, V)`, offset
//! `(U / 2, V / 2)`) pixel `(s U + u, t V + v)` is exactly view cell `(s U + u, t V + v)`:
//! what slf assumed before grids.
//!
//! The grid is the micro-images' grid, as the light-field toolboxes find it from a white
//! image (Dansereau et al. 2013): its pitch includes the main lens's chief-ray spread, so
//! a view is an angle relative to the main lens, which is what the decode needs.
//!
//! Two places map a point to a cell: [`GridDescription::cell`] (f64) for the simulator's
//! area shares, the physics the tests check against, and the firmware's `LensletGrid`
//! (`pixel`, `cell_position`, `view_of`; f32, [`GridDescription::firmware`]) for the decode
//! and for the calibration's per-view flat, so those two agree on every pixel. A hexagonal
//! grid (Lytro's) would give every other lenslet row a shift of half a pitch along the row,
//! and its view cells would be a hexagon's: both places change, with the cell polygon.

use anyhow::{Result, ensure};
use serde::{Deserialize, Serialize};
use slf_firmware::LensletGrid;

use crate::io::message::number;

/// `v` as [`number`] writes it.
fn number_f64(v: f64) -> String {
    number(v as f32)
}

/// The largest rotation a grid may state, degrees: a lenslet array glued on more than a few
/// degrees off is not aligned but turned, and its sensor would lose whole lenslet rows.
pub const MAX_ROTATION_DEG: f64 = 10.0;

/// How far a grid's pitch may lie from its views, as a fraction (5 views: 4 to 6 px).
pub const MAX_PITCH_OFF: f64 = 0.2;

/// `lenslet_grid` in `capture.json` and `calibration.json`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridDescription {
    /// The lenslet rows' angle to the sensor's rows, degrees; positive turns them down to
    /// the right.
    pub rotation_deg: f64,
    /// Pixels from one micro-image centre to the next `[down a column, along a row]`.
    pub pitch: [f64; 2],
    /// The sensor point `[row, col]` of lenslet (0, 0)'s micro-image centre, pixels.
    pub offset: [f64; 2],
    /// The sensor's size `[rows, cols]` in pixels: the frames'.
    pub sensor: [usize; 2],
    /// How far the micro-image centres a calibration found lie from this grid, RMS
    /// pixels (`slf calibrate`'s; absent on a grid that was stated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centres_rms_px: Option<f64>,
    /// How a calibration named its lenslets: the sensor point its captures stated for
    /// lenslet (0, 0), whose nearest point of the found lattice it calls (0, 0)
    /// (`slf calibrate`'s; absent on a stated grid, and on calibrations made before it was
    /// recorded, which called (0, 0) the micro-image nearest the centred array's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indexed_at: Option<[f64; 2]>,
}

/// How far from a point of a calibration's lattice a capture may put its lenslet (0, 0),
/// in pitches, and still name that lenslet: farther, the two grids do not say which
/// lenslet is which ([`GridDescription::indexed_as`]).
pub const MAX_INDEX_OFF: f64 = 0.25;

impl GridDescription {
    /// The aligned grid of `lenslets` lenslets of `views` views: what slf assumes without
    /// a grid.
    pub fn aligned(lenslets: [usize; 2], views: [usize; 2]) -> Self {
        Self {
            rotation_deg: 0.0,
            pitch: [views[0] as f64, views[1] as f64],
            offset: [views[0] as f64 / 2.0, views[1] as f64 / 2.0],
            sensor: [lenslets[0] * views[0], lenslets[1] * views[1]],
            centres_rms_px: None,
            indexed_at: None,
        }
    }

    /// The grid `rotation_deg` and `pitch` describe, centred on a sensor just large enough
    /// for `lenslets` lenslets unrotated (`round(S * pitch)` x `round(T * pitch)`): the array's
    /// middle on the sensor's middle, its corners cut off by a rotation as a real sensor
    /// cuts them.
    pub fn centred(lenslets: [usize; 2], rotation_deg: f64, pitch: [f64; 2]) -> Self {
        let sensor =
            [(lenslets[0] as f64 * pitch[0]).round() as usize, (lenslets[1] as f64 * pitch[1]).round() as usize];
        let mid = [(lenslets[0] as f64 - 1.0) / 2.0 * pitch[0], (lenslets[1] as f64 - 1.0) / 2.0 * pitch[1]];
        let turned = rotate(rotation_deg, mid);
        Self {
            rotation_deg,
            pitch,
            offset: [sensor[0] as f64 / 2.0 - turned[0], sensor[1] as f64 / 2.0 - turned[1]],
            sensor,
            centres_rms_px: None,
            indexed_at: None,
        }
    }

    /// Whether this is exactly the aligned grid of `lenslets` x `views` (then the decode
    /// and the simulator take the aligned path, and give the same bytes as before grids).
    pub fn is_aligned(&self, lenslets: [usize; 2], views: [usize; 2]) -> bool {
        Self { centres_rms_px: None, indexed_at: None, ..*self } == Self::aligned(lenslets, views)
    }

    /// Checks the grid against a light field of `lenslets` x `views`.
    ///
    /// # Errors
    /// A message naming the field out of its range.
    pub fn check(&self, lenslets: [usize; 2], views: [usize; 2]) -> Result<()> {
        ensure!(
            self.rotation_deg.is_finite() && self.rotation_deg.abs() <= MAX_ROTATION_DEG,
            "lenslet_grid.rotation_deg {}: must be within +-{MAX_ROTATION_DEG} degrees",
            number_f64(self.rotation_deg)
        );
        #[allow(clippy::needless_range_loop)] // four arrays, one axis
        for a in 0..2 {
            let n = views[a] as f64;
            ensure!(
                self.pitch[a].is_finite() && (self.pitch[a] - n).abs() <= MAX_PITCH_OFF * n,
                "lenslet_grid.pitch[{a}] {} px: must be within {} % of the {} views (a micro-image of {} to {} px)",
                number_f64(self.pitch[a]),
                MAX_PITCH_OFF * 100.0,
                views[a],
                number_f64(n * (1.0 - MAX_PITCH_OFF)),
                number_f64(n * (1.0 + MAX_PITCH_OFF))
            );
            ensure!(
                (1..=usize::from(u16::MAX)).contains(&self.sensor[a]),
                "lenslet_grid.sensor[{a}] {}: must be in 1..={}",
                self.sensor[a],
                u16::MAX
            );
            // The grid must put the light field's lenslets on the sensor, not beside it.
            let reach = lenslets[0] as f64 * self.pitch[0] + lenslets[1] as f64 * self.pitch[1];
            ensure!(
                self.offset[a].is_finite() && self.offset[a].abs() <= reach + self.sensor[a] as f64,
                "lenslet_grid.offset[{a}] {} px: lenslet (0, 0) must lie on or near the {} x {} sensor",
                number_f64(self.offset[a]),
                self.sensor[0],
                self.sensor[1]
            );
        }
        // Most of the array on the sensor: its middle lenslet's centre on it (an offset of
        // 200, 200 on 24 x 24 lenslets of 5 px once put every lenslet beside the sensor,
        // exit 0, and a decode of nothing).
        let mid = self.centre((lenslets[0] as f64 - 1.0) / 2.0, (lenslets[1] as f64 - 1.0) / 2.0);
        ensure!(
            (0..2).all(|a| (0.0..self.sensor[a] as f64).contains(&mid[a])),
            "lenslet_grid.offset {}, {} px: the middle of the {} x {} lenslet array falls at ({:.1}, {:.1}), off the {} \
             x {} sensor (a part of the array may reach past its edges, not most of it)",
            number_f64(self.offset[0]),
            number_f64(self.offset[1]),
            lenslets[0],
            lenslets[1],
            mid[0],
            mid[1],
            self.sensor[0],
            self.sensor[1]
        );
        if let Some(r) = self.centres_rms_px {
            ensure!(r.is_finite() && r >= 0.0, "lenslet_grid.centres_rms_px {}: must be at or above 0", number_f64(r));
        }
        if let Some(p) = self.indexed_at {
            ensure!(
                p.iter().all(|x| x.is_finite()),
                "lenslet_grid.indexed_at {}, {}: must be a sensor point",
                number_f64(p[0]),
                number_f64(p[1])
            );
        }
        Ok(())
    }

    /// The micro-image centre of lenslet `(s, t)`, a sensor point.
    pub fn centre(&self, s: f64, t: f64) -> [f64; 2] {
        let d = rotate(self.rotation_deg, [s * self.pitch[0], t * self.pitch[1]]);
        [self.offset[0] + d[0], self.offset[1] + d[1]]
    }

    /// The lattice coordinates of sensor point `p`: the lenslet `(s, t)` whose centre
    /// [`Self::centre`] puts there, fractional between centres.
    pub fn lattice(&self, p: [f64; 2]) -> [f64; 2] {
        let d = rotate(-self.rotation_deg, [p[0] - self.offset[0], p[1] - self.offset[1]]);
        [d[0] / self.pitch[0], d[1] / self.pitch[1]]
    }

    /// This grid (a calibration's, found from its flats) with its lenslets named as
    /// `stated` (the capture's) names them: its lenslet (0, 0) moved to its lattice point
    /// nearest `stated`'s lenslet (0, 0), and the whole lenslets `(s, t)` it moved. A
    /// calibration indexed at the very point `stated` names is taken as it is.
    ///
    /// A calibration once called (0, 0) the micro-image nearest the centred array's, and a
    /// capture stating its array at the sensor's corner was decoded 6 lenslets off, at
    /// 10.65 dB against 25.38 dB, with exit 0.
    ///
    /// # Errors
    /// `stated`'s lenslet (0, 0) lies between this grid's lenslets (more than
    /// [`MAX_INDEX_OFF`] of a pitch from the nearest), so the two do not say which lenslet
    /// is which: the message names both; or the moved grid puts the array off the sensor.
    pub fn indexed_as(&self, stated: &Self, lenslets: [usize; 2], views: [usize; 2]) -> Result<(Self, [i64; 2])> {
        if self.indexed_at == Some(stated.offset) {
            return Ok((*self, [0, 0]));
        }
        let at = self.lattice(stated.offset);
        let near = [at[0].round(), at[1].round()];
        let off = (at[0] - near[0]).abs().max((at[1] - near[1]).abs());
        ensure!(
            off <= MAX_INDEX_OFF,
            "the calibration's lenslet grid puts lenslet (0, 0) at ({:.2}, {:.2}) px and the capture's at ({:.2}, {:.2}) \
             px, {:.2} of a pitch from any of the calibration's lenslets: the two do not say which lenslet is which \
             (give --grid capture to decode with the capture's own grid, or state the capture's lenslet_grid.offset at \
             a micro-image centre)",
            self.offset[0],
            self.offset[1],
            stated.offset[0],
            stated.offset[1],
            off
        );
        let moved = Self { offset: self.centre(near[0], near[1]), indexed_at: Some(stated.offset), ..*self };
        moved.check(lenslets, views).map_err(|e| {
            anyhow::anyhow!(
                "the calibration's lenslet grid named as the capture's (lenslet (0, 0) at ({:.2}, {:.2}) px): {e}",
                stated.offset[0],
                stated.offset[1]
            )
        })?;
        Ok((moved, [near[0] as i64, near[1] as i64]))
    }

    /// The view-cell coordinates of sensor point `p` for `views` views: cell
    /// `(floor(q0), floor(q1))` = `(s U + u, t V + v)` holds it (module docs).
    pub fn cell(&self, views: [usize; 2], p: [f64; 2]) -> [f64; 2] {
        let l = self.lattice(p);
        let q = |a: usize| l[a] * views[a] as f64 + views[a] as f64 / 2.0;
        [q(0), q(1)]
    }
}

impl GridDescription {
    /// The firmware's grid for lenslets of `views` views (the rotation as its `f32` cosine
    /// and sine, computed here in `f64`: the device is given the same numbers).
    ///
    /// # Errors
    /// What the firmware refuses (checked here first, so not expected).
    pub fn firmware(&self, views: [usize; 2]) -> Result<LensletGrid> {
        let (sin, cos) = self.rotation_deg.to_radians().sin_cos();
        LensletGrid::new(
            (cos as f32, sin as f32),
            (self.pitch[0] as f32, self.pitch[1] as f32),
            (self.offset[0] as f32, self.offset[1] as f32),
            (views[0] as u8, views[1] as u8),
            (self.sensor[0] as u16, self.sensor[1] as u16),
        )
        .map_err(|e| anyhow::anyhow!("lenslet_grid: {e}"))
    }
}

/// What of a light field a grid puts off its sensor: view cells whose centres no pixel
/// holds, never measured (the decode's guesses from their neighbours). A turned array
/// centred on a sensor its own size ([`GridDescription::centred`]) puts its corners past
/// the sensor's edges. Such lenslets are marked in `slf decode --coverage-map` and left out
/// of the decode's estimated PSNR ([`OffSensor::left_out`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OffSensor {
    /// Lenslets with at least one view off the sensor.
    pub lenslets: usize,
    /// Their views off the sensor, all told.
    pub views: usize,
    /// Each such lenslet `[s, t]`, with the share of its views on the sensor (below 1): a
    /// turned array's edges, so about its perimeter's length.
    pub partial: Vec<([usize; 2], f32)>,
}

impl OffSensor {
    /// Of `lenslets` lenslets behind `grid`, as the decode reads them: the view cells
    /// whose centre [`LensletGrid::pixel`] finds no pixel under.
    pub fn of(grid: &LensletGrid, lenslets: [usize; 2]) -> Self {
        let (nu, nv) = grid.views();
        let all = usize::from(nu) * usize::from(nv);
        let mut off = Self::default();
        for s in 0..lenslets[0] {
            for t in 0..lenslets[1] {
                let cells = (0..usize::from(nu))
                    .flat_map(|u| (0..usize::from(nv)).map(move |v| (u, v)))
                    .filter(|&uv| grid.pixel((s as isize, t as isize), uv).is_none())
                    .count();
                if cells > 0 {
                    off.views += cells;
                    off.lenslets += 1;
                    off.partial.push(([s, t], (all - cells) as f32 / all as f32));
                }
            }
        }
        off
    }

    /// Each of the `[rows, cols]` lenslets' share of views on the sensor, row-major: 1 but
    /// for the lenslets that reach past it (`slf decode --coverage-map`).
    pub fn coverage(&self, [rows, cols]: [usize; 2]) -> Vec<f32> {
        let mut map = vec![1.0; rows * cols];
        for &([s, t], share) in &self.partial {
            if let Some(m) = map.get_mut(s * cols + t) {
                *m = share;
            }
        }
        map
    }

    /// A per-lenslet map (`cols` lenslets a row) with the lenslets that reach past the sensor
    /// NaN: their guessed views are no figure of the decode's.
    pub fn left_out(&self, map: &[f32], cols: usize) -> Vec<f32> {
        let mut out = map.to_vec();
        for &([s, t], _) in &self.partial {
            if let Some(m) = out.get_mut(s * cols + t) {
                *m = f32::NAN;
            }
        }
        out
    }
}

/// View cell `cell` (`(s U + u, t V + v)`, [`GridDescription::cell`]'s whole parts) as
/// lenslet `(s, t)` and view `(u, v)`; `None` outside the light field's `lenslets`.
pub fn lenslet_view(cell: [i64; 2], lenslets: [usize; 2], views: [usize; 2]) -> Option<([usize; 2], [usize; 2])> {
    let split = |a: usize| {
        let n = views[a] as i64;
        let l = usize::try_from(cell[a].div_euclid(n)).ok().filter(|&l| l < lenslets[a])?;
        Some((l, cell[a].rem_euclid(n) as usize))
    };
    let ((s, u), (t, v)) = (split(0)?, split(1)?);
    Some(([s, t], [u, v]))
}

/// `v` turned by `deg` degrees: the columns' axis `(0, 1)` to `(sin, cos)`.
pub fn rotate(deg: f64, v: [f64; 2]) -> [f64; 2] {
    let (sin, cos) = deg.to_radians().sin_cos();
    [v[0] * cos + v[1] * sin, -v[0] * sin + v[1] * cos]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_aligned_grid_puts_each_pixel_in_its_own_view_cell() {
        let g = GridDescription::aligned([3, 4], [5, 5]);
        assert_eq!(GridDescription::centred([3, 4], 0.0, [5.0, 5.0]), g);
        g.check([3, 4], [5, 5]).unwrap();
        for row in 0..15 {
            for col in 0..20 {
                let q = g.cell([5, 5], [row as f64 + 0.5, col as f64 + 0.5]);
                assert_eq!([q[0].floor(), q[1].floor()], [row as f64, col as f64]);
            }
        }
        assert_eq!(g.centre(1.0, 2.0), [7.5, 12.5]);
    }

    #[test]
    fn centres_and_cells_agree_on_a_turned_grid() {
        let g = GridDescription::centred([20, 30], 0.7, [5.04, 4.97]);
        g.check([20, 30], [5, 5]).unwrap();
        for (s, t) in [(0.0, 0.0), (3.0, 17.0), (19.0, 29.0)] {
            // A micro-image centre is the middle of its lenslet's cells: (s U + 2.5, t V + 2.5).
            let q = g.cell([5, 5], g.centre(s, t));
            assert!((q[0] - (5.0 * s + 2.5)).abs() < 1e-9 && (q[1] - (5.0 * t + 2.5)).abs() < 1e-9, "{q:?}");
        }
        // Down one lenslet column moves along (cos, -sin): the rows tilt down to the right.
        let (a, b) = (g.centre(0.0, 0.0), g.centre(0.0, 1.0));
        assert!(b[0] > a[0] && (b[0] - a[0] - 4.97 * 0.7f64.to_radians().sin()).abs() < 1e-12);
    }

    #[test]
    fn views_off_the_sensor_are_counted() {
        // The aligned grid: every view on the sensor.
        let off = |g: &GridDescription, lenslets: [usize; 2]| OffSensor::of(&g.firmware([5, 5]).unwrap(), lenslets);
        assert_eq!(off(&GridDescription::aligned([4, 6], [5, 5]), [4, 6]), OffSensor::default());
        // Moved a lenslet left: the first lenslet column lies wholly off the sensor, and the
        // last column's right neighbour would be on it (no lenslet there to count).
        let mut g = GridDescription::aligned([4, 6], [5, 5]);
        g.offset[1] -= 5.0;
        let column: Vec<_> = (0..4).map(|s| ([s, 0], 0.0)).collect();
        assert_eq!(off(&g, [4, 6]), OffSensor { lenslets: 4, views: 4 * 25, partial: column });
        // Moved 2.2 px up: the first lenslet row's top two view rows (centres at 0.5 and 1.5
        // px, now above the top edge) of every lenslet in it.
        let mut g = GridDescription::aligned([4, 6], [5, 5]);
        g.offset[0] -= 2.2;
        let row: Vec<_> = (0..6).map(|t| ([0, t], 0.6)).collect();
        assert_eq!(off(&g, [4, 6]), OffSensor { lenslets: 6, views: 6 * 2 * 5, partial: row });
        // Marked in the coverage map, and left out of a per-lenslet map's figures.
        let coverage = off(&g, [4, 6]).coverage([4, 6]);
        assert!(coverage.iter().enumerate().all(|(i, &c)| c == if i < 6 { 0.6 } else { 1.0 }), "{coverage:?}");
        let left = off(&g, [4, 6]).left_out(&[0.5; 24], 6);
        assert!(left.iter().enumerate().all(|(i, e)| e.is_nan() == (i < 6)), "{left:?}");
        // Turned a degree on a sensor its own size: some corner views are off, and only
        // lenslets near the edges have any.
        let g = GridDescription::centred([64, 64], 1.0, [5.1, 5.1]);
        let turned = off(&g, [64, 64]);
        assert!(turned.lenslets > 0 && turned.views >= turned.lenslets, "{turned:?}");
        assert!(turned.lenslets < 4 * 64, "only edge lenslets: {turned:?}");
    }

    #[test]
    fn grids_out_of_range_are_refused_by_field() {
        let ok = GridDescription::centred([10, 10], 0.3, [5.02, 5.02]);
        for (bad, says) in [
            (GridDescription { rotation_deg: 45.0, ..ok }, "rotation_deg"),
            (GridDescription { pitch: [5.0, 7.0], ..ok }, "pitch[1]"),
            (GridDescription { pitch: [f64::NAN, 5.0], ..ok }, "pitch[0]"),
            (GridDescription { sensor: [0, 50], ..ok }, "sensor[0]"),
            (GridDescription { offset: [1e9, 0.0], ..ok }, "offset[0]"),
            (GridDescription { centres_rms_px: Some(-1.0), ..ok }, "centres_rms_px"),
        ] {
            let e = bad.check([10, 10], [5, 5]).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn a_found_grid_is_named_as_the_stated_one() {
        // A calibration's grid (turned, non-integer pitch), and captures stating lenslet
        // (0, 0) at its lenslet (s, t) give or take a tenth of a pitch: moved by (s, t).
        let found = GridDescription::centred([30, 40], 0.6, [5.03, 4.98]);
        for (s, t, jitter) in [(0.0, 0.0, 0.1), (2.0, -3.0, -0.1), (-1.0, 4.0, 0.2)] {
            let at = found.centre(s + jitter, t - jitter);
            let stated = GridDescription { offset: at, ..GridDescription::aligned([30, 40], [5, 5]) };
            let (moved, by) = found.indexed_as(&stated, [30, 40], [5, 5]).unwrap();
            assert_eq!(by, [s as i64, t as i64]);
            let want = found.centre(s, t);
            assert!((moved.offset[0] - want[0]).abs() < 1e-9 && (moved.offset[1] - want[1]).abs() < 1e-9);
            assert_eq!(moved.indexed_at, Some(at));
            // Every lenslet of the moved grid is the found grid's lenslet (s, t) further.
            let c = moved.centre(7.0, 9.0);
            let f = found.centre(7.0 + s, 9.0 + t);
            assert!((c[0] - f[0]).abs() < 1e-9 && (c[1] - f[1]).abs() < 1e-9);
            // Named at that very point again: taken as it is.
            assert_eq!(moved.indexed_as(&stated, [30, 40], [5, 5]).unwrap(), (moved, [0, 0]));
        }
        // Between two lenslets: refused, naming both.
        let between = GridDescription { offset: found.centre(1.4, 0.0), ..found };
        let e = found.indexed_as(&between, [30, 40], [5, 5]).unwrap_err().to_string();
        assert!(e.contains("0.40 of a pitch") && e.contains("the capture's at"), "{e}");
    }
}
