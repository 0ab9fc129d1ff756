//! On a workstation: a raw frame in memory -> the tile decoder with the shipped ensemble
//! -> patches collected with where they belong. The same library code the camera runs,
//! with `std` around it (a heap-allocated workspace, a `Vec` sink).
//!
//!     cargo run --release -p slf-firmware --example decode_host
//!
//! `slf decode` (host-sim) does this for a capture folder, over all cores.

use slf_firmware::prelude::*;

/// Every decoded patch with its origin; rejected patches are counted.
#[derive(Default)]
struct Collect {
    patches: Vec<(PatchOrigin, Box<PaperPatch>)>,
    rejected: usize,
}

impl PatchSink<PaperShape> for Collect {
    type Error = core::convert::Infallible;
    fn accept(&mut self, at: PatchOrigin, patch: &PaperPatch, _: &PatchReport) -> Result<(), Self::Error> {
        self.patches.push((at, Box::new(*patch)));
        Ok(())
    }
    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        self.rejected += 1;
        Ok(())
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 10 x 15 lenslets of 5 x 5 pixels, one snapshot of a seeded pixel mask, 12-bit DN.
    let lenslet = LensletSize { rows: 5, cols: 5 };
    let (rows, cols) = (50, 75);
    let frame: Vec<u16> = (0..rows * cols).map(|i| 500 + (i % cols) as u16 * 30 + (i / cols) as u16 * 5).collect();
    let config = DecoderConfig {
        sensor: SensorGeometry { lenslets: (10, 15), lenslet },
        mask: Mask::pixel(7, 1, 13, lenslet).map_err(SetupError::from)?,
        raw: RawFormat { black: 64.0, white: 3691.9, max_valid: 4094.5 },
        defects: DefectList::EMPTY,
        sl0: Sl0Config::DEFAULT,
    };
    let decoder = PaperDecoder::new(config).map_err(SetupError::from)?;
    let ensemble = PaperEnsemble::new(DEFAULT_ENSEMBLE).map_err(SetupError::from)?;
    let model = PaperEnsembleModel::new(ensemble, MemberChoice::Screened(ChoiceRule::DEFAULT));
    let frames = [RawFrame::new(&frame, rows, cols).map_err(SetupError::from)?];
    let mut ws = Box::new(PaperWorkspace::new()); // 66 KiB: on the heap here, a static on a device
    let mut sink = Collect::default();
    let report = decoder.decode_frame(&model, (2, 2), &mut FrameSource::new(&frames), &mut sink, &mut ws);
    let Some((first, _)) = sink.patches.first() else {
        return Err(format!("no patch decoded ({} rejected)", sink.rejected).into());
    };
    println!(
        "{} tiles, {} patches decoded, {} rejected; the first at lenslet ({}, {}), view ({}, {})",
        report.tiles,
        report.patches.decoded,
        sink.rejected,
        first.lenslet_row,
        first.lenslet_col,
        first.view_row,
        first.view_col
    );
    Ok(())
}
