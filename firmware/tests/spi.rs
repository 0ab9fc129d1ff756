//! The SPI frame-buffer tile source: the exact bytes on the wire (embedded-hal-mock), the
//! same patches as the in-memory source, and bus errors, short reads and a buffer that is
//! not ready each failing only their tile.

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTx};
use slf_firmware::raw::ReadError;
use slf_firmware::*;

#[test]
fn one_read_puts_the_documented_bytes_on_the_wire() {
    // Frame 10 x 20, sample (snapshot 1, row 2, col 3): address 2 * ((1 * 10 + 2) * 20 + 3) = 486.
    let spi = SpiMock::new(&[
        SpiTx::transaction_start(),
        SpiTx::write_vec(vec![0x03, 0x00, 0x01, 0xE6]),
        SpiTx::read_vec(vec![0x00, 0x08]),
        SpiTx::read_vec(vec![0x40, 0x00, 0x41, 0x00, 0xFF, 0x0F, 0x00, 0x00]),
        SpiTx::transaction_end(),
    ]);
    let ready = PinMock::new(&[PinTx::get(State::High)]);
    let mut src = SpiFrameBuffer::new(spi, ready, 10, 20, 2);
    let mut out = [0.0f32; 4];
    src.read(1, 2, 3, &mut out).unwrap();
    assert_eq!(out, [64.0, 65.0, 4095.0, 0.0]);
    let (mut spi, mut ready) = src.release();
    spi.done();
    ready.done();
}

#[test]
fn a_buffer_that_is_not_ready_or_out_of_range_is_an_error_without_bus_traffic() {
    let spi = SpiMock::new(&[]);
    let ready = PinMock::new(&[PinTx::get(State::Low)]);
    let mut src = SpiFrameBuffer::new(spi, ready, 10, 20, 2);
    let mut out = [0.0f32; 4];
    assert_eq!(src.read(0, 0, 0, &mut out), Err(SpiSourceError::NotReady));
    assert_eq!(src.read(2, 0, 0, &mut out), Err(SpiSourceError::OutOfRange));
    assert_eq!(src.read(0, 0, 18, &mut out), Err(SpiSourceError::OutOfRange));
    let (mut spi, mut ready) = src.release();
    spi.done();
    ready.done();
}

/// An SPI frame-buffer chip: serves the protocol from memory, with faults on request.
struct Chip {
    memory: Vec<u8>,
    /// Byte addresses in this range fail with a bus error...
    bus_error: core::ops::Range<usize>,
    /// ...or report only half the bytes asked for.
    short: core::ops::Range<usize>,
}

impl ErrorType for Chip {
    type Error = ErrorKind;
}

impl SpiDevice for Chip {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        let [Operation::Write(cmd), Operation::Read(count), Operation::Read(data)] = ops else {
            return Err(ErrorKind::Other);
        };
        assert_eq!(cmd[0], 0x03);
        let addr = (cmd[1] as usize) << 16 | (cmd[2] as usize) << 8 | cmd[3] as usize;
        if self.bus_error.contains(&addr) {
            return Err(ErrorKind::ModeFault);
        }
        let mut avail = data.len().min(self.memory.len().saturating_sub(addr));
        if self.short.contains(&addr) {
            avail /= 2;
        }
        count.copy_from_slice(&(avail as u16).to_be_bytes());
        data[..avail].copy_from_slice(&self.memory[addr..addr + avail]);
        Ok(())
    }
}

struct High;
impl embedded_hal::digital::ErrorType for High {
    type Error = core::convert::Infallible;
}
impl embedded_hal::digital::InputPin for High {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        Ok(true)
    }
    fn is_low(&mut self) -> Result<bool, Self::Error> {
        Ok(false)
    }
}

const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
const SENSOR: SensorGeometry = SensorGeometry { lenslets: (10, 10), lenslet: L5 };

fn frames() -> Vec<Vec<u16>> {
    (0..2).map(|j| (0..2500).map(|p| (800 + (p * 37 + j * 11) % 2000) as u16).collect()).collect()
}

fn chip(frames: &[Vec<u16>], bus_error: core::ops::Range<usize>, short: core::ops::Range<usize>) -> Chip {
    let memory = frames.iter().flatten().flat_map(|s| s.to_le_bytes()).collect();
    Chip { memory, bus_error, short }
}

