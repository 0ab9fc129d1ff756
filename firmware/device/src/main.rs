//! `slf-device`: the decoder on a Cortex-M core.
//!
//! Decodes every tile of the capture in `firmware/device/capture` (written by
//! `slf device-capture`, included in flash at build time) in full-view patches (5 x 5
//! lenslets x all 5 x 5 views x 13 bands) with the shipped 8-member full-view ensemble and
//! screened member choice, and prints over semihosting every decoded patch
//! (f32 bit patterns) for `slf device-check` to compare with the host's decode. Then it
//! decodes the same tiles with the 5D DCT, runs the model trial (a pilot on each tile's
//! block: the DCT against the ensemble by their held-out errors, printed with its pick), and
//! last decodes the whole frame with the picked model as the host's default decodes it
//! (overlapping patches at stride 2, tapered window, the shifted grids seeded from the
//! disjoint grid's decode: the engine the host drives) through a strip of lenslet rows,
//! printing each finished row.
//! `bench_begin` / `bench_end` bracket one synthesis, then each ensemble tile, then each
//! DCT tile, then each pilot, then the overlapped frame, then one block's disparity
//! choice, then the DCT tiles sheared to whole and to half-pixel disparities, then a real
//! sensor's tiles uncalibrated, calibrated, and with the error estimate, so the qemu plugin
//! `scripts/wincount/wincount.c` counts instructions per transform and per patch. The
//! stack is painted at start and scanned at the end for its peak depth.
//!
//! Run: `cargo run --profile device -p slf-device --target thumbv7em-none-eabihf` (qemu's
//! Cortex-M7 board `mps2-an500` is the runner, see `.cargo/config.toml`; the memory map is
//! the top-level `memory.x`: the stack in the 128 KiB DTCM, the workspace and the strip in the
//! 512 KiB RAM). On the host this file builds to a stub that says so.
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Instruction-count window markers: never inlined, distinct bodies, addresses found by
/// symbol name. `black_box` keeps the calls and bodies from being folded away.
#[unsafe(no_mangle)]
#[inline(never)]
pub extern "C" fn bench_begin(x: u32) -> u32 {
    core::hint::black_box(x).wrapping_add(0x5f0d)
}

#[unsafe(no_mangle)]
#[inline(never)]
pub extern "C" fn bench_end(x: u32) -> u32 {
    core::hint::black_box(x).wrapping_mul(0x2545_f491)
}

