//! A lenslet row's measurements, read from the raw frames exactly as the CS decoder reads
//! them: the firmware's mask, raw format and defect list (saturated, defective and
//! non-finite samples are not measurements).

use anyhow::Result;
use slf_firmware::{DefectList, Mask, RawFormat};

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
        Ok(Self {
            capture,
            frames: capture.raw_frames()?,
            mask: capture.mask()?,
            raw: capture.raw_format(),
            defects: capture.defects(),
            cols: capture.frame_size().1,
            views: (d.views[0], d.views[1]),
            lenslets: (d.lenslets[0], d.lenslets[1]),
            bands: d.bands_nm.len(),
        })
    }

    /// Positions in a lenslet row: `T x U x V`.
    pub(super) fn positions(&self) -> usize {
        self.lenslets.1 * self.views.0 * self.views.1
    }

    /// Lenslet row `s`'s measurements. Lenslet `(s, t)`'s view `(u, v)` is sensor pixel
    /// `(s U + u, t V + v)`.
    ///
    /// # Errors
    /// A paged frame's read that fails.
    pub(super) fn row(&self, s: usize) -> Result<LensletRow> {
        let (vu, vv) = self.views;
        // The lenslet row's sensor rows of every frame, read a row at a time (a paged
        // frame finds its band once a row).
        let cols = self.cols;
        let mut sensor = vec![0.0f32; self.frames.len() * vu * cols];
        for (j, frame) in self.frames.iter().enumerate() {
            for u in 0..vu {
                let at = (j * vu + u) * cols;
                frame.read_run((s * vu + u) * cols, &mut sensor[at..at + cols]).ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: cannot read row {} of frame {j}{}",
                        self.capture.source(),
                        s * vu + u,
                        self.capture.frames.read_error().err().map_or_else(String::new, |e| format!(": {e}"))
                    )
                })?;
            }
        }
        let mut taken = Vec::new();
        let mut start = Vec::with_capacity(self.positions() + 1);
        start.push(0);
        for t in 0..self.lenslets.1 {
            for u in 0..vu {
                for v in 0..vv {
                    let (row, col) = (s * vu + u, t * vv + v);
                    if !self.defects.contains(row, col) {
                        let bands = self.mask.bands_at(row, col);
                        for (j, &band) in bands.iter().enumerate().take(self.frames.len()) {
                            if let Ok(x) = self.raw.classify(sensor[(j * vu + u) * cols + col]) {
                                taken.push((band, x));
                            }
                        }
                    }
                    start.push(taken.len());
                }
            }
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
