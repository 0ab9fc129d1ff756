//! A capture corrected by its sensor's calibration (issue 43), as a decode reads it: each
//! raw value becomes `black + (raw - dark) / flat` (DN), so a pixel reads as an ideal,
//! unvignetted one of the capture's black and white levels; hot, dead and saturated pixels
//! join the defects.
//!
//! The correction is applied inside the reader (issue 65): a paged frame's corrected twin
//! reads its raw rows and the calibration's dark and flat rows as each band is asked for
//! ([`Corrected`]), so a calibrated decode holds no corrected frame and no map whole. Held
//! frames (PNG, PGM, numpy's) are corrected whole, a band of the maps at a time.

use std::collections::BTreeSet;
use std::sync::Arc;

use anyhow::{Result, ensure};

use crate::decode::calibrate::DEAD_FLAT;
use crate::io::calibration::OpenCalibration;
use crate::io::capture::Capture;
use crate::io::frames::Frames;
use crate::io::grid::GridDescription;
use crate::io::map::{MAP_BAND_ROWS, Map};
use crate::io::paged_frame::{FrameRows, PagedFrame};
use crate::io::row_reader::by_bands;

/// The correction of one sensor's raw values: its maps and levels.
#[derive(Debug)]
struct Correction {
    dark: Map,
    flat: Map,
    black: f32,
    /// Raw values at or above it are saturated: corrected to the top of 16 bits, left out.
    saturation: f32,
}

impl Correction {
    /// Corrects `raw`, whole rows from `first_row` on, into `out`.
    ///
    /// # Errors
    /// A map's read that fails, naming its file.
    fn apply(&self, first_row: usize, raw: &[u16], out: &mut [u16]) -> Result<()> {
        let mut dark = vec![0.0f32; raw.len()];
        let mut flat = vec![0.0f32; raw.len()];
        self.dark.read_rows(first_row, &mut dark)?;
        self.flat.read_rows(first_row, &mut flat)?;
        let top = f32::from(u16::MAX);
        for (((o, &raw), &d), &f) in out.iter_mut().zip(raw).zip(&dark).zip(&flat) {
            *o = if f32::from(raw) >= self.saturation {
                u16::MAX // at the corrected saturation level: left out
            } else {
                let v = self.black + (f32::from(raw) - d) / f.max(DEAD_FLAT);
                v.round().clamp(0.0, top - 1.0) as u16
            };
        }
        Ok(())
    }
}

/// A paged frame's rows corrected as they are read.
#[derive(Debug)]
struct Corrected {
    raw: Arc<dyn FrameRows>,
    correction: Arc<Correction>,
}

impl FrameRows for Corrected {
    fn size(&self) -> (usize, usize) {
        self.raw.size()
    }

    fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        let mut raw = vec![0u16; out.len()];
        self.raw.read_rows(first, &mut raw)?;
        self.correction.apply(first, &raw, out)
    }
}

/// `capture` corrected by `cal` for its dark levels and flats. The corrected capture's
/// saturation level is the top of 16 bits (a vignetted pixel corrected may read above the
/// sensor's top code and is still a measurement). A lenslet grid the calibration found
/// replaces the capture's, its lenslets named as the capture names them
/// ([`GridDescription::indexed_as`]; the aligned grid's names without a stated grid): the
/// whole lenslets it was moved by come back beside the capture. With `keep_grid` the
/// capture keeps its own grid (`--grid capture` or `aligned`), and the calibration's is not
/// looked at.
///
/// Paged frames stay paged, corrected as they are read; held frames are corrected whole.
///
/// # Errors
/// A calibration of another geometry, bands or levels, or whose lenslet grid does not say
/// which of its lenslets is the capture's (0, 0); a map's read that fails.
pub fn corrected(capture: &Capture, cal: &OpenCalibration, keep_grid: bool) -> Result<(Capture, [i64; 2])> {
    let (d, c) = (&capture.description, &cal.description);
    ensure!(
        d.lenslets == c.lenslets && d.views == c.views,
        "the calibration is of {:?} lenslets and {:?} views; the capture of {:?} and {:?}",
        c.lenslets,
        c.views,
        d.lenslets,
        d.views
    );
    // The band centres themselves, not their count (a shift of 1 nm once read as "the same
    // bands").
    ensure!(
        d.bands_nm == c.bands_nm,
        "the calibration's band centres (bands_nm {:?} nm) are not the capture's ({:?} nm)",
        c.bands_nm,
        d.bands_nm
    );
    ensure!(
        d.black_level == c.black_level && d.white_level == c.white_level,
        "the calibration's levels (black {}, white {}) are not the capture's ({}, {})",
        c.black_level,
        c.white_level,
        d.black_level,
        d.white_level
    );
    let size = capture.frame_size();
    ensure!(
        size == cal.frame_size(),
        "the calibration is of a {:?} sensor, the capture's frames are {:?} (another lenslet grid's)",
        cal.frame_size(),
        size
    );
    let (rows, cols) = size;
    let correction = Arc::new(Correction {
        dark: cal.dark.clone(),
        flat: cal.flat.clone(),
        black: d.black_level,
        saturation: d.saturation_level,
    });
    let frames = match &capture.frames {
        Frames::Paged(raw) => Frames::Paged(
            raw.iter()
                .map(|f| PagedFrame::new(Arc::new(Corrected { raw: f.source(), correction: correction.clone() })))
                .collect(),
        ),
        Frames::Held(raw) => {
            let mut all = Vec::with_capacity(raw.len());
            for f in raw {
                let mut out = vec![0u16; rows * cols];
                let read =
                    |first: usize, part: &mut [u16]| correction.apply(first, &f[first * cols..][..part.len()], part);
                by_bands((rows, cols), MAP_BAND_ROWS, read, |first, part| {
                    out[first * cols..][..part.len()].copy_from_slice(part);
                    Ok(())
                })?;
                all.push(out);
            }
            Frames::Held(all)
        }
    };
    let mut defects: BTreeSet<[u32; 2]> = d.defective_pixels.iter().copied().collect();
    defects.extend(c.hot_pixels.iter().chain(&c.outside_pixels).copied());
    // A pixel the flat calls dead never reads as a measurement.
    cal.flat.visit(size, |first, flat| {
        for (i, _) in flat.iter().enumerate().filter(|&(_, &f)| f < DEAD_FLAT) {
            let p = first * cols + i;
            defects.insert([(p / cols) as u32, (p % cols) as u32]);
        }
        Ok(())
    })?;
    let mut description = d.clone();
    description.saturation_level = f32::from(u16::MAX);
    // The grid the calibration found from its flats replaces the one the capture states,
    // with the capture's lenslet (0, 0).
    let mut moved = [0, 0];
    if let Some(found) = c.lenslet_grid.as_ref().filter(|_| !keep_grid) {
        let stated = d.lenslet_grid.unwrap_or_else(|| GridDescription::aligned(d.lenslets, d.views));
        let (grid, by) = found.indexed_as(&stated, d.lenslets, d.views)?;
        description.lenslet_grid = Some(grid);
        moved = by;
    }
    description.defective_pixels = defects.into_iter().collect();
    let mut out = Capture::with_frames(description, frames)?;
    out.keep_source_of(capture);
    out.divided_by(cal.flat.clone());
    Ok((out, moved))
}
