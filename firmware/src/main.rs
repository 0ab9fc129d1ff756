//! `slf-device`: the decoder on a Cortex-M core.
//!
//! Today it decodes one synthetic patch (measured through a seeded `pixel` mask) with the
//! 5D DCT and reports over semihosting the steps taken and a checksum of the decoded
//! patch, then exits through semihosting (qemu's exit code: 0 on success). Run it with
//! `cargo run --release -p slf-firmware --target thumbv7em-none-eabihf` (see the README);
//! the device issue grows it into a tile decoder of a capture held in flash.
//! On the host this file builds to a stub that says so.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod device {
    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};
    use panic_semihosting as _;
    use slf_firmware::{Dictionary, LensletSize, Mask, PaperShape, PaperWorkspace, Sl0Config, solve};

    /// The 5D DCT: a compile-time table in flash.
    static DCT: Dictionary<5, 5, 4, 4, 13> = Dictionary::dct();

    /// A smooth test patch value at `(s, t, u, v, b)`, no trigonometry.
    fn truth(i: usize) -> f32 {
        let [s, t, u, v, b] = PaperShape::coordinates(i);
        0.3 + 0.04 * s as f32 + 0.03 * t as f32 + 0.01 * (u + v) as f32 + 0.02 * b as f32
    }

    #[entry]
    fn main() -> ! {
        let code = run();
        debug::exit(code);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    fn run() -> debug::ExitStatus {
        let Some(ws) = cortex_m::singleton!(: PaperWorkspace = PaperWorkspace::new()) else {
            return debug::EXIT_FAILURE;
        };
        let Ok(mask) = Mask::pixel(1, 1, 13, LensletSize { rows: 5, cols: 5 }) else {
            return debug::EXIT_FAILURE;
        };
        for p in 0..PaperShape::PIXELS {
            let [s, t, u, v, _] = PaperShape::coordinates(p * 13);
            for &band in mask.bands_at(s * 5 + u, t * 5 + v).iter() {
                let i = p * 13 + band as usize;
                if ws.measurements_mut().set(i, truth(i)).is_err() {
                    return debug::EXIT_FAILURE;
                }
            }
        }
        match solve(&DCT, &Sl0Config::DEFAULT, ws) {
            Ok(outcome) => {
                let sum = ws.patch().iter().fold(0u32, |h, x| h.rotate_left(5) ^ x.to_bits());
                let worst = (0..5200).map(|i| (ws.patch()[i] - truth(i)).abs()).fold(0.0f32, f32::max);
                hprintln!("steps {} checksum {:#010x} max-error-e6 {}", outcome.iterations, sum, (worst * 1e6) as u32);
                debug::EXIT_SUCCESS
            }
            Err(_) => debug::EXIT_FAILURE,
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!("slf-device runs on a Cortex-M core: build with --target thumbv7em-none-eabihf");
}
