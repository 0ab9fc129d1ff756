//! A lenslet row's measurements, read from the raw frames exactly as the CS decoder reads
//! them: the firmware's mask, raw format and defect list (saturated, defective and
//! non-finite samples are not measurements).
//!
//! Behind a turned lenslet grid each view cell reads the sensor pixel under its centre
//! (the firmware's [`LensletGrid::pixel`], as the CS decode's half-pixel patches read it),
//! with that pixel's filters: the baselines then see the mosaic as an aligned array of view
//! cells, as they do on an aligned sensor. A cell whose centre lies past the sensor's edge
//! has no measurement (filled from its neighbours, as an invalid sample is).

use anyhow::Result;
use slf_firmware::{DefectList, LensletGrid, Mask, RawFormat};

use slf_firmware::Frame;

use crate::io::capture::Capture;
use crate::io::frames::SensorFrame;

/// Reads lenslet rows of one capture.
pub(super) struct Reader<'a> {
    capture: &'a Capture,
    frames: Vec<SensorFrame<'a>>,
    mask: Mask<'a>,
    raw: RawFormat,
    defects: DefectList<'a>,
    cols: usize,
    /// The turned grid the frames are read through (`None`: the aligned sensor).
    grid: Option<LensletGrid>,
    /// Views `(U, V)`.
    pub views: (usize, usize),
    /// Lenslets `(S, T)`.
    pub lenslets: (usize, usize),
    /// Bands.
    pub bands: usize,
}

/// One lenslet row's valid samples `(band, value)`: lenslet by lenslet, view by view in
/// `(u, v)` order, each view's in snapshot order.
pub(super) struct LensletRow {
    taken: Vec<(u8, f32)>,
    /// Where each `(t, u, v)` position's samples start in `taken`, and one end.
    start: Vec<usize>,
    views: usize,
}

impl<'a> Reader<'a> {
    /// A reader of `capture`'s rows.
    ///
    /// # Errors
    /// A capture whose mask cannot be built.
    pub(super) fn new(capture: &'a Capture) -> Result<Self> {
        let d = &capture.description;
        let grid = d.turned_grid().map(|g| g.firmware(d.views)).transpose()?;
        Ok(Self {
            capture,
            frames: capture.raw_frames()?,
            mask: capture.mask()?,
            raw: capture.raw_format(),
            defects: capture.defects(),
            cols: capture.frame_size().1,
            grid,
            views: (d.views[0], d.views[1]),
            lenslets: (d.lenslets[0], d.lenslets[1]),
            bands: d.bands_nm.len(),
        })
    }

    /// Positions in a lenslet row: `T x U x V`.
    pub(super) fn positions(&self) -> usize {
        self.lenslets.1 * self.views.0 * self.views.1
    }

    /// The sensor pixel lenslet `(s, t)`'s view `(u, v)` reads: `(s U + u, t V + v)` on the
    /// aligned sensor; behind a turned grid the pixel under the view cell's centre, `None`
    /// past the sensor's edge.
    fn pixel(&self, (s, t): (usize, usize), (u, v): (usize, usize)) -> Option<(usize, usize)> {
        match &self.grid {
            None => Some((s * self.views.0 + u, t * self.views.1 + v)),
            Some(g) => g.pixel((s as isize, t as isize), (u, v)),
        }
    }

    /// Lenslet row `s`'s measurements, each view cell's from the sensor pixel [`Self::pixel`]
    /// names.
    ///
    /// # Errors
    /// A paged frame's read that fails.
    pub(super) fn row(&self, s: usize) -> Result<LensletRow> {
        let (vu, vv) = self.views;
        let (positions, cols) = (self.positions(), self.cols);
        let pixels: Vec<Option<(usize, usize)>> = (0..self.lenslets.1)
            .flat_map(|t| (0..vu).flat_map(move |u| (0..vv).map(move |v| (t, u, v))))
            .map(|(t, u, v)| self.pixel((s, t), (u, v)))
            .collect();
        // The sensor rows those pixels lie on, of every frame, read a row at a time (a paged
        // frame finds its band once a row): the lenslet's U rows on the aligned sensor, and
        // behind a turned grid as many more as the grid's turn moves a lenslet row across the
        // sensor.
        let (first, last) = pixels.iter().flatten().fold((usize::MAX, 0), |(a, b), &(r, _)| (a.min(r), b.max(r)));
        let height = (last + 1).saturating_sub(first);
        let mut sensor = vec![0.0f32; self.frames.len() * height * cols];
        for (j, frame) in self.frames.iter().enumerate() {
            for r in 0..height {
                let at = (j * height + r) * cols;
                frame.read_run((first + r) * cols, &mut sensor[at..at + cols]).ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: cannot read row {} of frame {j}{}",
                        self.capture.source(),
                        first + r,
                        self.capture.frames.read_error().err().map_or_else(String::new, |e| format!(": {e}"))
                    )
                })?;
            }
        }
        let mut taken = Vec::new();
        let mut start = Vec::with_capacity(positions + 1);
        start.push(0);
        for &pixel in &pixels {
            if let Some((row, col)) = pixel.filter(|&(r, c)| !self.defects.contains(r, c)) {
                let bands = self.mask.bands_at(row, col);
                for (j, &band) in bands.iter().enumerate().take(self.frames.len()) {
                    if let Ok(x) = self.raw.classify(sensor[(j * height + row - first) * cols + col]) {
                        taken.push((band, x));
                    }
                }
            }
            start.push(taken.len());
        }
        Ok(LensletRow { taken, start, views: vu * vv })
    }

    /// The capture's name, for messages.
    pub(super) fn source(&self) -> String {
        self.capture.source()
    }

    /// The light field's range: `0` to the brightest value a pixel can measure
    /// ([`RawFormat::range`]), which every baseline's output is clamped to.
    pub(super) fn range(&self) -> (f32, f32) {
        self.raw.range()
    }
}

