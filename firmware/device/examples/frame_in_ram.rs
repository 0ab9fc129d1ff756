//! For the firmware engineer: a raw frame in RAM -> the tile decoder with the shipped
//! ensemble -> a `PatchSink`, with every buffer caller-owned and no heap.
//!
//! Build for the camera's core, or run it in qemu (the runner in `.cargo/config.toml`):
//!
//!     cargo run --profile device -p slf-device --example frame_in_ram --target thumbv7em-none-eabihf
//!
//! On the host (`cargo run -p slf-device --example frame_in_ram`) the same `decode` runs.
#![cfg_attr(target_os = "none", no_std, no_main)]

use slf_firmware::prelude::*;

/// The sensor: 10 x 10 lenslets of 5 x 5 pixels, one snapshot through a pixel mask.
const LENSLETS: (u16, u16) = (10, 10);
const LENSLET: LensletSize = LensletSize { rows: 5, cols: 5 };
const ROWS: usize = 50;
const COLS: usize = 50;

/// Where patches go: here a count and a sum; on a camera, a DMA buffer or a host link.
#[derive(Default)]
struct Summary {
    patches: u32,
    sum: f32,
}

impl PatchSink<PaperShape> for Summary {
    type Error = core::convert::Infallible;
    fn accept(&mut self, _: PatchOrigin, patch: &PaperPatch, _: &PatchReport) -> Result<(), Self::Error> {
        self.patches += 1;
        self.sum += patch.iter().sum::<f32>();
        Ok(())
    }
}

/// Decodes every tile of `frame` (12-bit DN, black 64, white 3691.9) into `sink`.
fn decode(frame: &[u16], ws: &mut PaperWorkspace, sink: &mut Summary) -> Result<TileReport, SetupError> {
    let config = DecoderConfig {
        sensor: SensorGeometry { lenslets: LENSLETS, lenslet: LENSLET },
        mask: Mask::pixel(7, 1, 13, LENSLET)?, // the mask the camera was calibrated with
        raw: RawFormat { black: 64.0, white: 3691.9, max_valid: 4094.5 },
        defects: DefectList::EMPTY,
        sl0: Sl0Config::DEFAULT,
    };
    let decoder = PaperDecoder::new(config)?;
    let model =
        PaperEnsembleModel::new(PaperEnsemble::new(DEFAULT_ENSEMBLE)?, MemberChoice::Screened(ChoiceRule::DEFAULT));
    let frames = [RawFrame::new(frame, ROWS, COLS)?];
    let report = decoder.decode_frame(&model, (1, 1), &mut FrameSource::new(&frames), sink, ws);
    Ok(report.patches)
}

/// A frame as the sensor's DMA would leave it: a smooth grey ramp.
fn expose(frame: &mut [u16]) {
    for (i, px) in frame.iter_mut().enumerate() {
        *px = 600 + (i % COLS) as u16 * 20 + (i / COLS) as u16 * 10;
    }
}

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use cortex_m_semihosting::{debug, hprintln};
    use panic_semihosting as _;
    // Caller-owned memory: the workspace (66 KiB) and the frame live in statics.
    let ws = cortex_m::singleton!(: PaperWorkspace = PaperWorkspace::new());
    let frame = cortex_m::singleton!(: [u16; ROWS * COLS] = [0; ROWS * COLS]);
    let mut sink = Summary::default();
    let result = match (ws, frame) {
        (Some(ws), Some(frame)) => {
            expose(frame);
            decode(frame, ws, &mut sink)
        }
        _ => Ok(TileReport::default()),
    };
    let ok = matches!(result, Ok(r) if r.decoded > 0 && r.failed == 0);
    match result {
        Ok(r) => hprintln!("decoded {} patches ({} failed), sum {}", r.decoded, r.failed, sink.sum as u32),
        Err(e) => hprintln!("set-up failed: {}", e),
    }
    debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
    loop {
        cortex_m::asm::wfi(); // not reached under a debugger or qemu
    }
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    let mut ws = Box::new(PaperWorkspace::new());
    let mut frame = vec![0u16; ROWS * COLS];
    expose(&mut frame);
    let mut sink = Summary::default();
    match decode(&frame, &mut ws, &mut sink) {
        Ok(r) if r.decoded > 0 && r.failed == 0 => {
            println!("decoded {} patches, mean {:.4}", r.decoded, sink.sum / (sink.patches as f32 * 5200.0));
            std::process::ExitCode::SUCCESS
        }
        Ok(r) => {
            eprintln!("error: {} patches decoded, {} failed", r.decoded, r.failed);
            std::process::ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
