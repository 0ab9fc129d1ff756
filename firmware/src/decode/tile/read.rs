//! The sensor read: a patch's samples from the source, balanced, placed in its views (or
//! in the view cells of a turned grid), and the white balance estimated from the frame.

use super::*;
use crate::operators::shape::{PerBand, Shape};
use crate::sensor::extent::{Array, Bands, Per};
use crate::sensor::mask::{BandList, MAX_BANDS};
use crate::solver::shares::{MAX_OUTSIDE_SHARE, MAX_SEEDED_OUTSIDE_SHARE, Reach};

impl<'a, S: Shape> TileDecoder<'a, S> {
    /// Grey-world band gains of a frame: every valid sample of the sensor (defects and
    /// invalid samples left out) summed per band ([`crate::sensor::gains::gains_from_sums`]).
    /// Reads the frame once, one sensor row at a time in runs of up to 16 samples per
    /// snapshot.
    ///
    /// # Errors
    /// The source's error; nothing is estimated then.
    pub fn estimate_gains<Src: TileSource>(&self, source: &mut Src) -> Result<PerBand<S, f32>, Src::Error> {
        const RUN: usize = 16;
        let c = &self.config;
        let (rows, cols) = self.frame_size();
        let k = c.mask.snapshots();
        let mut sums = <PerBand<S, _>>::splat(0.0f32);
        let mut counts = <PerBand<S, _>>::splat(0u32);
        // A pixel measures at most `B` distinct bands, so `k <= B` (checked by the mask).
        let mut runs = <PerBand<S, [f32; RUN]>>::splat([0.0; RUN]);
        for row in 0..rows {
            // Per row in f32, then added to the totals: a frame's sum in one f32 would lose
            // the small bands' low digits.
            let mut row_sums = <PerBand<S, _>>::splat(0.0f32);
            for col0 in (0..cols).step_by(RUN) {
                let len = RUN.min(cols - col0);
                for (j, run) in runs.iter_mut().enumerate().take(k) {
                    let Some(out) = run.get_mut(..len) else { break };
                    source.read(j, row, col0, out)?;
                }
                for dc in 0..len {
                    let col = col0 + dc;
                    if c.defects.contains(row, col) || !self.in_array(row, col) {
                        continue;
                    }
                    // One band list per pixel, every snapshot's sample against it.
                    for (band, run) in c.mask.bands_at(row, col).iter().zip(runs.iter()) {
                        let Ok(y) = c.raw.classify(run.get(dc).copied().unwrap_or(f32::NAN)) else { continue };
                        let y = y / self.view_gain(row, col);
                        if let (Some(s), Some(n)) = (row_sums.get_mut(*band as usize), counts.get_mut(*band as usize)) {
                            *s += y;
                            *n += 1;
                        }
                    }
                }
            }
            for (t, r) in sums.iter_mut().zip(row_sums.iter()) {
                *t += r;
            }
        }
        if !self.solved_response().is_identity() {
            // The filters' means are `R` of the frame's mean spectrum: the gains are of the
            // spectrum (leaked light from a bright band would otherwise inflate a dark
            // band's gain and tilt the balanced spectra: measured on the office scene at 10 %
            // leakage, 2.6 dB lost with the DCT).
            let (mut means, mut ones) = (<PerBand<S, _>>::splat(0.0f32), <PerBand<S, _>>::splat(0u32));
            for (((m, o), &s), &n) in means.iter_mut().zip(ones.iter_mut()).zip(sums.iter()).zip(counts.iter()) {
                (*m, *o) = (s / n.max(1) as f32, u32::from(n > 0));
            }
            self.response.unmix(&mut means);
            return Ok(crate::sensor::gains::gains_from_sums(&means, &ones));
        }
        Ok(crate::sensor::gains::gains_from_sums(&sums, &counts))
    }

