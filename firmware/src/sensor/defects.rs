//! Defective sensor pixels: positions that are never measurements.

use crate::sensor::mask::SensingError;

/// A sensor pixel position in the raw frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pixel {
    pub row: u16,
    pub col: u16,
}

/// A set of defective pixels, held as a strictly increasing `(row, col)` list (in flash
/// on the device); looked up by binary search. Checked at construction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DefectList<'a> {
    pixels: &'a [Pixel],
}

impl<'a> DefectList<'a> {
    /// No defects.
    pub const EMPTY: DefectList<'static> = DefectList { pixels: &[] };

    /// # Errors
    /// [`SensingError::DefectsUnsorted`] if the list is not strictly increasing.
    pub fn new(pixels: &'a [Pixel]) -> Result<Self, SensingError> {
        if let Some(i) = pixels.windows(2).position(|w| w[0] >= w[1]) {
            return Err(SensingError::DefectsUnsorted { index: i as u32 + 1 });
        }
        Ok(Self { pixels })
    }

    /// Whether sensor pixel `(row, col)` is defective.
    pub fn contains(&self, row: usize, col: usize) -> bool {
        let (Ok(row), Ok(col)) = (u16::try_from(row), u16::try_from(col)) else {
            return false;
        };
        self.pixels.binary_search(&Pixel { row, col }).is_ok()
    }

    /// Number of defective pixels.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }
}
