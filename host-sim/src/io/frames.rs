//! A capture's raw frames, one per snapshot ([`Frames`]): held in memory (made by the
//! simulator, given from numpy, or a small capture's files read whole), or read from their
//! `.npy`, PGM or grey PNG files a band of rows at a time ([`PagedFrame`]); and the frame the decoder reads either way
//! ([`SensorFrame`]).
//!
//! Whole-frame work (a calibration's correction, a capture saved again, the frames handed
//! to numpy) asks for the frames held ([`Frames::held`]), which reads paged ones whole
//! after checking the memory cap; the decode reads them paged, and a frame made from a
//! paged one (cropped here, corrected by `decode::correction`) is paged too.

use std::borrow::Cow;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Result, anyhow, ensure};
use slf_firmware::{Frame, RawFrame};

use crate::io::frame_file::{extension, read_frame};
use crate::io::paged_frame::{FrameRows, PagedFrame};
use crate::io::row_reader::by_bands;

/// A capture's frames, one per snapshot, row-major.
#[derive(Clone, Debug)]
pub enum Frames {
    /// In memory.
    Held(Vec<Vec<u16>>),
    /// Read from their files as the decode asks.
    Paged(Vec<PagedFrame>),
}

/// One snapshot's frame as the decoder reads it.
#[derive(Clone, Copy, Debug)]
pub enum SensorFrame<'a> {
    Held(RawFrame<'a, u16>),
    Paged(&'a PagedFrame),
}

impl Frames {
    /// Opens a capture's frame files, each `rows x cols`. Past `hold_bytes` in all, `.npy`,
    /// PGM and grey PNG frames are read as the decode asks, a band of rows at a time: their
    /// header and length (and a PGM's values against its MAXVAL) are checked now. The
    /// others are read whole. `fits(path, top)` checks a file's largest value (its MAXVAL or
    /// bit depth) against the capture's saturation level.
    ///
    /// # Errors
    /// A file and what is wrong with it, or what `fits` says.
    pub fn open(
        paths: &[PathBuf],
        (rows, cols): (usize, usize),
        hold_bytes: u64,
        fits: impl Fn(&Path, u32) -> Result<()>,
    ) -> Result<Self> {
        let mut paged = Vec::with_capacity(paths.len());
        let held_bytes = (paths.len() * rows * cols * 2) as u64;
        for path in paths.iter().filter(|_| held_bytes > hold_bytes) {
            let frame = match extension(path).as_str() {
                "npy" => PagedFrame::open_npy(path, (rows, cols))?,
                "pgm" => {
                    let (frame, top) = PagedFrame::open_pgm(path, (rows, cols))?;
                    fits(path, top)?;
                    Some(frame)
                }
                "png" => match PagedFrame::open_png(path, (rows, cols))? {
                    Some((frame, top)) => {
                        fits(path, top)?;
                        Some(frame)
                    }
                    None => None,
                },
                _ => None,
            };
            match frame {
                Some(frame) => paged.push(frame),
                None => break,
            }
        }
        if !paths.is_empty() && paged.len() == paths.len() {
            return Ok(Self::Paged(paged));
        }
        let mut frames = Vec::with_capacity(paths.len());
        for path in paths {
            // Of the capture's size: read_frame refuses another from the file's header.
            let frame = read_frame(path, Some((rows, cols)))?;
            fits(path, frame.top)?;
            frames.push(frame.data);
        }
        Ok(Self::Held(frames))
    }

    /// Snapshots.
    pub fn len(&self) -> usize {
        match self {
            Self::Held(f) => f.len(),
            Self::Paged(f) => f.len(),
        }
    }

    /// No snapshot (not a capture: [`crate::io::capture::Capture::new`] refuses it).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The frames held in memory (none where they are paged).
    pub fn in_memory(&self) -> &[Vec<u16>] {
        match self {
            Self::Held(f) => f,
            Self::Paged(_) => &[],
        }
    }

    /// Whether the frames are read from their files.
    pub fn is_paged(&self) -> bool {
        matches!(self, Self::Paged(_))
    }

    /// The frames in memory: as held, or read whole (`rows x cols` each) after the memory
    /// cap is checked.
    ///
    /// # Errors
    /// Frames past the memory cap, or a read that fails.
    pub fn held(&self, (rows, cols): (usize, usize)) -> Result<Cow<'_, [Vec<u16>]>> {
        match self {
            Self::Held(f) => Ok(Cow::Borrowed(f)),
            Self::Paged(f) => {
                crate::io::budget::check(
                    (f.len() * rows * cols * 2) as u64,
                    &format!("holding {} raw frames of {rows} x {cols}", f.len()),
                    "a capture of fewer snapshots or a smaller sensor",
                )?;
                let mut all = Vec::with_capacity(f.len());
                for frame in f {
                    let mut values = vec![0u16; rows * cols];
                    frame.read_rows(0, &mut values)?;
                    all.push(values);
                }
                Ok(Cow::Owned(all))
            }
        }
    }

    /// The frames held in memory for changing them: paged frames are read whole first (as
    /// [`Self::held`]).
    ///
    /// # Errors
    /// As [`Self::held`].
    pub fn held_mut(&mut self, size: (usize, usize)) -> Result<&mut Vec<Vec<u16>>> {
        if let Self::Paged(_) = self {
            *self = Self::Held(self.held(size)?.into_owned());
        }
        match self {
            Self::Held(f) => Ok(f),
            Self::Paged(_) => Err(anyhow!("the frames could not be held")),
        }
    }

    /// Calls `f(snapshot, first row, rows)` on every frame's rows in order, a band of
    /// rows at a time (`rows x cols` frames; held frames in one call each): a pass that
    /// holds no frame.
    ///
    /// # Errors
    /// A read that fails.
    pub fn visit(&self, (rows, cols): (usize, usize), mut f: impl FnMut(usize, usize, &[u16])) -> Result<()> {
        match self {
            Self::Held(frames) => frames.iter().enumerate().for_each(|(j, v)| f(j, 0, v)),
            Self::Paged(frames) => {
                for (j, frame) in frames.iter().enumerate() {
                    let band = crate::io::paged_frame::MIN_BAND_ROWS;
                    let read = |first, part: &mut [u16]| frame.read_rows(first, part);
                    by_bands((rows, cols), band, read, |first, part| {
                        f(j, first, part);
                        Ok(())
                    })?;
                }
            }
        }
        Ok(())
    }

    /// Whether any value of any frame (each `rows x cols`) meets `pred`, by [`Self::visit`].
    ///
    /// # Errors
    /// A read that fails.
    pub fn any(&self, size: (usize, usize), pred: impl Fn(u16) -> bool) -> Result<bool> {
        let mut found = false;
        self.visit(size, |_, _, values| found = found || values.iter().any(|&x| pred(x)))?;
        Ok(found)
    }

    /// The frames as the decoder reads them, each `rows x cols`.
    ///
    /// # Errors
    /// A held frame of another size (checked when the capture was made, so not expected).
    pub fn sensor(&self, (rows, cols): (usize, usize)) -> Result<Vec<SensorFrame<'_>>> {
        match self {
            Self::Held(f) => f
                .iter()
                .map(|f| RawFrame::new(f, rows, cols).map(SensorFrame::Held).map_err(|e| anyhow!("{e}")))
                .collect(),
            Self::Paged(f) => Ok(f.iter().map(SensorFrame::Paged).collect()),
        }
    }

    /// The top-left `rows x cols` of every frame (each `whole`): paged frames cropped as
    /// they are read, held ones copied (the aligned reading of a capture behind a grid).
    pub fn cropped(&self, whole: (usize, usize), (rows, cols): (usize, usize)) -> Self {
        match self {
            Self::Paged(f) => Self::Paged(
                f.iter().map(|f| PagedFrame::new(Arc::new(Cropped { whole: f.source(), rows, cols }))).collect(),
            ),
            Self::Held(f) => {
                let c0 = whole.1;
                Self::Held(
                    f.iter().map(|f| (0..rows).flat_map(|r| f[r * c0..r * c0 + cols].to_vec()).collect()).collect(),
                )
            }
        }
    }

    /// The first read of a paged frame that failed since it was opened: a decode that read
    /// no sample there must not pass as one that flagged the pixels.
    ///
    /// # Errors
    /// That read's error.
    pub fn read_error(&self) -> Result<()> {
        match self {
            Self::Held(_) => Ok(()),
            Self::Paged(f) => match f.iter().find_map(PagedFrame::error) {
                Some(e) => Err(anyhow!("{e}")),
                None => Ok(()),
            },
        }
    }

    /// Bands read from the files so far, all frames (0 for held frames).
    pub fn loads(&self) -> u64 {
        match self {
            Self::Held(_) => 0,
            Self::Paged(f) => f.iter().map(PagedFrame::loads).sum(),
        }
    }
}