    /// Whether sensor pixel `(row, col)` belongs to the light field: on the aligned sensor
    /// every pixel does; behind a lenslet grid, a pixel whose centre lies in no view cell of
    /// the array's lenslets is outside it (a turned array leaves such pixels at the
    /// sensor's edges). No patch reads one, and the grey world leaves them out: they record
    /// no light of the scene.
    pub fn in_array(&self, row: usize, col: usize) -> bool {
        let Some(g) = &self.grid else { return true };
        let (s_n, t_n) = self.config.sensor.lenslets;
        g.view_of(row, col).is_some_and(|((s, t), _)| s < usize::from(s_n) && t < usize::from(t_n))
    }

    /// Reads the patch at `origin` into the workspace's measurements (each divided by its
    /// band's gain), as a decode does before it solves; returns the flags and the number of
    /// samples left out. A sheared patch (`origin.disparity != 0`) reads each view from its
    /// shifted lenslet ([`PatchOrigin::lenslet`]), one sample at a time; pixels the shear
    /// puts outside the sensor are not measurements. `origin` is not checked against the
    /// sensor: a pixel outside it is a read the source refuses.
    ///
    /// # Errors
    /// The source's error.
    pub fn read_patch<Src: TileSource>(
        &self,
        origin: PatchOrigin,
        source: &mut Src,
        ws: &mut Workspace<S>,
    ) -> Result<(PatchFlags, u16), Src::Error> {
        self.read_patch_seeded::<Src, super::NoSeed>(origin, source, ws, None)
    }