#[cfg(target_os = "none")]
mod device {
    include!("../capture.rs");

    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprint, hprintln};
    #[cfg(feature = "defmt")]
    use defmt_semihosting as _;
    use panic_semihosting as _;
    use slf_firmware::Shape as _;
    use slf_firmware::{
        ChoiceRule, DEFAULT_FULL_VIEW_ENSEMBLE, DecoderConfig, DefectList, Dictionary, Disparity, DisparityRange,
        Ensemble, EnsembleModel, FrameSource, FullViewShape, FullViewWorkspace, HoldOut, LeU16Frame, LensletGrid,
        LensletSize, Mask, MemberChoice, Overlap, OverlapDecoder, PairedErrors, PatchModel, PatchOrigin, PatchReport,
        PatchSink, Pick, Picked, Pixel, RawFormat, Response, ResponseModel, RowSink, ScheduledDictionary,
        SensorGeometry, Sl0Config, TileDecoder, tie_prior,
    };

    use super::{bench_begin, bench_end};

    static FRAMES: [&[u8]; 3] = [
        include_bytes!("../capture/snapshot_0.npy"),
        include_bytes!("../capture/snapshot_1.npy"),
        include_bytes!("../capture/snapshot_2.npy"),
    ];

    /// The real sensor's frames (leaky filters, vignetting, dark spread, hot pixels).
    static SENSOR_FRAMES: [&[u8]; 3] = [
        include_bytes!("../capture-sensor/snapshot_0.npy"),
        include_bytes!("../capture-sensor/snapshot_1.npy"),
        include_bytes!("../capture-sensor/snapshot_2.npy"),
    ];

    /// The body of an `.npy` v1 file: past the 10-byte preamble and the header whose length
    /// is at bytes 8..10.
    fn npy_body(file: &'static [u8]) -> &'static [u8] {
        let header = match file.get(8..10) {
            Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]) as usize,
            _ => 0,
        };
        file.get(10 + header..).unwrap_or(&[])
    }

    /// Folds `values` into `checksum`, in order.
    fn fold(checksum: &mut u32, values: &[f32]) {
        for x in values {
            *checksum = checksum.rotate_left(5) ^ x.to_bits();
        }
    }

    /// Prints `values` as `data` lines of 13 f32 bit patterns (one pixel's bands each).
    fn print_data(values: &[f32]) {
        for chunk in values.chunks(13) {
            hprint!("data");
            for x in chunk {
                hprint!(" {:08x}", x.to_bits());
            }
            hprintln!();
        }
    }

    /// The real sensor's capture decoded with the screened ensemble, through the lenslet
    /// grid its calibration found (the array turned by a degree, 5.1 pixels a lenslet):
    /// windows 8 (each tile as the ideal sensor's, uncalibrated) and 9 (each tile with the
    /// compact calibration: the dark level as the raw black, a flat per view, the hot
    /// pixels as defects, the response matrix unmixing each decoded spectrum), the calibrated patches printed
    /// after a `calibrated` line for `slf device-check`; 10 (uncalibrated, with the error
    /// estimate); 12 (the whole frame uncalibrated as the host's default decodes it, in
    /// `strip`, its rows printed after a `sensor rows` line). Returns the failures.
    #[inline(never)]
    fn calibrated(
        config: &DecoderConfig<'static>,
        model: &EnsembleModel<'static, FullViewShape>,
        frame_model: &Picked<'_, ScheduledDictionary<FullViewShape>, EnsembleModel<'static, FullViewShape>>,
        strip: &mut [f32],
        ws: &mut FullViewWorkspace,
    ) -> u32 {
        static DEFECTS: [Pixel; SENSOR_DEFECTS.len()] = SENSOR_DEFECTS;
        static VIEW_GAINS: [f32; SENSOR_VIEW_GAINS.len()] = SENSOR_VIEW_GAINS;
        let grid =
            LensletGrid::new(SENSOR_GRID_ROTATION, SENSOR_GRID_PITCH, SENSOR_GRID_OFFSET, VIEWS, SENSOR_GRID_SENSOR);
        let Ok(grid) = grid else {
            hprintln!("error: the real sensor's lenslet grid does not validate");
            return 1;
        };
        let (rows, cols) = grid.sensor();
        let mut frames = [LeU16Frame::new(&[], 0, 0).ok(), None, None];
        for (f, file) in frames.iter_mut().zip(SENSOR_FRAMES) {
            *f = LeU16Frame::new(npy_body(file), rows, cols).ok();
        }
        let [Some(f0), Some(f1), Some(f2)] = frames else {
            hprintln!("error: a real sensor's frame does not match the capture's size");
            return 1;
        };
        let frames = [f0, f1, f2];
        let plain = TileDecoder::<FullViewShape>::new(*config)
            .ok()
            .and_then(|d| d.with_grid(Some(grid)).ok())
            .and_then(|d| d.estimate_gains(&mut FrameSource::new(&frames)).ok().and_then(|g| d.with_gains(&g).ok()));
        let (Ok(defects), Ok(response)) = (DefectList::new(&DEFECTS), Response::new(&SENSOR_RESPONSE)) else {
            hprintln!("error: the compact calibration does not validate");
            return 1;
        };
        let raw = RawFormat { black: SENSOR_BLACK, white: SENSOR_WHITE, max_valid: MAX_VALID };
        let calibrated = TileDecoder::<FullViewShape>::new(DecoderConfig { raw, defects, ..*config })
            .ok()
            .and_then(|d| d.with_response(&response, ResponseModel::Unmix).ok())
            .and_then(|d| d.with_view_gains(Some((&VIEW_GAINS, SENSOR_REGIONS))).ok())
            .and_then(|d| d.with_grid(Some(grid)).ok())
            .and_then(|d| d.estimate_gains(&mut FrameSource::new(&frames)).ok().and_then(|g| d.with_gains(&g).ok()));
        let (Some(plain), Some(calibrated)) = (plain, calibrated) else {
            hprintln!("error: the real sensor's decoders were rejected");
            return 1;
        };
        let mut failed = 0;
        let mut quiet = Print { checksum: 0, patches: 0, print: false };
        for tile in plain.tiles((1, 1)) {
            bench_begin(8);
            let r = plain.decode_tile(model, tile, &mut FrameSource::new(&frames), &mut quiet, ws);
            bench_end(8);
            failed += r.map_or(1, |t| t.failed);
        }
        hprint!("calibrated gains");
        for g in calibrated.gains() {
            hprint!(" {:08x}", g.to_bits());
        }
        hprintln!();
        let mut out = Print { checksum: 0, patches: 0, print: true };
        for tile in calibrated.tiles((1, 1)) {
            bench_begin(9);
            let r = calibrated.decode_tile(model, tile, &mut FrameSource::new(&frames), &mut out, ws);
            bench_end(9);
            failed += r.map_or(1, |t| t.failed);
        }
        hprintln!("calibrated patches {} defects {}", out.patches, DEFECTS.len());
        // The same tiles uncalibrated with the error estimate from held-out measurements:
        // its instructions a patch beside the plain decode's (window 8).
        if let Ok(estimating) = plain.with_error_estimate(Some(HoldOut::DEFAULT)) {
            for tile in estimating.tiles((1, 1)) {
                bench_begin(10);
                let r = estimating.decode_tile(model, tile, &mut FrameSource::new(&frames), &mut quiet, ws);
                bench_end(10);
                failed += r.map_or(1, |t| t.failed);
            }
        }
        // Window 12: the real sensor's whole frame behind the grid, uncalibrated, as the
        // host's default decodes it (stride 2, tapered window, seeded: each shifted patch
        // takes its pixels' shares of the cells outside it out of their measurements by the
        // seeds), by the screened ensemble; its rows printed after a `sensor rows` line
        // for `slf device-check`.
        let search = DisparityRange::for_capture(config.mask.family(), SNAPSHOTS);
        let mut rows = PrintRows { checksum: 0, rows: 0 };
        hprintln!("sensor rows");
        match OverlapDecoder::new(plain.with_disparities(search), Overlap::DEFAULT) {
            Ok(overlapped) if overlapped.strip_len(STRIP_COLUMNS) <= strip.len() => {
                bench_begin(12);
                let r = overlapped.decode_frame(frame_model, &mut FrameSource::new(&frames), strip, &mut rows, ws);
                bench_end(12);
                match r {
                    Ok(r) => {
                        failed += r.patches.failed + r.source_failures;
                        hprintln!("sensor overlap patches {}", r.patches.decoded);
                    }
                    Err(_) => failed += 1,
                }
            }
            _ => {
                hprintln!("error: the real sensor's overlapped decode does not fit the strip");
                failed += 1;
            }
        }
        hprintln!("sensor rows end {} checksum {:#010x}", rows.rows, rows.checksum);
        failed
    }

    /// Prints each accepted patch, folds it into a checksum.
    struct Print {
        checksum: u32,
        patches: u32,
        print: bool,
    }

    impl PatchSink<FullViewShape> for Print {
        type Error = core::convert::Infallible;
        fn accept(&mut self, o: PatchOrigin, p: &[f32; 8125], r: &PatchReport) -> Result<(), Self::Error> {
            self.patches += 1;
            fold(&mut self.checksum, p);
            if self.print {
                hprintln!(
                    "patch {} {} {} {} member {} solves {} steps {}",
                    o.lenslet_row,
                    o.lenslet_col,
                    o.view_row,
                    o.view_col,
                    r.member.unwrap_or(u16::MAX),
                    r.solves,
                    r.outcome.iterations
                );
                print_data(p);
            }
            Ok(())
        }
    }

    /// Lenslet columns of the overlapped decode's strip: the capture's 10, in one band.
    const STRIP_COLUMNS: usize = 10;
    /// The part's RAM for statics (`memory.x`: 512 KiB), for the camera-sized frame's band.
    const RAM_BYTES: usize = 512 * 1024;
    /// The strip of the host's default (stride 2, seeded) on the capture: its 5 lenslet
    /// rows (all a patch reaches) x 10 columns x 25 views x (13 sums, 1 weight and 13
    /// seeds) f32, 135,000 B, in the part's 512 KiB RAM beside the workspace.
    const STRIP_LEN: usize = 5 * STRIP_COLUMNS * 25 * 27;

    /// Prints each finished row of the overlapped decode, folds it into a checksum.
    struct PrintRows {
        checksum: u32,
        rows: u32,
    }

    impl RowSink for PrintRows {
        type Error = core::convert::Infallible;
        fn row(&mut self, row: u16, first_col: u16, values: &[f32]) -> Result<(), Self::Error> {
            self.rows += 1;
            hprintln!("row {} {} values {}", row, first_col, values.len());
            print_data(values);
            fold(&mut self.checksum, values);
            Ok(())
        }
    }

    /// The shipped ensemble with screened choice, built in a frame of its own: the
    /// dictionaries `EnsembleModel::new` compares (2 KB each) leave the stack with it
    /// instead of staying in `run`'s frame for the whole decode.
    #[inline(never)]
    fn model() -> Option<EnsembleModel<'static, FullViewShape>> {
        let ensemble = Ensemble::<FullViewShape>::new(DEFAULT_FULL_VIEW_ENSEMBLE).ok()?;
        Some(EnsembleModel::new(ensemble, MemberChoice::Screened(ChoiceRule::DEFAULT)))
    }

    #[entry]
    fn main() -> ! {
        crate::stack::paint();
        let code = run();
        debug::exit(code);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    fn run() -> debug::ExitStatus {
        let Some(ws) = cortex_m::singleton!(: FullViewWorkspace = FullViewWorkspace::new()) else {
            return debug::EXIT_FAILURE;
        };
        let (rows, cols) = (LENSLETS.0 as usize * VIEWS.0 as usize, LENSLETS.1 as usize * VIEWS.1 as usize);
        let mut frames = [LeU16Frame::new(&[], 0, 0).ok(), None, None];
        for (f, file) in frames.iter_mut().zip(FRAMES) {
            *f = LeU16Frame::new(npy_body(file), rows, cols).ok();
        }
        let [Some(f0), Some(f1), Some(f2)] = frames else {
            hprintln!("error: an embedded frame does not match the capture's size");
            return debug::EXIT_FAILURE;
        };
        let frames = [f0, f1, f2];
        let lenslet = LensletSize { rows: VIEWS.0, cols: VIEWS.1 };
        let Ok(mask) = Mask::pixel(MASK_SEED, SNAPSHOTS, 13, lenslet) else {
            return debug::EXIT_FAILURE;
        };
        let config = DecoderConfig {
            sensor: SensorGeometry { lenslets: LENSLETS, lenslet },
            mask,
            raw: RawFormat { black: BLACK, white: WHITE, max_valid: MAX_VALID },
            defects: DefectList::EMPTY,
            sl0: Sl0Config { noise: NOISE, shot: SHOT, ..Sl0Config::DEFAULT },
        };
        let Ok(decoder) = TileDecoder::<FullViewShape>::new(config) else {
            hprintln!("error: decoder config rejected");
            return debug::EXIT_FAILURE;
        };
        // White balance (the host's default): one pass over the frame for each band's mean.
        bench_begin(4);
        let gains = decoder.estimate_gains(&mut FrameSource::new(&frames));
        bench_end(4);
        let Ok(decoder) = gains.map_err(|_| ()).and_then(|g| decoder.with_gains(&g).map_err(|_| ())) else {
            hprintln!("error: the frame's white balance could not be estimated");
            return debug::EXIT_FAILURE;
        };
        hprint!("gains");
        for g in decoder.gains() {
            hprint!(" {:08x}", g.to_bits());
        }
        hprintln!();
        let Some(model) = model() else {
            hprintln!("error: the shipped ensemble does not validate");
            return debug::EXIT_FAILURE;
        };
        // In flash: a `const` table, not 2 KB of the stack.
        static DCT: Dictionary<FullViewShape> = Dictionary::dct();
        let dct = &DCT;

        // Window 0: one synthesis (FullViewShape::TRANSFORM_MACS multiply-adds).
        ws.coefficients_mut().fill(0.5);
        bench_begin(0);
        ws.synthesize(dct);
        bench_end(0);
        hprintln!("transform macs {}", FullViewShape::TRANSFORM_MACS);

        let mut out = Print { checksum: 0, patches: 0, print: true };
        let mut failed = 0u32;
        hprintln!("model ensemble-screened members {}", model.ensemble().len());
        // Windows 1..=T: ensemble tiles.
        for tile in decoder.tiles((1, 1)) {
            bench_begin(1);
            let r = decoder.decode_tile(&model, tile, &mut FrameSource::new(&frames), &mut out, ws);
            bench_end(1);
            match r {
                Ok(t) => {
                    failed += t.failed;
                    hprintln!("tile {} {} patches {}", tile.lenslet_row, tile.lenslet_col, t.decoded);
                }
                Err(_) => failed += 1,
            }
        }
        // Windows T+1..=2T: DCT tiles.
        let mut quiet = Print { checksum: 0, patches: 0, print: false };
        hprintln!("model dct");
        for tile in decoder.tiles((1, 1)) {
            bench_begin(2);
            let r = decoder.decode_tile(dct, tile, &mut FrameSource::new(&frames), &mut quiet, ws);
            bench_end(2);
            if r.is_err() {
                failed += 1;
            }
        }
        let _ = dct.decode(&Sl0Config::DEFAULT, ws);
        let disjoint_stack = crate::stack::peak();

        // Window 11: the model trial, a pilot on every tile's block: the DCT on the
        // ensemble's schedules against the ensemble, by their held-out errors. The picked
        // model decodes the overlapped frame; `slf device-check` runs the same trial.
        // Built in the singleton, not by `EnsembleModel::scheduled_screen`: its value, moved
        // in, took 3.9 KB more peak stack (33,796 B against 29,900, `scripts/budgets.sh`).
        let Some(scheduled) = model.schedules().copied().and_then(|schedules| {
            cortex_m::singleton!(: ScheduledDictionary<FullViewShape> = ScheduledDictionary { dictionary: Dictionary::dct(), schedules })
        }) else {
            hprintln!("error: the shipped ensemble has no trained schedules");
            return debug::EXIT_FAILURE;
        };
        let mut trial = PairedErrors::default();
        for tile in decoder.tiles((1, 1)) {
            bench_begin(11);
            let r = decoder.trial(
                &*scheduled,
                &model,
                (tile.lenslet_row, tile.lenslet_col),
                &mut FrameSource::new(&frames),
                ws,
            );
            bench_end(11);
            match r {
                Ok(t) => trial += t.errors,
                Err(_) => failed += 1,
            }
        }
        // Where the pilots tie, the model the mask and snapshot count favour, as the host's
        // default picks.
        let pick = trial.pick_unless_tied(tie_prior(config.mask.family(), SNAPSHOTS.into()));
        hprintln!(
            "trial pilots {} dct {:08x} ensemble {:08x} pick {}",
            trial.pilots,
            trial.first.to_bits(),
            trial.second.to_bits(),
            if pick == Pick::First { "dct" } else { "ensemble" }
        );
        let picked = Picked { first: &*scheduled, second: &model, pick };

        // Window 3: the whole frame as the host's default decodes it (stride 2, tapered
        // window, seeded) through the strip, printed row by row for `slf device-check`.
        let Some(strip) = cortex_m::singleton!(: [f32; STRIP_LEN] = [0.0; STRIP_LEN]) else {
            return debug::EXIT_FAILURE;
        };
        // Window 5 (after the frame): the disparity choice of one block, alone.
        // The host's default search for the capture (whole disparities on its pixel mask at k > 1).
        let search = DisparityRange::for_capture(config.mask.family(), SNAPSHOTS);
        let depth = decoder.with_disparities(search);
        let Ok(overlapped) = OverlapDecoder::new(depth, Overlap::DEFAULT) else {
            return debug::EXIT_FAILURE;
        };
        if overlapped.strip_len(STRIP_COLUMNS) > STRIP_LEN {
            hprintln!("error: the strip holds less than {} columns", STRIP_COLUMNS);
            return debug::EXIT_FAILURE;
        }
        let mut rows = PrintRows { checksum: 0, rows: 0 };
        hprintln!(
            "overlap stride 2 tapered seeded disparities -1..1 strip columns {} rows {} seed-rows {}",
            STRIP_COLUMNS,
            overlapped.slots().rows,
            overlapped.slots().seed_rows
        );
        bench_begin(3);
        let r = overlapped.decode_frame(&picked, &mut FrameSource::new(&frames), strip, &mut rows, ws);
        bench_end(3);
        match r {
            Ok(r) => {
                failed += r.patches.failed + r.source_failures;
                hprintln!(
                    "overlap patches {} bands {} uncovered {} frame-patches {}",
                    r.patches.decoded,
                    r.bands,
                    r.uncovered,
                    overlapped.patch_decodes(LENSLETS.1 as usize)
                );
            }
            Err(_) => failed += 1,
        }
        // The patch solves of a camera-sized frame (100 x 100 lenslets, the capture's mask
        // and sheared overlap) through the strip this part's RAM holds beside the workspace:
        // `scripts/budgets.sh` projects the frame's time from them. The seeded default holds
        // the rows from the first a pending shifted patch reaches to the last an added
        // disjoint patch reaches, over a band and the columns its seeds are read from: more
        // than the part's RAM at any band width (`band 0`); unseeded, bands fit.
        let camera = SensorGeometry { lenslets: (100, 100), lenslet };
        let ram_left = RAM_BYTES.saturating_sub(core::mem::size_of::<FullViewWorkspace>());
        for overlap in [Overlap::DEFAULT, Overlap { seeded: false, ..Overlap::DEFAULT }] {
            if let Ok(camera) = TileDecoder::<FullViewShape>::new(DecoderConfig { sensor: camera, ..config })
                .map(|d| d.with_disparities(search))
                .and_then(|d| OverlapDecoder::new(d, overlap))
            {
                let band = camera.band_width(ram_left / 4).unwrap_or(0);
                hprintln!(
                    "camera frame 100 x 100 seeded {} rows {} band {} patch-solves {} full-width {} full-width-bytes {}",
                    overlap.seeded as u8,
                    camera.slots().rows,
                    band,
                    if band > 0 { camera.patch_decodes(band) } else { 0 },
                    camera.patch_decodes(100),
                    4 * camera.strip_len(100)
                );
            }
        }
        bench_begin(5);
        let chosen = depth.choose_disparity(2, 3, &mut FrameSource::new(&frames));
        bench_end(5);
        hprintln!("disparity of block 2 3 (half pixels): {}", chosen.map_or(i8::MIN, |d| d.in_halves()));
        let stack = crate::stack::peak();

        // Windows 6 and 7: the DCT tiles' patches again, each read sheared to disparity 1
        // (whole pixels, selections) and to 1/2 (interpolating measurements) and solved,
        // without the choice or edge fallbacks of a sheared tile decode, so the two
        // compare solve for solve. The stack is painted anew: its peak is theirs.
        crate::stack::paint();
        let halves = decoder.with_disparities(DisparityRange::DEFAULT.with_halves(true));
        let mut steps = [0u32; 2];
        for (i, d) in [Disparity::pixels(1), Disparity::halves(1)].into_iter().enumerate() {
            for tile in decoder.tiles((1, 1)) {
                for (view_row, view_col) in decoder.windows() {
                    let origin = PatchOrigin {
                        lenslet_row: tile.lenslet_row,
                        lenslet_col: tile.lenslet_col,
                        view_row,
                        view_col,
                        disparity: d,
                    };
                    bench_begin(6 + i as u32);
                    let r = halves
                        .read_patch(origin, &mut FrameSource::new(&frames), ws)
                        .map_err(|_| ())
                        .and_then(|_| dct.decode(&decoder.config().sl0, ws).map_err(|_| ()));
                    bench_end(6 + i as u32);
                    match r {
                        Ok(o) => steps[i] += o.outcome.iterations,
                        Err(()) => failed += 1,
                    }
                }
            }
        }
        hprintln!("sheared dct steps whole {} half {}", steps[0], steps[1]);
        // The real sensor's frame by the ensemble, through the same `Picked` as the frame
        // above (one copy of the overlapped decode's code in flash).
        let ensemble = Picked { first: picked.first, second: picked.second, pick: Pick::Second };
        failed += calibrated(&config, &model, &ensemble, strip, ws);
        hprintln!("sheared stack peak bytes {}", crate::stack::peak());
        hprintln!("strip bytes {}", core::mem::size_of::<[f32; STRIP_LEN]>());
        hprintln!("disjoint stack peak bytes {}", disjoint_stack);
        hprintln!("workspace bytes {}", core::mem::size_of::<FullViewWorkspace>());
        hprintln!("stack peak bytes {}", stack);
        #[cfg(feature = "defmt")]
        defmt::println!(
            "done patches={=u32} failed={=u32} checksum={=u32:#010x} dct-checksum={=u32:#010x} rows-checksum={=u32:#010x} stack={=usize}",
            out.patches,
            failed,
            out.checksum,
            quiet.checksum,
            rows.checksum,
            stack
        );
        hprintln!(
            "done patches={} failed={} checksum={:#010x} dct-checksum={:#010x} rows={} rows-checksum={:#010x}",
            out.patches,
            failed,
            out.checksum,
            quiet.checksum,
            rows.rows,
            rows.checksum
        );
        if failed == 0 { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE }
    }
}