/// The top-left `rows x cols` of a paged frame, read as asked (the aligned reading of a
/// capture behind a grid).
#[derive(Debug)]
struct Cropped {
    whole: Arc<dyn FrameRows>,
    rows: usize,
    cols: usize,
}

impl FrameRows for Cropped {
    fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        let (_, wide) = self.whole.size();
        let n = out.len() / self.cols.max(1);
        ensure!(first + n <= self.rows, "rows {first}..{} of {} read as aligned", first + n, self.rows);
        let mut all = vec![0u16; n * wide];
        self.whole.read_rows(first, &mut all)?;
        for (o, r) in out.chunks_mut(self.cols.max(1)).zip(all.chunks(wide.max(1))) {
            o.copy_from_slice(&r[..o.len()]);
        }
        Ok(())
    }
}
impl Frame for SensorFrame<'_> {
    fn size(&self) -> (usize, usize) {
        match self {
            Self::Held(f) => f.size(),
            Self::Paged(f) => f.size(),
        }
    }

    #[inline]
    fn sample(&self, i: usize) -> Option<f32> {
        match self {
            Self::Held(f) => f.sample(i),
            Self::Paged(f) => f.sample(i),
        }
    }

    #[inline]
    fn read_run(&self, start: usize, out: &mut [f32]) -> Option<()> {
        match self {
            Self::Held(f) => f.read_run(start, out),
            Self::Paged(f) => f.read_run(start, out),
        }
    }
}