    /// [`Self::read_patch`] with a decode of the frame to read cells outside the patch from:
    /// behind a lenslet grid, a full-view patch's pixel's shares of cells outside it (an
    /// unsheared patch's rim; a sheared one's too, and its outer views' cells across a
    /// micro-image border) are taken out of its measurement by `seed`'s estimates of them
    /// ([`CellShares::known_outside`]); a pixel with such a cell `seed` has no estimate of
    /// is left out, and so is one more than half of whose square lies outside
    /// ([`crate::solver::shares::MAX_SEEDED_OUTSIDE_SHARE`]).
    ///
    /// # Errors
    /// The source's error.
    pub fn read_patch_seeded<Src: TileSource, Q: PatchSeed<S> + ?Sized>(
        &self,
        origin: PatchOrigin,
        source: &mut Src,
        ws: &mut Workspace<S>,
        mut seed: Option<&mut Q>,
    ) -> Result<(PatchFlags, u16), Src::Error> {
        let c = &self.config;
        let (lu, lv) = (c.sensor.lenslet.rows as usize, c.sensor.lenslet.cols as usize);
        let k = c.mask.snapshots();
        let m = ws.measurements_mut();
        m.clear();
        // Checked within [1/64, 64] by `with_gains`; `B <= MAX_BANDS` by `PatchShape`.
        let _ = m.set_gains(self.gains.as_ref());
        ws.set_response(self.solved_response());
        let m = ws.measurements_mut();
        let mut flags = PatchFlags::default();
        let mut excluded = 0u16;
        let mut run = <PerBand<S, Per<S::V, f32>>>::splat(S::V::ZEROS);
        let half = HalfViews::of(origin.disparity, (origin.view_row as usize, origin.view_col as usize), (lu, lv));
        m.set_half_views(half);
        // Behind a lenslet grid each pixel is the shares of the cells it covers (a half view's
        // cell the mean of two grid positions); with a response that mixes bands, the cell
        // under its centre.
        let mut shares = self.cell_shares(origin);
        let full = S::PU == lu && S::PV == lv;
        let known = seed.is_some() && full;
        if let Some(c) = shares.as_mut() {
            c.known_outside = known;
        }
        if m.set_shares(shares).is_err() {
            let _ = m.set_shares(None);
        }
        let shared = m.shares().is_some();
        // A sheared patch's pixels that lie largely outside it are left out at k >= 2
        // (`MAX_OUTSIDE_SHARE`); a seeded patch's, sheared or not, past half outside
        // (`MAX_SEEDED_OUTSIDE_SHARE`).
        let known = known && m.shares().is_some_and(|c| c.known_outside);
        let reach = m
            .shares()
            .filter(|_| known || (origin.disparity != Disparity::ZERO && k >= 2))
            .map(|c| Reach::<S>::new(c, half));
        let most = if known { MAX_SEEDED_OUTSIDE_SHARE } else { MAX_OUTSIDE_SHARE };
        let lenslets = (c.sensor.lenslets.0 as isize, c.sensor.lenslets.1 as isize);
        for s in 0..S::PS {
            for u in 0..S::PU {
                for t in 0..S::PT {
                    if origin.disparity == Disparity::ZERO && self.grid.is_none() {
                        // One run of the lenslet's view row per snapshot.
                        let row = (origin.lenslet_row as usize + s) * lu + origin.view_row as usize + u;
                        let col0 = (origin.lenslet_col as usize + t) * lv + origin.view_col as usize;
                        for (j, r) in run.iter_mut().enumerate().take(k) {
                            source.read(j, row, col0, r.as_mut())?;
                        }
                        for v in 0..S::PV {
                            let at = S::pixel_index(s, t, u, v);
                            self.put_pixel(
                                m,
                                at,
                                row,
                                col0 + v,
                                |j| run.get(j).map(|r| r[v]),
                                &mut flags,
                                &mut excluded,
                            );
                        }
                    } else {
                        for v in 0..S::PV {
                            let (vr, vc) = (origin.view_row as usize + u, origin.view_col as usize + v);
                            let Some(lenslet) = origin.lenslet::<S>(s, t, u, v, (lu, lv)) else { continue };
                            let Some((row, col)) = self.sensor_pixel(lenslet, vr, vc) else { continue };
                            let at = S::pixel_index(s, t, u, v);
                            // With the cells outside the patch known: the pixel's bands, and
                            // each one's estimate of those cells by their shares (empty
                            // otherwise: nothing to take out).
                            let mut outside_bands = BandList::new();
                            let mut outside = heapless::Vec::<f32, MAX_BANDS>::new();
                            if shared {
                                // The pixel's place in its cell; a pixel whose centre lies
                                // in another cell is that cell's measurement, not this one's.
                                let Some(place) = self.place_in_cell(lenslet, (vr, vc), (row, col)) else { continue };
                                if reach.as_ref().is_some_and(|r| r.outside((s, t, u, v), place) > most) {
                                    continue;
                                }
                                let _ = m.set_place(at / S::B, place);
                                if let (true, Some(r), Some(sd)) = (known, reach.as_ref(), seed.as_deref_mut()) {
                                    outside_bands = c.mask.bands_at(row, col);
                                    let bands = &outside_bands;
                                    // At most `MAX_BANDS` bands: the resize cannot fail.
                                    let _ = outside.resize(bands.len(), 0.0);
                                    let (lui, lvi) = (lu as isize, lv as isize);
                                    let (pr, pc) = (lenslet.0 * lui + vr as isize, lenslet.1 * lvi + vc as isize);
                                    let mut whole = true;
                                    r.outside_cells((s, t, u, v), place, |(dr, dc), w| {
                                        let (qr, qc) = (pr + dr, pc + dc);
                                        let cell = qr
                                            .checked_div_euclid(lui)
                                            .zip(qc.checked_div_euclid(lvi))
                                            .zip(qr.checked_rem_euclid(lui).zip(qc.checked_rem_euclid(lvi)));
                                        let (l, view) = cell.unwrap_or(((-1, -1), (0, 0)));
                                        let view = (view.0 as usize, view.1 as usize);
                                        let inside = (0..lenslets.0).contains(&l.0) && (0..lenslets.1).contains(&l.1);
                                        for (o, &b) in outside.iter_mut().zip(bands.iter()) {
                                            let b = usize::from(b);
                                            let est = if inside {
                                                sd.cell((l.0 as usize, l.1 as usize), view, b)
                                            } else {
                                                None
                                            };
                                            match est {
                                                Some(x) => *o += w * x / self.gains.get(b).copied().unwrap_or(1.0),
                                                None => whole = false,
                                            }
                                        }
                                    });
                                    if !whole {
                                        continue;
                                    }
                                }
                            }
                            for (j, r) in run.iter_mut().enumerate().take(k) {
                                source.read(j, row, col, &mut r.as_mut()[..1])?;
                            }
                            self.put_pixel(m, at, row, col, |j| run.get(j).map(|r| r[0]), &mut flags, &mut excluded);
                            for (&b, &o) in outside_bands.iter().zip(outside.iter()) {
                                let e = at + usize::from(b);
                                if let Some(y) = m.get(e) {
                                    let _ = m.set(e, y - o);
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok((flags, excluded))
    }

    /// How the pixels of a patch at `origin` share view cells behind the lenslet grid:
    /// `None` on the aligned sensor (each pixel its cell, the selection's bits) and for a
    /// solved response that mixes bands (its projection is not built with shares). A
    /// half-pixel shear's half views are the measurements' (`Measurements::half_views`):
    /// the shares read each such cell as the mean of its two grid positions.
    pub(super) fn cell_shares(&self, origin: PatchOrigin) -> Option<CellShares> {
        let g = self.grid.as_ref().filter(|g| !g.is_aligned())?;
        let fits = S::PU <= MAX_SHARE_VIEWS && S::PV <= MAX_SHARE_VIEWS && S::PS * S::PT * S::PU * S::PV <= MAX_PLACES;
        if !self.solved_response().is_identity() || !fits {
            return None;
        }
        let (lu, lv) = (usize::from(self.config.sensor.lenslet.rows), usize::from(self.config.sensor.lenslet.cols));
        let mut shares = CellShares::unsheared(g.pixel_width());
        let d = origin.disparity;
        for (u, o) in shares.shift.0.iter_mut().enumerate().take(S::PU) {
            *o = i8::try_from(shift(d, origin.view_row as usize + u, lu)).ok()?;
        }
        for (v, o) in shares.shift.1.iter_mut().enumerate().take(S::PV) {
            *o = i8::try_from(shift(d, origin.view_col as usize + v, lv)).ok()?;
        }
        Some(shares)
    }

    /// Where pixel `(row, col)`'s centre lies in the view cell of view `(u, v)` of lenslet
    /// `(lr, lc)`: cells off the cell's centre (rows, cols), `None` if outside that cell (so
    /// no pixel is two cells' measurement).
    pub(super) fn place_in_cell(
        &self,
        (lr, lc): (isize, isize),
        (u, v): (usize, usize),
        (row, col): (usize, usize),
    ) -> Option<(f32, f32)> {
        let g = self.grid.as_ref()?;
        let (a, b) = g.cell_position(row, col)?;
        let (nu, nv) = g.views();
        let centre = |l: isize, n: u8, w: usize| l as f32 * f32::from(n) + w as f32 + 0.5;
        let (dr, dc) = (a - centre(lr, nu, u), b - centre(lc, nv, v));
        // Cells at least a pixel apart (pitch at least the views) never share the pixel under
        // their centres, which may sit on the cell's border (a grid offset by half a pixel);
        // smaller cells may, and the border then goes to the cell after it.
        let within = |d: f32, wide: bool| if wide { (-0.5..=0.5).contains(&d) } else { (-0.5..0.5).contains(&d) };
        let (wr, wc) = g.pixel_width();
        (within(dr, wr <= 1.0) && within(dc, wc <= 1.0)).then_some((dr, dc))
    }

    /// The sensor pixel `(row, col)` of view `(u, v)` of lenslet `(lr, lc)` (a shear can
    /// put the lenslet outside the sensor: then `None`).
    #[inline(always)]
    pub(super) fn sensor_pixel(&self, (lr, lc): (isize, isize), u: usize, v: usize) -> Option<(usize, usize)> {
        let c = &self.config;
        let lr = usize::try_from(lr).ok().filter(|&r| r < usize::from(c.sensor.lenslets.0))?;
        let lc = usize::try_from(lc).ok().filter(|&c0| c0 < usize::from(c.sensor.lenslets.1))?;
        if let Some(g) = &self.grid {
            return g.pixel((lr as isize, lc as isize), (u, v));
        }
        Some((lr * usize::from(c.sensor.lenslet.rows) + u, lc * usize::from(c.sensor.lenslet.cols) + v))
    }

    /// A raw sample of sensor pixel `(row, col)` through `band` as a measurement:
    /// normalised and divided by its view's gain and the band's, or why it is not one.
    #[inline(always)]
    pub(super) fn balanced(&self, band: u8, raw: f32, (row, col): (usize, usize)) -> Result<f32, Invalid> {
        let gain = self.gains.get(band as usize).copied().unwrap_or(1.0) * self.view_gain(row, col);
        self.config.raw.classify(raw).map(|y| y / gain)
    }

    /// A raw sample of sensor pixel `(row, col)` in the decoded light field's units:
    /// normalised and divided by its view's flat field (the band gains are divided out
    /// before the solve and multiplied back into its output), or why it is not a
    /// measurement. On the aligned grid with the identity response it is the light field's
    /// value at the pixel's lenslet, view and band: what a held-out sample is compared with.
    #[inline]
    pub fn light_field_value(&self, raw: f32, (row, col): (usize, usize)) -> Result<f32, Invalid> {
        let gain = self.view_gain(row, col);
        self.config.raw.classify(raw).map(|y| y / gain)
    }

    /// Whether the decode's light field holds each sample's own value: no lenslet grid
    /// (every pixel under one lenslet's view) and the identity response (a pixel measures
    /// one band). Then a sample the decode was not given can be compared with the output
    /// ([`Self::light_field_value`]).
    pub fn samples_are_values(&self) -> bool {
        self.grid.is_none() && self.solved_response().is_identity()
    }

    /// The flat field of sensor pixel `(row, col)`'s view ([`Self::with_view_gains`]); 1
    /// without one.
    #[inline(always)]
    pub fn view_gain(&self, row: usize, col: usize) -> f32 {
        let Some((table, (rr, rc))) = self.view_gains else { return 1.0 };
        let (lenslet, lenslets) = (self.config.sensor.lenslet, self.config.sensor.lenslets);
        let (lu, lv) = (usize::from(lenslet.rows), usize::from(lenslet.cols));
        // The pixel's lenslet and view: on the grid, the cell its centre lies in.
        let ((s, t), (u, v)) = match &self.grid {
            Some(g) => g.view_of(row, col).unwrap_or(((0, 0), (0, 0))),
            None => (
                (row.checked_div(lu).unwrap_or(0), col.checked_div(lv).unwrap_or(0)),
                (row.checked_rem(lu).unwrap_or(0), col.checked_rem(lv).unwrap_or(0)),
            ),
        };
        let region = |l: usize, count: u16, regions: u16| {
            (l * usize::from(regions))
                .checked_div(usize::from(count))
                .unwrap_or(0)
                .min(usize::from(regions).saturating_sub(1))
        };
        let (i, j) = (region(s, lenslets.0, rr), region(t, lenslets.1, rc));
        table.get(((i * usize::from(rc) + j) * lu + u) * lv + v).copied().unwrap_or(1.0)
    }

    /// Sensor pixel `(row, col)`'s samples (`sample(j)` of snapshot `j`) as measurements
    /// of the patch's pixel whose first band is at `at`, each divided by its band's gain;
    /// a defective pixel or an invalid sample is left out and flagged.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn put_pixel(
        &self,
        m: &mut crate::solver::workspace::Measurements<S::Values>,
        at: usize,
        row: usize,
        col: usize,
        sample: impl Fn(usize) -> Option<f32>,
        flags: &mut PatchFlags,
        excluded: &mut u16,
    ) {
        let c = &self.config;
        if c.defects.contains(row, col) {
            flags.insert(PatchFlags::DEFECTIVE);
            *excluded += c.mask.snapshots() as u16;
            return;
        }
        for (j, band) in c.mask.bands_at(row, col).iter().enumerate() {
            let ok = match self.balanced(*band, sample(j).unwrap_or(f32::NAN), (row, col)) {
                Ok(y) => m.set(at + *band as usize, y).map_err(|_| Invalid::NonFinite),
                Err(e) => Err(e),
            };
            if let Err(e) = ok {
                flags.insert(e.into());
                *excluded += 1;
            }
        }
    }
}
