//! Where raw samples come from: the trait every frame source implements.
//!
//! The tile decoder asks a source for short runs of one row (`PV` samples of one lenslet's
//! view row, per snapshot). That maps onto both random access into RAM ([`super::raw`]) and
//! addressed reads of a serial frame buffer ([`super::spi`]); a sequential-only sensor FIFO
//! is buffered tile by tile by its source. The trait lives here, beside the frames, so that
//! the sources need nothing of the decoder above them.

use core::fmt;

/// Where raw samples come from.
pub trait TileSource {
    /// A read failure (bus error, short read, out of range). `Copy`, to travel in errors.
    type Error: Copy + fmt::Debug;

    /// Fills `out` with the `out.len()` consecutive samples of `snapshot`'s raw frame that
    /// start at sensor pixel `(row, col)` and run along the row.
    ///
    /// # Errors
    /// The source's own error; the decoder then abandons the current tile only.
    fn read(&mut self, snapshot: usize, row: usize, col: usize, out: &mut [f32]) -> Result<(), Self::Error>;

    /// The flat field sensor pixel `(row, col)`'s samples were already divided by when this
    /// source hands them out (a host's per-pixel calibration corrects a frame before the
    /// decoder reads it), on top of the decoder's own view gains. Only the error estimate
    /// reads it: a corrected sample's noise is its raw value's over this flat
    /// ([`crate::solver::holdout::noise_variance`]), so a vignetted pixel's noise is not
    /// under-counted. 1 (the default) for a source of raw samples; a value that is not
    /// positive and finite counts as 1.
    #[inline]
    fn flat(&self, row: usize, col: usize) -> f32 {
        let _ = (row, col);
        1.0
    }

    /// Whether [`Self::flat`] can be other than 1: where neither it nor the decoder's view
    /// gains can, the error estimate does not look up each held-out sample's pixel.
    #[inline]
    fn divided(&self) -> bool {
        false
    }
}
