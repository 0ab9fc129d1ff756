//! Raw frames: sensor samples, what makes one a measurement, and frames held in RAM.
//!
//! The decoder works in normalised units: `(raw - black) / (white - black)`, so a white
//! surface reads 1. A sample is a measurement only if it is finite, not negative and not
//! above `max_valid` (a clipped, saturated pixel says only "at least this bright", and
//! fed in as a value it would pull the solution down). Samples between 0 and the black
//! level are dark noise and are kept. Anything else is left out of the constraints and
//! the patch is flagged (see [`crate::decode::tile::PatchFlags`]).

use core::fmt;

use crate::sensor::mask::SensingError;
use crate::sensor::source::TileSource;

/// How raw sample values map to the decoder's normalised units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawFormat {
    /// Raw value of no light.
    pub black: f32,
    /// Raw value of a white (reflectance 1) surface.
    pub white: f32,
    /// Largest raw value that is still a measurement; above it a pixel is saturated.
    pub max_valid: f32,
}

impl RawFormat {
    /// Samples already normalised: black 0, white 1, anything up to 1 valid.
    pub const NORMALISED: Self = Self { black: 0.0, white: 1.0, max_valid: 1.0 };

    /// A `bits`-bit sensor with the given black level; the top code is saturated.
    pub fn bits(bits: u8, black: f32) -> Self {
        let top = ((1u32 << bits.clamp(1, 24)) - 1) as f32;
        Self { black, white: top, max_valid: top - 1.0 }
    }

    /// Whether the format can normalise anything: finite, `white > black` with a finite
    /// difference (-3e38 and 3e38 are finite, their difference is not: every value would
    /// normalise to 0), `max_valid >= 0`.
    pub fn is_valid(&self) -> bool {
        self.black.is_finite()
            && self.white.is_finite()
            && self.max_valid.is_finite()
            && self.white > self.black
            && (self.white - self.black).is_finite()
            && (self.max_valid - self.black).is_finite()
            && self.max_valid >= 0.0
    }

    /// The physical range of a value in normalised units: from no light (0) to the
    /// brightest a pixel can measure (`max_valid`). A decoded value outside it is not a
    /// radiance this sensor could have recorded, so the decoder clamps to it.
    pub fn range(&self) -> (f32, f32) {
        (0.0, ((self.max_valid - self.black) / (self.white - self.black)).max(0.0))
    }

    /// A sample as a measurement in normalised units, or why it is not one.
    #[inline]
    pub fn classify(&self, raw: f32) -> Result<f32, Invalid> {
        if !raw.is_finite() {
            Err(Invalid::NonFinite)
        } else if raw < 0.0 {
            Err(Invalid::Negative)
        } else if raw > self.max_valid {
            Err(Invalid::OverRange)
        } else {
            Ok((raw - self.black) / (self.white - self.black))
        }
    }
}

/// Why a sample is not a measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Invalid {
    NonFinite,
    Negative,
    OverRange,
}

/// A sample type of a raw frame.
pub trait Sample: Copy {
    fn to_f32(self) -> f32;
}

impl Sample for u16 {
    #[inline]
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
}

impl Sample for f32 {
    #[inline]
    fn to_f32(self) -> f32 {
        self
    }
}

/// One snapshot's raw frame, row-major, `rows x cols` samples. Checked at construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawFrame<'a, T: Sample> {
    data: &'a [T],
    rows: usize,
    cols: usize,
}

impl<'a, T: Sample> RawFrame<'a, T> {
    /// # Errors
    /// [`SensingError::FrameSize`] if `data.len() != rows * cols`.
    pub fn new(data: &'a [T], rows: usize, cols: usize) -> Result<Self, SensingError> {
        let expected = rows.saturating_mul(cols);
        if data.len() != expected {
            return Err(SensingError::FrameSize {
                expected: expected.min(u32::MAX as usize) as u32,
                found: data.len().min(u32::MAX as usize) as u32,
            });
        }
        Ok(Self { data, rows, cols })
    }

    /// Rows (sensor height).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Columns (sensor width).
    pub fn cols(&self) -> usize {
        self.cols
    }
}

/// Why a read from an in-memory frame failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReadError {
    /// No frame for this snapshot.
    NoSuchSnapshot { snapshot: u8 },
    /// The requested samples run outside the frame.
    OutOfBounds { row: u32, col: u32 },
}

impl core::fmt::Display for ReadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NoSuchSnapshot { snapshot } => write!(f, "no raw frame for snapshot {snapshot}"),
            Self::OutOfBounds { row, col } => {
                write!(f, "read outside the raw frame at ({row}, {col})")
            }
        }
    }
}

impl core::error::Error for ReadError {}

/// One snapshot's raw frame as little-endian u16 bytes: how a frame sits in flash (an
/// `.npy` body, a DMA buffer) without copying or aligning it. Checked at construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeU16Frame<'a> {
    bytes: &'a [u8],
    rows: usize,
    cols: usize,
}