#[derive(Default)]
struct Collect(Vec<(PatchOrigin, Vec<f32>)>);

impl PatchSink<PaperShape> for Collect {
    type Error = ();
    fn accept(&mut self, o: PatchOrigin, p: &[f32; 5200], _: &PatchReport) -> Result<(), ()> {
        self.0.push((o, p.to_vec()));
        Ok(())
    }
}

fn decoder(mask: Mask<'static>) -> TileDecoder<'static, PaperShape> {
    let raw = RawFormat::bits(12, 64.0);
    TileDecoder::new(DecoderConfig { sensor: SENSOR, mask, raw, defects: DefectList::EMPTY, sl0: Sl0Config::DEFAULT })
        .unwrap()
}

#[test]
fn spi_source_gives_the_in_memory_patches_and_faults_lose_only_their_tile() {
    let f = frames();
    let dec = decoder(Mask::pixel(4, 2, 13, L5).unwrap());
    let dict = Dictionary::dct();
    let mut ws = Box::new(PaperWorkspace::new());

    // Reference: the same frames in memory.
    let raw: Vec<RawFrame<u16>> = f.iter().map(|x| RawFrame::new(x, 50, 50).unwrap()).collect();
    let mut reference = Collect::default();
    let r = dec.decode_frame(&dict, (1, 1), &mut FrameSource::new(&raw), &mut reference, &mut ws);
    assert_eq!((r.tiles, r.failed_tiles, r.patches.decoded), (4, 0, 16));

    // Over SPI, no faults: the same patches, bit for bit.
    let mut spi = SpiFrameBuffer::new(chip(&f, 0..0, 0..0), High, 50, 50, 2);
    let mut got = Collect::default();
    let r = dec.decode_frame(&dict, (1, 1), &mut spi, &mut got, &mut ws);
    assert_eq!((r.failed_tiles, r.patches.decoded), (0, 16));
    assert_eq!(got.0, reference.0);

    // A bus error inside tile (5, 5) (sensor row 30, col 30 of snapshot 0), then a short
    // read inside tile (0, 5) (snapshot 1, row 2, col 26): each fails its tile only.
    let bus = 2 * (30 * 50 + 30);
    let short = 2 * (2500 + 2 * 50 + 26);
    let mut spi = SpiFrameBuffer::new(chip(&f, bus..bus + 1, short..short + 1), High, 50, 50, 2);
    let mut got = Collect::default();
    let r = dec.decode_frame(&dict, (1, 1), &mut spi, &mut got, &mut ws);
    assert_eq!(r.failed_tiles, 2);
    assert_eq!(r.patches.decoded, 8);
    let (tile, err) = r.first_failure.unwrap();
    assert_eq!((tile.lenslet_row, tile.lenslet_col), (0, 5));
    assert_eq!(err, TileError::Source(SpiSourceError::ShortRead { wanted: 8, available: 4 }));
    // Nothing else lost: every patch of the two healthy tiles arrives, and every patch that
    // arrives (a faulty tile's patches before its fault included) equals the reference.
    let healthy = |o: &PatchOrigin| matches!((o.lenslet_row, o.lenslet_col), (0, 0) | (5, 0));
    assert_eq!(got.0.iter().filter(|(o, _)| healthy(o)).count(), 8);
    for (o, p) in &got.0 {
        let want = reference.0.iter().find(|(r, _)| r == o).map(|(_, p)| p);
        assert!(want == Some(p), "patch {o:?} differs from the in-memory decode");
    }
    // Tile (0, 5) failed at window (0, 1): its window (0, 0) patch was already delivered.
    assert_eq!(got.0.len(), 9);
    // The bus error reached the caller as its kind.
    let mut spi = SpiFrameBuffer::new(chip(&f, bus..bus + 1, 0..0), High, 50, 50, 2);
    let t = Tile { lenslet_row: 5, lenslet_col: 5, lenslet_rows: 5, lenslet_cols: 5 };
    let e = dec.decode_tile(&dict, t, &mut spi, &mut Collect::default(), &mut ws).unwrap_err();
    assert_eq!(e, TileError::Source(SpiSourceError::Bus(ErrorKind::ModeFault)));
    assert!(SpiSourceError::ShortRead { wanted: 8, available: 4 }.to_string().contains("short read"));
    let _ = ReadError::NoSuchSnapshot { snapshot: 0 };
}
