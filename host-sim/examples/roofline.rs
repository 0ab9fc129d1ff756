//! The roofline's kernels on one host core (issue 62): how many multiply-adds a second each
//! kernel of a solve step runs, beside what the core can issue.
//!
//! Each kernel runs on the full-view patch (5 x 5 x 5 x 5 x 13, N = 8,125) from random
//! coefficients, with the 5D DCT (whose mode products fold mirrored rows: about half the
//! multiplies, counted here at the unfolded figure, the arithmetic a separable transform
//! needs) and with a member of the shipped ensemble (no fold). Per kernel: nanoseconds a
//! call (median of 9 rounds of at least 20 ms each), the multiply-adds it stands for, the
//! achieved rate and that rate in multiply-adds a cycle.
//!
//! - **synthesis**, **analysis**: `N (5 + 5 + 5 + 5 + 13)` multiply-adds
//!   ([`PatchShape::TRANSFORM_MACS`]);
//! - **projection** (one-hot, pixel mask at one snapshot: 625 measurements, one a pixel):
//!   [`projection_macs`], the pixel modes' synthesis and analysis and `2 B` a measurement;
//! - **ascent**: one weight `exp(-s^2 / 2 sigma^2)` a coefficient (27 flops: no
//!   multiply-add count; nanoseconds a coefficient).
//!
//! The clock is measured, not read: a chain of dependent 64-bit integer `xor` and multiply
//! (4 cycles a link on every x86 core since 2011: Agner Fog's instruction tables), timed. The
//! peak is the core's: two 8-lane FMA (or one multiply and one add) pipes a cycle with AVX2,
//! 16 multiply-adds a cycle; slf's host build is x86-64-v3 (AVX2, FMA), and Rust never fuses
//! a multiply and an add on its own, so a multiply-add is two instructions on two pipes.
//!
//!     cargo run --release -p slf-host --example roofline
//!
//! Prints `key value` lines for `scripts/roofline.sh` and nothing else.

use slf_firmware::Shape;
use std::hint::black_box;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use slf_firmware::ascent::ascend;
use slf_firmware::ball::Ball;
use slf_firmware::projection::{project_coefficients, projection_macs};
use slf_firmware::transform::{analyze, synthesize};
use slf_firmware::{DEFAULT_FULL_VIEW_ENSEMBLE, Dictionary, Ensemble, FullViewShape, Measurements};

const N: usize = FullViewShape::N;
type Full = Dictionary<FullViewShape>;

/// Peak multiply-adds a cycle of one AVX2 core: 2 pipes x 8 lanes.
const PEAK_MACS_PER_CYCLE: f64 = 16.0;

/// Median nanoseconds of one call of `f`, over 9 rounds of at least 20 ms.
fn time(mut f: impl FnMut()) -> f64 {
    let mut reps = 1usize;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        if t.elapsed().as_secs_f64() >= 0.02 {
            break;
        }
        reps *= 2;
    }
    let mut rounds: Vec<f64> = (0..9)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                f();
            }
            t.elapsed().as_secs_f64() * 1e9 / reps as f64
        })
        .collect();
    rounds.sort_by(f64::total_cmp);
    rounds[4]
}

/// The core's clock in GHz: a chain of dependent `xor` and `imul r64` (1 and 3 cycles of
/// latency on every x86 core since 2011: Agner Fog's instruction tables); the `xor` keeps
/// the compiler from folding the multiplies into one.
fn clock_ghz() -> f64 {
    const CHAIN: u64 = 8_000_000;
    let ns = time(|| {
        let mut x = black_box(3u64);
        let (m, s) = (black_box(0x9E37_79B9_7F4A_7C15u64), black_box(0x5851_F42Du64));
        for _ in 0..CHAIN / 8 {
            // Eight a turn, so the loop's own counter runs beside the chain.
            for _ in 0..8 {
                x = (x ^ s).wrapping_mul(m);
            }
        }
        black_box(x);
    });
    4.0 * CHAIN as f64 / ns
}

fn random_patch(rng: &mut ChaCha8Rng) -> Box<[f32; N]> {
    let v: Vec<f32> = (0..N).map(|_| rng.random_range(-1.0f32..1.0)).collect();
    v.into_boxed_slice().try_into().unwrap_or_else(|_| unreachable!("N values"))
}

fn main() -> anyhow::Result<()> {
    let ghz = clock_ghz();
    println!("clock_ghz {ghz:.3}");
    println!("peak_macs_per_cycle {PEAK_MACS_PER_CYCLE}");
    println!("peak_gmacs {:.2}", ghz * PEAK_MACS_PER_CYCLE);
    let mut rng = ChaCha8Rng::seed_from_u64(62);
    let ensemble = Ensemble::<FullViewShape>::new(DEFAULT_FULL_VIEW_ENSEMBLE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let member = ensemble.member(0).map_err(|e| anyhow::anyhow!("{e}"))?;
    // Pixel k = 1: one band a pixel, the band of a 3 x 3 periodic mask.
    let mut m = Box::new(Measurements::<slf_firmware::shape::ValueCount<N>>::new());
    for p in 0..N / 13 {
        let b = (p * 7 + p / 25) % 13;
        m.set(p * 13 + b, rng.random_range(0.0f32..1.0)).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    }
    let ball = Ball::new(0.0, 0.0, m.count() as u32, 0);
    let transform = FullViewShape::TRANSFORM_MACS as f64;
    let projection = projection_macs::<FullViewShape>(m.count()) as f64;
    println!("transform_macs {transform}");
    println!("projection_macs {projection}");
    println!("measurements {}", m.count());
    for (name, dict) in [("dct", Full::dct()), ("ensemble", member)] {
        let (mut a, mut b) = (random_patch(&mut rng), random_patch(&mut rng));
        let start = random_patch(&mut rng);
        let report = |kernel: &str, ns: f64, macs: f64| {
            let gmacs = macs / ns;
            println!(
                "{kernel}_{name} ns {ns:.0} macs {macs} gmacs {gmacs:.2} macs_per_cycle {:.2} of_peak {:.3}",
                gmacs / ghz,
                gmacs / ghz / PEAK_MACS_PER_CYCLE
            );
        };
        let ns = time(|| {
            a.copy_from_slice(&start[..]);
            synthesize(&dict, black_box(&mut a), &mut b);
        });
        report("synthesis", ns, transform);
        let ns = time(|| {
            a.copy_from_slice(&start[..]);
            analyze(&dict, black_box(&mut a), &mut b);
        });
        report("analysis", ns, transform);
        let ns = time(|| {
            a.copy_from_slice(&start[..]);
            black_box(project_coefficients(&dict, black_box(&mut a), &mut b, &m, &ball, None));
        });
        report("projection", ns, projection);
    }
    // The copy each kernel's call starts with, to take off: N loads and stores.
    let (mut a, start) = (random_patch(&mut rng), random_patch(&mut rng));
    let copy = time(|| a.copy_from_slice(black_box(&start[..])));
    println!("copy ns {copy:.0}");
    let ns = time(|| {
        a.copy_from_slice(&start[..]);
        black_box(ascend(black_box(&mut a[..]), 1.0, 4.0));
    });
    println!("ascent ns {ns:.0} ns_per_value {:.3}", ns / N as f64);
    Ok(())
}