impl<'a> LeU16Frame<'a> {
    /// # Errors
    /// [`SensingError::FrameSize`] if `bytes.len() != 2 * rows * cols` (in samples).
    pub fn new(bytes: &'a [u8], rows: usize, cols: usize) -> Result<Self, SensingError> {
        let expected = rows.saturating_mul(cols);
        if bytes.len() != expected.saturating_mul(2) {
            return Err(SensingError::FrameSize {
                expected: expected.min(u32::MAX as usize) as u32,
                found: (bytes.len() / 2).min(u32::MAX as usize) as u32,
            });
        }
        Ok(Self { bytes, rows, cols })
    }
}

/// A raw frame a [`FrameSource`] reads: its size and its samples by row-major index.
pub trait Frame {
    /// Rows and columns.
    fn size(&self) -> (usize, usize);
    /// Sample `i` (row-major); `None` past the end.
    fn sample(&self, i: usize) -> Option<f32>;
    /// Samples `start..start + out.len()` (row-major, inside one row) into `out`; `None` if
    /// any is past the end. A frame read from storage a band of rows at a time (the host's
    /// paged frame) finds the band once a run, not once a sample.
    #[inline]
    fn read_run(&self, start: usize, out: &mut [f32]) -> Option<()> {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.sample(start.checked_add(i)?)?;
        }
        Some(())
    }
}

impl<T: Sample> Frame for RawFrame<'_, T> {
    fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }
    #[inline]
    fn sample(&self, i: usize) -> Option<f32> {
        self.data.get(i).map(|s| s.to_f32())
    }
}

impl Frame for LeU16Frame<'_> {
    fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }
    #[inline]
    fn sample(&self, i: usize) -> Option<f32> {
        match self.bytes.get(2 * i..2 * i + 2) {
            Some(&[lo, hi]) => Some(f32::from(u16::from_le_bytes([lo, hi]))),
            _ => None,
        }
    }
}

/// A [`TileSource`] over raw frames in RAM or flash, one per snapshot; with
/// [`Self::with_flat`], frames already divided by a per-pixel flat field.
#[derive(Clone, Copy)]
pub struct FrameSource<'a, F: Frame> {
    frames: &'a [F],
    flat: Option<&'a dyn Frame>,
}

impl<F: Frame> fmt::Debug for FrameSource<'_, F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FrameSource").field("frames", &self.frames.len()).field("flat", &self.flat.is_some()).finish()
    }
}

impl<'a, F: Frame> FrameSource<'a, F> {
    pub fn new(frames: &'a [F]) -> Self {
        Self { frames, flat: None }
    }

    /// These frames as already divided by `flat` (one value a sensor pixel, frame pixel
    /// `(row, col)` at the flat's `(row, col)`: the flat of frames cropped to their top-left
    /// corner is the whole sensor's): the error estimate's noise term reads it
    /// ([`TileSource::flat`]).
    ///
    /// # Errors
    /// [`SensingError::FrameSize`] if `flat` does not cover every frame.
    pub fn with_flat(self, flat: &'a dyn Frame) -> Result<Self, SensingError> {
        let (rows, cols) = flat.size();
        if let Some(f) = self.frames.iter().find(|f| f.size().0 > rows || f.size().1 > cols) {
            let (r, c) = f.size();
            return Err(SensingError::FrameSize {
                expected: r.saturating_mul(c).min(u32::MAX as usize) as u32,
                found: rows.saturating_mul(cols).min(u32::MAX as usize) as u32,
            });
        }
        Ok(Self { flat: Some(flat), ..self })
    }
}

impl<F: Frame> TileSource for FrameSource<'_, F> {
    type Error = ReadError;

    #[inline]
    fn divided(&self) -> bool {
        self.flat.is_some()
    }

    #[inline]
    fn flat(&self, row: usize, col: usize) -> f32 {
        let Some(flat) = self.flat else { return 1.0 };
        let (rows, cols) = flat.size();
        if row >= rows || col >= cols {
            return 1.0;
        }
        match flat.sample(row * cols + col) {
            Some(f) if f > 0.0 && f.is_finite() => f,
            _ => 1.0,
        }
    }

    fn read(&mut self, snapshot: usize, row: usize, col: usize, out: &mut [f32]) -> Result<(), ReadError> {
        let frame = self.frames.get(snapshot).ok_or(ReadError::NoSuchSnapshot { snapshot: snapshot.min(255) as u8 })?;
        let oob =
            ReadError::OutOfBounds { row: row.min(u32::MAX as usize) as u32, col: col.min(u32::MAX as usize) as u32 };
        let (rows, cols) = frame.size();
        if row >= rows || col.saturating_add(out.len()) > cols {
            return Err(oob);
        }
        frame.read_run(row * cols + col, out).ok_or(oob)
    }
}
