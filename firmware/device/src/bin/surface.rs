//! `slf-surface`: every public decode entry point of `slf-firmware`, linked into one device
//! image and run once each, so that CI can prove the whole decode surface (not only the
//! paths the demo binary happens to take) compiles to no panic call: every mask family
//! (seeded and tiled), defect lists, the raw frame types, the SPI frame buffer, the DCT, a
//! learned member, every member choice and rule, the noise-aware, early-stop and flat
//! paths, warm solves, and the paper's pseudo-inverse path (its set-up SVDs included).
//!
//! Inputs pass through `black_box` so nothing is folded away at compile time. Under qemu it
//! exits 0 when every path returned (a typed error counts as returned; only a panic or a
//! hang fails). `scripts/panic-sites.py` reads its ELF in CI.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod device {
    use core::convert::Infallible;
    use core::hint::black_box;

    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};
    use embedded_hal::digital::{ErrorType as PinErrorType, InputPin};
    use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
    use panic_semihosting as _;
    use slf_firmware::blob::write_blob;
    use slf_firmware::pinv::{PinvOperator, solve_pinv};
    use slf_firmware::prelude::*;
    use slf_firmware::sl0::solve_warm;
    use slf_firmware::{PaperShape, solve};

    const LENSLET: LensletSize = LensletSize { rows: 5, cols: 5 };
    const ROWS: usize = 50;
    const COLS: usize = 50;

    /// A frame buffer chip that answers every read with a ramp.
    struct FakeSpi;
    impl ErrorType for FakeSpi {
        type Error = Infallible;
    }
    impl SpiDevice for FakeSpi {
        fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
            for op in ops {
                if let Operation::Read(buf) = op {
                    for (i, b) in buf.iter_mut().enumerate() {
                        *b = if i % 2 == 0 { 0x40 } else { 0x06 };
                    }
                }
            }
            Ok(())
        }
    }
    struct Ready;
    impl PinErrorType for Ready {
        type Error = Infallible;
    }
    impl InputPin for Ready {
        fn is_high(&mut self) -> Result<bool, Infallible> {
            Ok(true)
        }
        fn is_low(&mut self) -> Result<bool, Infallible> {
            Ok(false)
        }
    }

    /// Counts what it is given.
    #[derive(Default)]
    struct Count(u32, u32);
    impl<S: Shape> PatchSink<S> for Count {
        type Error = Infallible;
        fn accept(&mut self, _: PatchOrigin, p: &PerValue<S, f32>, _: &PatchReport) -> Result<(), Infallible> {
            self.0 += u32::from(p.iter().all(|x| x.is_finite()));
            Ok(())
        }
        fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Infallible> {
            self.1 += 1;
            Ok(())
        }
    }

    /// Counts the finished rows of an overlapped decode.
    #[derive(Default)]
    struct Rows(u32);
    impl RowSink for Rows {
        type Error = Infallible;
        fn row(&mut self, _: u16, _: u16, values: &[f32]) -> Result<(), Infallible> {
            self.0 += u32::from(values.iter().all(|x| x.is_finite()));
            Ok(())
        }
    }

    /// Ring columns of the full-view overlapped decode below: 4 of the sensor's 10 (bands).
    const STRIP: usize = 4 * 9 * 25 * 14;

    static TILE: [u8; 2 * 3 * 4] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10];
    static DEFECTS: [Pixel; 2] = [Pixel { row: 3, col: 4 }, Pixel { row: 20, col: 31 }];
    const BLOB_LEN: usize = slf_firmware::blob::blob_len([5, 5, 4, 4, 13], 2);

    fn frame(i: usize) -> u16 {
        600 + (i % COLS) as u16 * 20 + (i / COLS) as u16 * 10
    }

    #[entry]
    fn main() -> ! {
        let ok = run();
        debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
        loop {
            cortex_m::asm::wfi();
        }
    }

    fn run() -> bool {
        let Some(ws) = cortex_m::singleton!(: PaperWorkspace = PaperWorkspace::new()) else { return false };
        let Some(data) = cortex_m::singleton!(: [u16; ROWS * COLS] = [0; ROWS * COLS]) else { return false };
        for (i, x) in data.iter_mut().enumerate() {
            *x = black_box(frame(i));
        }
        let Some(bytes) = cortex_m::singleton!(: [u8; 2 * ROWS * COLS] = [0; 2 * ROWS * COLS]) else { return false };
        for (i, b) in bytes.chunks_exact_mut(2).enumerate() {
            b.copy_from_slice(&frame(i).to_le_bytes());
        }
        let k = black_box(2u8);
        let seed = black_box(7u64);
        let mut done = 0u32;

        // Masks of every family and source; defects; the solver's optional paths.
        let tile = BandTile::new(black_box(3), black_box(4), k, 13, &TILE);
        let masks = [
            Mask::pixel(seed, k, 13, LENSLET),
            Mask::lenslet(seed, k, 13, LENSLET),
            Mask::kronecker(seed, k, 13, LENSLET, (5, 5)),
            tile.and_then(|t| Mask::pixel_tile(t, 13, LENSLET)),
            tile.and_then(|t| Mask::lenslet_tile(t, 13, LENSLET)),
        ];
        let defects = DefectList::new(&DEFECTS).unwrap_or_default();
        let mut noisy = Sl0Config::DEFAULT;
        noisy.noise = black_box(0.01);
        noisy.tolerance = black_box(1e-3);
        noisy.flat = black_box(4e-3);
        noisy.max_iterations = black_box(40);
        let mut short = Sl0Config::DEFAULT;
        short.max_iterations = black_box(30);

        let ensemble = PaperEnsemble::new(DEFAULT_ENSEMBLE);
        let rule = ChoiceRule::Residual { tau: black_box(100) };
        let choices = [
            MemberChoice::Screened(rule),
            MemberChoice::ScreenedResolve(ChoiceRule::L1),
            MemberChoice::Exhaustive(ChoiceRule::Count { threshold: black_box(0.01) }),
        ];
        let dct = PaperDictionary::dct();
        let frames_u16 = [RawFrame::new(&data[..], ROWS, COLS), RawFrame::new(&data[..], ROWS, COLS)];
        let frames_le = [LeU16Frame::new(&bytes[..], ROWS, COLS), LeU16Frame::new(&bytes[..], ROWS, COLS)];
        let raw = RawFormat { black: 64.0, white: 3691.9, max_valid: 4094.5 };

        for (m, mask) in masks.iter().enumerate() {
            let Ok(mask) = mask else { continue };
            let cfg = if m % 2 == 0 { short } else { noisy };
            let config = DecoderConfig {
                sensor: SensorGeometry { lenslets: (10, 10), lenslet: LENSLET },
                mask: *mask,
                raw,
                defects: if m == 1 { defects } else { DefectList::EMPTY },
                sl0: cfg,
            };
            let Ok(decoder) = PaperDecoder::new(config) else { continue };
            let Some(tile) = decoder.tiles((1, 1)).next() else { continue };
            let mut sink = Count::default();
            // The DCT from u16 frames, an ensemble choice from little-endian bytes, and the
            // SPI frame buffer: each once per mask.
            if let [Ok(a), Ok(b)] = &frames_u16 {
                let _ = decoder.decode_tile(&dct, tile, &mut FrameSource::new(&[*a, *b]), &mut sink, ws);
            }
            if let ([Ok(a), Ok(b)], Ok(e)) = (&frames_le, &ensemble) {
                let model = PaperEnsembleModel::new(*e, choices[m % 3]);
                let _ = decoder.decode_tile(&model, tile, &mut FrameSource::new(&[*a, *b]), &mut sink, ws);
            }
            let mut spi = SpiFrameBuffer::new(FakeSpi, Ready, ROWS, COLS, 2);
            let _ = decoder.decode_tile(&dct, tile, &mut spi, &mut sink, ws);
            done += sink.0 + sink.1;
        }

        // The full-view patch (every view of a lenslet): the DCT and the shipped full-view
        // ensemble, tile by tile, sheared to half pixels, and overlapped through a strip of
        // 4 columns (3 bands), seeded with nothing.
        let full_ws = cortex_m::singleton!(: FullViewWorkspace = FullViewWorkspace::new());
        let strip = cortex_m::singleton!(: [f32; STRIP] = [0.0; STRIP]);
        if let (Some(full_ws), Some(strip), Ok(mask), [Ok(a), Ok(b)]) = (full_ws, strip, masks[0], &frames_u16) {
            let config = DecoderConfig {
                sensor: SensorGeometry { lenslets: (10, 10), lenslet: LENSLET },
                mask,
                raw,
                defects,
                sl0: noisy,
            };
            let full_dct = FullViewDictionary::dct();
            let halves = DisparityRange::DEFAULT.with_halves(black_box(true));
            if let Ok(decoder) = FullViewDecoder::new(config).map(|d| d.with_disparities(halves)) {
                let mut sink = Count::default();
                let frames = [*a, *b];
                let source = &mut FrameSource::new(&frames);
                if let Some(tile) = decoder.tiles((1, 1)).next() {
                    let _ = decoder.decode_tile(&full_dct, tile, source, &mut sink, full_ws);
                    if let Ok(e) = FullViewEnsemble::new(DEFAULT_FULL_VIEW_ENSEMBLE) {
                        let model = FullViewEnsembleModel::new(e, choices[0]);
                        let _ = decoder.decode_tile(&model, tile, source, &mut sink, full_ws);
                        let _ = decoder.decode_tile_seeded(
                            &model,
                            tile,
                            source,
                            &mut slf_firmware::NoSeed,
                            &mut sink,
                            full_ws,
                        );
                        // The error estimate from held-out measurements, and a tight
                        // plausibility bound (every patch decoded again and clipped).
                        let tight = slf_firmware::Plausibility { factor: black_box(1.0), margin: 0.0 };
                        if let Ok(estimating) = decoder
                            .with_error_estimate(Some(slf_firmware::HoldOut::DEFAULT))
                            .and_then(|d| d.with_plausibility(tight))
                        {
                            let _ = estimating.decode_tile(&model, tile, source, &mut sink, full_ws);
                            let checking = estimating.with_shear_check(black_box(true));
                            let _ = checking.decode_tile(&full_dct, tile, source, &mut sink, full_ws);
                        }
                    }
                }
                let overlap = Overlap { stride: (black_box(2), 2), window: Window::Tapered, seeded: black_box(true) };
                if let Ok(od) = FullViewOverlapDecoder::new(decoder, overlap) {
                    let mut rows = Rows::default();
                    let _ = od.decode_frame(&full_dct, &mut FrameSource::new(&[*a, *b]), strip, &mut rows, full_ws);
                    done += rows.0;
                }
                done += sink.0 + sink.1;
            }
        }

        // One patch by hand: solve, a warm solve with a learned member, a blob written.
        ws.measurements_mut().clear();
        for p in 0..PaperShape::PIXELS {
            let _ = ws.measurements_mut().set(p * 13 + (p * 5) % 13, black_box(0.3));
        }
        let _ = solve(&dct, &short, ws);
        let blob = cortex_m::singleton!(: [u8; BLOB_LEN] = [0; BLOB_LEN]);
        if let (Ok(member), Some(blob)) = (ensemble.and_then(|e| e.member(black_box(3))), blob) {
            let _ = solve_warm(&member, &short, ws);
            let _ = write_blob(&[dct.clone(), member], blob);
            done += u32::from(PaperEnsemble::new(blob).is_ok());
        }

        // The paper's general path for a kronecker block: set-up SVDs and the solve.
        if let Ok(mask) = masks[2]
            && let Ok(phi) = mask.kronecker_phi::<Fixed<5>, Fixed<5>, Fixed<4>, Fixed<4>>(black_box(0), black_box(0))
            && let Ok(op) = PinvOperator::new(&dct, &phi)
        {
            ws.measurements_mut().clear();
            for p in 0..PaperShape::PIXELS {
                for &b in &phi.bands {
                    let _ = ws.measurements_mut().set(p * 13 + b as usize, black_box(0.3));
                }
            }
            done += u32::from(solve_pinv(&op, &short, ws).is_ok());
        }
        hprintln!("surface: {} results", done);
        done > 0
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!("slf-surface runs on a Cortex-M core: build with --target thumbv7em-none-eabihf");
}