impl LensletRow {
    /// The samples of lenslet `t`'s view `k` (`k = u V + v`).
    #[inline]
    pub(super) fn at(&self, t: usize, k: usize) -> &[(u8, f32)] {
        let i = t * self.views + k;
        &self.taken[self.start[i]..self.start[i + 1]]
    }

    /// Positions (lenslets times views) with at least one sample, and without.
    pub(super) fn measured_and_not(&self) -> (usize, usize) {
        let measured = self.start.windows(2).filter(|w| w[1] > w[0]).count();
        (measured, self.start.len() - 1 - measured)
    }

    /// Lenslet `t`'s views' samples, in `(u, v)` order.
    pub(super) fn lenslet(&self, t: usize) -> impl Iterator<Item = &[(u8, f32)]> {
        (0..self.views).map(move |k| self.at(t, k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::camera::{CameraConfig, GridSettings, simulate};
    use crate::sim::scene::SceneSize;

    /// Behind a grid turned 0.7 degrees (pitch 5.06 x 4.97 px, k = 2, its first lenslets
    /// partly past the sensor), each view cell's
    /// samples are the sensor pixel's under its centre, found here by the f64 rotation, with
    /// that pixel's bands; cells past the sensor have none. Cells whose centre lies within
    /// 1e-3 px of a pixel's edge, where f32 and f64 may part, are skipped (few).
    #[test]
    fn each_view_cell_reads_the_pixel_under_its_centre() {
        let lf =
            crate::sim::realistic::named("office").unwrap().render(SceneSize { views: (5, 5), rows: 12, cols: 14 });
        let mut cam = CameraConfig::pixel(3, 2).noiseless();
        // Lenslet (0, 0)'s centre 1.2 px from the top and 0.8 from the left edge: its first
        // views lie past the sensor.
        cam.grid = Some(GridSettings { rotation_deg: 0.7, pitch: Some([5.06, 4.97]), offset: Some([1.2, 0.8]) });
        let cap = simulate(&lf, &cam).unwrap();
        let g = cap.description.lenslet_grid.unwrap();
        let (rows, cols) = cap.frame_size();
        let frames = cap.frames.held((rows, cols)).unwrap();
        let (mask, raw) = (cap.mask().unwrap(), cap.raw_format());
        let reader = Reader::new(&cap).unwrap();
        let (sin, cos) = g.rotation_deg.to_radians().sin_cos();
        let (mut checked, mut skipped, mut off) = (0, 0, 0);
        for s in 0..12 {
            let row = reader.row(s).unwrap();
            for t in 0..14 {
                for (k, (u, v)) in (0..5).flat_map(|u| (0..5).map(move |v| (u, v))).enumerate() {
                    let da = (s as f64 + (u as f64 + 0.5) / 5.0 - 0.5) * g.pitch[0];
                    let db = (t as f64 + (v as f64 + 0.5) / 5.0 - 0.5) * g.pitch[1];
                    let (y, x) = (g.offset[0] + da * cos + db * sin, g.offset[1] + db * cos - da * sin);
                    let near = |z: f64| (z - z.round()).abs() < 1e-3;
                    if near(y) || near(x) {
                        skipped += 1;
                        continue;
                    }
                    let got = row.at(t, k);
                    if y < 0.0 || x < 0.0 || y >= rows as f64 || x >= cols as f64 {
                        assert!(got.is_empty(), "({s}, {t}, {u}, {v}) past the sensor has samples");
                        off += 1;
                        continue;
                    }
                    let (r, c) = (y.floor() as usize, x.floor() as usize);
                    let want: Vec<(u8, f32)> = mask
                        .bands_at(r, c)
                        .iter()
                        .zip(frames.iter())
                        .filter_map(|(&b, f)| raw.classify(f32::from(f[r * cols + c])).ok().map(|x| (b, x)))
                        .collect();
                    assert_eq!(got, want.as_slice(), "({s}, {t}, {u}, {v}) at pixel ({r}, {c})");
                    checked += 1;
                }
            }
        }
        assert!(
            checked > 3000 && skipped * 100 < checked && off > 20,
            "{checked} checked, {skipped} skipped, {off} off"
        );
    }
}
