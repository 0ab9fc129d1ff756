//! Sensor access over `embedded-hal` 1.0: a [`TileSource`] that reads raw samples from an
//! SPI frame buffer (the capture held by the sensor's FIFO or an external SPI RAM).
//!
//! Wire protocol (one `SpiDevice` transaction per run of samples; chip select is the
//! `SpiDevice`'s):
//!
//! 1. write `READ` (0x03) and the 24-bit byte address, most significant first; the
//!    address of sample `(snapshot, row, col)` is `2 * ((snapshot * rows + row) * cols + col)`
//!    (frames stored one after another, row-major, little-endian u16);
//! 2. read 2 bytes: how many bytes the buffer can deliver from there (big-endian);
//! 3. read the samples, 2 bytes each.
//!
//! A ready pin (an `InputPin`, high when a whole capture is in the buffer) is sampled
//! before each read. A bus error, a pin error, a buffer that is not ready, or one that has
//! fewer bytes than asked for (a short read) is a typed [`SpiSourceError`]: the tile
//! decoder abandons that tile only and goes on with the next.

use core::fmt;

use embedded_hal::digital::InputPin;
use embedded_hal::spi::{Operation, SpiDevice};

use crate::sensor::source::TileSource;

/// The read command byte.
pub const READ: u8 = 0x03;
/// The longest run of samples one read may ask for.
pub const MAX_RUN: usize = 32;

/// Why a read from the SPI frame buffer failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SpiSourceError {
    /// The SPI bus or device failed.
    Bus(embedded_hal::spi::ErrorKind),
    /// The ready pin could not be read.
    Pin(embedded_hal::digital::ErrorKind),
    /// The frame buffer does not hold a complete capture yet.
    NotReady,
    /// The buffer had fewer bytes than the read asked for.
    ShortRead { wanted: u16, available: u16 },
    /// The read lies outside the capture, or is longer than [`MAX_RUN`].
    OutOfRange,
}

impl fmt::Display for SpiSourceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Bus(k) => write!(f, "SPI bus error: {k:?}"),
            Self::Pin(k) => write!(f, "ready pin error: {k:?}"),
            Self::NotReady => f.write_str("frame buffer not ready"),
            Self::ShortRead { wanted, available } => write!(f, "short read: {available} of {wanted} bytes"),
            Self::OutOfRange => f.write_str("read outside the capture"),
        }
    }
}

impl core::error::Error for SpiSourceError {}

/// A capture of `snapshots` frames of `rows x cols` samples in an SPI frame buffer.
#[derive(Debug)]
pub struct SpiFrameBuffer<SPI, RDY> {
    spi: SPI,
    ready: RDY,
    rows: usize,
    cols: usize,
    snapshots: usize,
}

impl<SPI: SpiDevice, RDY: InputPin> SpiFrameBuffer<SPI, RDY> {
    /// A source over the device `spi` with its ready pin.
    pub fn new(spi: SPI, ready: RDY, rows: usize, cols: usize, snapshots: usize) -> Self {
        Self { spi, ready, rows, cols, snapshots }
    }

    /// Gives the bus and pin back.
    pub fn release(self) -> (SPI, RDY) {
        (self.spi, self.ready)
    }
}

impl<SPI: SpiDevice, RDY: InputPin> TileSource for SpiFrameBuffer<SPI, RDY> {
    type Error = SpiSourceError;

    fn read(&mut self, snapshot: usize, row: usize, col: usize, out: &mut [f32]) -> Result<(), SpiSourceError> {
        if snapshot >= self.snapshots
            || row >= self.rows
            || col.saturating_add(out.len()) > self.cols
            || out.len() > MAX_RUN
        {
            return Err(SpiSourceError::OutOfRange);
        }
        match self.ready.is_high() {
            Ok(true) => {}
            Ok(false) => return Err(SpiSourceError::NotReady),
            Err(e) => return Err(SpiSourceError::Pin(embedded_hal::digital::Error::kind(&e))),
        }
        let address = 2 * ((snapshot * self.rows + row) * self.cols + col);
        if address + 2 * out.len() > 1 << 24 {
            return Err(SpiSourceError::OutOfRange);
        }
        let cmd = [READ, (address >> 16) as u8, (address >> 8) as u8, address as u8];
        let mut count = [0u8; 2];
        let mut data = [0u8; 2 * MAX_RUN];
        let wanted = 2 * out.len();
        let bytes = data.get_mut(..wanted).ok_or(SpiSourceError::OutOfRange)?;
        self.spi
            .transaction(&mut [Operation::Write(&cmd), Operation::Read(&mut count), Operation::Read(bytes)])
            .map_err(|e| SpiSourceError::Bus(embedded_hal::spi::Error::kind(&e)))?;
        let available = u16::from_be_bytes(count);
        if (available as usize) < wanted {
            return Err(SpiSourceError::ShortRead { wanted: wanted as u16, available });
        }
        let (pairs, _) = bytes.as_chunks::<2>();
        for (o, p) in out.iter_mut().zip(pairs) {
            *o = f32::from(u16::from_le_bytes(*p));
        }
        Ok(())
    }
}