/// Peak stack by painting: the only `unsafe` in the crate, in the binary and not the
/// decoder library, because measuring the stack means writing and reading memory no Rust
/// object owns. It runs once at start and once at the end; nothing else touches it.
#[cfg(target_os = "none")]
mod stack {
    const PAINT: u32 = 0xDEAD_BEEF;
    unsafe extern "C" {
        /// cortex-m-rt: the top of the stack (initial SP).
        static _stack_start: u32;
        /// cortex-m-rt: the stack's floor (`memory.x`: the bottom of the DTCM, which holds
        /// the stack alone).
        static _stack_end: u32;
    }

    fn bounds() -> (usize, usize) {
        // Only the addresses of the linker symbols are taken, never their values.
        (core::ptr::addr_of!(_stack_end) as usize, core::ptr::addr_of!(_stack_start) as usize)
    }

    /// Paints from the stack's floor up to 256 bytes below the current stack pointer.
    pub fn paint() {
        let (floor, _) = bounds();
        let sp = cortex_m::register::msp::read() as usize;
        let mut p = floor;
        while p + 4 <= sp.saturating_sub(256) {
            // SAFETY: [floor, sp - 256) is RAM below the live stack and above every static;
            // nothing owns it yet. Word-aligned: cortex-m-rt asserts _stack_end % 4 == 0.
            unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
            p += 4;
        }
    }

    /// Bytes of stack ever used: from the top down to the lowest word not still painted.
    pub fn peak() -> usize {
        let (floor, top) = bounds();
        let mut p = floor;
        // SAFETY: reads of the painted region, which nothing but the stack has written.
        while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
            p += 4;
        }
        top - p
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!("slf-device runs on a Cortex-M core: build with --target thumbv7em-none-eabihf");
    // Keep the markers referenced on the host too.
    let _ = (bench_begin(0), bench_end(0));
}