/// Whether `name` is a frame's name as a capture writes it: `snapshot_N.npy`, `.pgm` or
/// `.png` ([`crate::io::frame_file::frame_names`]); only such files of an old capture are
/// replaced with it.
pub(crate) fn is_frame_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix("snapshot_") else { return false };
    let Some((n, ext)) = rest.split_once('.') else { return false };
    !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()) && matches!(ext, "npy" | "pgm" | "png")
}

/// A frame's path: `name` must be a relative path inside the capture folder.
///
/// # Errors
/// An absolute path, `..`, or an empty name.
pub fn frame_path(dir: &Path, name: &str) -> Result<PathBuf> {
    use std::path::Component;
    let rel = Path::new(name);
    ensure!(!name.is_empty(), "an empty file name");
    ensure!(
        rel.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir)),
        "{name:?} is not a path inside the capture folder (no absolute paths, no '..')"
    );
    Ok(dir.join(rel))
}

/// Checks that `path` (a frame of the capture folder `dir`) resolves inside `dir`: a
/// symbolic link to a file elsewhere is not read as the capture's.
///
/// # Errors
/// Where the link leads, or an I/O error resolving it.
pub(crate) fn inside(dir: &Path, path: &Path) -> Result<()> {
    let (Ok(d), Ok(p)) = (fs::canonicalize(dir), fs::canonicalize(path)) else {
        // Missing files are named by the reader, which opens them next.
        return Ok(());
    };
    ensure!(
        p.starts_with(&d),
        "{} leads to {}, outside the capture folder (frames are read from inside it only)",
        path.display(),
        p.display()
    );
    Ok(())
}
