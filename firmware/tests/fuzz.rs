//! Fuzz targets of the decoder: the dictionary blob and the tile decoder, on arbitrary and
//! mutated inputs. Each must return (a value or a typed error) without panicking, and
//! what it returns must hold: a blob that validates gives members that validate, a decoded
//! patch is finite, and the counts add up.
//!
//! The harness is proptest on stable Rust: cargo-fuzz needs a nightly toolchain (libFuzzer
//! and the sanitizers), which the project's machines and its users' CI do not have, and
//! proptest runs inside `cargo test`, from a fixed seed, and shrinks a failure to a small
//! input. It is not coverage-guided; the generators are structure-aware instead (valid
//! inputs mutated, not only random bytes). Cases per target: `SLF_FUZZ_CASES` (default 64,
//! what `cargo test` runs); seed: `SLF_FUZZ_SEED`. The documented long run:
//!
//!     SLF_FUZZ_CASES=20000 cargo test --release --test fuzz -- --nocapture

use std::sync::atomic::{AtomicU32, Ordering};

use proptest::prelude::*;

#[path = "common/fuzz_runner.rs"]
mod fuzz_runner;
use fuzz_runner::{cases, runner};
use slf_firmware::prelude::*;

/// Edits applied to a valid input: flip bits, overwrite, truncate, extend.
#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Set(usize, u8),
    Truncate(usize),
    Extend(Vec<u8>),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    let edit = prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(i, b)| Edit::Flip(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        any::<usize>().prop_map(Edit::Truncate),
        prop::collection::vec(any::<u8>(), 1..64).prop_map(Edit::Extend),
    ];
    prop::collection::vec(edit, 1..6)
}

fn apply(mut bytes: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let n = bytes.len().max(1);
        match e {
            Edit::Flip(i, b) => {
                if let Some(x) = bytes.get_mut(i % n) {
                    *x ^= b;
                }
            }
            Edit::Set(i, b) => {
                if let Some(x) = bytes.get_mut(i % n) {
                    *x = *b;
                }
            }
            Edit::Truncate(i) => bytes.truncate(i % n),
            Edit::Extend(tail) => bytes.extend_from_slice(tail),
        }
    }
    bytes
}

/// Validates `blob`; if it passes, every member must load and validate.
fn check_blob(blob: &[u8]) -> Result<(), TestCaseError> {
    if let Ok(e) = PaperEnsemble::new(blob) {
        prop_assert!(!e.is_empty());
        for k in 0..e.len() {
            let m = e.member(k).map_err(|err| TestCaseError::fail(format!("member {k}: {err}")))?;
            prop_assert!(m.synthesis().validate(k as u16).is_ok());
        }
        prop_assert!(e.member(e.len()).is_err());
    }
    Ok(())
}

#[test]
fn fuzz_dictionary_blob() {
    runner().run(&prop::collection::vec(any::<u8>(), 0..2048), |bytes| check_blob(&bytes)).unwrap();
    // Mutations of the shipped blob (which a random byte string almost never resembles).
    runner().run(&edits(), |e| check_blob(&apply(DEFAULT_ENSEMBLE.to_vec(), &e))).unwrap();
    // A header's fields set to anything, with a matching checksum, reaches the checks past
    // the checksum.
    runner()
        .run(&(prop::collection::vec(any::<u8>(), 24), 0usize..3), |(header, members)| {
            let mut blob = header;
            blob.extend(std::iter::repeat_n(0u8, members * 1004));
            let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&blob);
            blob.extend_from_slice(&crc.to_le_bytes());
            check_blob(&blob)
        })
        .unwrap();
    eprintln!("fuzz dictionary blob: {} cases x 3 generators, no failure", cases());
}

/// Everything a tile decode takes, drawn at random: a sensor, a mask (seeded or tiled,
/// possibly invalid), defects (possibly unsorted or outside), a raw format and a solver
/// configuration (possibly invalid or non-finite), and frames of any values.
#[derive(Clone, Debug)]
struct DecodeCase {
    lenslets: (u16, u16),
    lenslet: (u8, u8),
    family: u8,
    snapshots: u8,
    seed: u64,
    tile: (u16, u16, Vec<u8>),
    defects: Vec<(u16, u16)>,
    raw: (f32, f32, f32),
    sl0: (f32, u16, f32, f32, u32, f32),
    frames: Vec<u16>,
    ensemble: bool,
}

fn any_float() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -2.0f32..2.0,
        1 => prop::num::f32::ANY,
        1 => Just(f32::NAN),
        1 => Just(0.0f32),
    ]
}

fn decode_cases() -> impl Strategy<Value = DecodeCase> {
    (
        (
            prop_oneof![3 => (5u16..13, 5u16..13), 1 => (0u16..20, 0u16..20)],
            prop_oneof![3 => (4u8..7, 4u8..7), 1 => (0u8..9, 0u8..9)],
            0u8..5,
            prop_oneof![3 => 1u8..4, 1 => 0u8..15],
            any::<u64>(),
        ),
        ((0u16..4, 0u16..4, prop::collection::vec(0u8..16, 0..40)), prop::collection::vec((0u16..80, 0u16..80), 0..6)),
        (
            prop_oneof![
                3 => Just((64.0f32, 3691.9f32, 4094.5f32)),
                1 => (any_float(), any_float(), any_float()),
            ],
            prop_oneof![
                3 => (0.3f32..0.95, 1u16..4, 0.5f32..3.0, 1e-4f32..1e-1, 1u32..30, prop_oneof![Just(0.0f32), 0.0f32..0.1]),
                1 => (any_float(), 0u16..5, any_float(), any_float(), 0u32..30, any_float()),
            ],
        ),
        (prop::collection::vec(any::<u16>(), 0..200), any::<bool>()),
    )
        .prop_map(|((lenslets, lenslet, family, snapshots, seed), (tile, defects), (raw, sl0), (frames, ensemble))| {
            DecodeCase { lenslets, lenslet, family, snapshots, seed, tile, defects, raw, sl0, frames, ensemble }
        })
}

/// Counts what the decoder delivers and checks each patch is finite.
#[derive(Default)]
struct Check {
    accepted: u32,
    rejected: u32,
    non_finite: u32,
}

impl PatchSink<PaperShape> for Check {
    type Error = core::convert::Infallible;
    fn accept(&mut self, _: PatchOrigin, p: &PaperPatch, _: &PatchReport) -> Result<(), Self::Error> {
        self.accepted += 1;
        self.non_finite += u32::from(!p.iter().all(|x| x.is_finite()));
        Ok(())
    }
    fn reject(&mut self, _: PatchOrigin, _: SolveError) -> Result<(), Self::Error> {
        self.rejected += 1;
        Ok(())
    }
}

/// Cases that reached a decode, and the patches they delivered.
static DECODES: AtomicU32 = AtomicU32::new(0);
static PATCHES: AtomicU32 = AtomicU32::new(0);

fn run_decode(c: &DecodeCase, ws: &mut PaperWorkspace) -> Result<(), TestCaseError> {
    let lenslet = LensletSize { rows: c.lenslet.0, cols: c.lenslet.1 };
    let tile;
    let mask = match c.family {
        0 => Mask::pixel(c.seed, c.snapshots, 13, lenslet),
        1 => Mask::lenslet(c.seed, c.snapshots, 13, lenslet),
        2 => Mask::kronecker(c.seed, c.snapshots, 13, lenslet, (5, 5)),
        f => {
            tile = BandTile::new(c.tile.0, c.tile.1, c.snapshots, 13, &c.tile.2);
            match tile {
                Ok(t) if f == 3 => Mask::pixel_tile(t, 13, lenslet),
                Ok(t) => Mask::lenslet_tile(t, 13, lenslet),
                Err(e) => Err(e),
            }
        }
    };
    let Ok(mask) = mask else { return Ok(()) };
    let pixels: Vec<Pixel> = c.defects.iter().map(|&(row, col)| Pixel { row, col }).collect();
    let defects = DefectList::new(&pixels).unwrap_or_default();
    let (sigma_f, steps, mu, sigma_min, max_iterations, noise) = c.sl0;
    let sl0 = Sl0Config { sigma_f, steps, mu, sigma_min, max_iterations, noise, ..Sl0Config::DEFAULT };
    let config = DecoderConfig {
        sensor: SensorGeometry { lenslets: c.lenslets, lenslet },
        mask,
        raw: RawFormat { black: c.raw.0, white: c.raw.1, max_valid: c.raw.2 },
        defects,
        sl0,
    };
    let Ok(decoder) = PaperDecoder::new(config) else { return Ok(()) };
    // Sheared blocks too: a disparity range of 0..=3 either way, with or without the
    // half-pixel shears, from the seed's top bits.
    let reach = ((c.seed >> 61) % 4) as i8;
    let halves = (c.seed >> 60) & 1 == 1;
    let range = DisparityRange::new(-reach, reach).unwrap_or(DisparityRange::OFF).with_halves(halves);
    let decoder = decoder.with_disparities(range);
    // Frames: the drawn values repeated over the sensor (a frame of the wrong size is
    // refused by `RawFrame::new`, also checked).
    let (rows, cols) = config.sensor.frame_size();
    let data: Vec<u16> = if c.frames.is_empty() {
        vec![0; rows * cols]
    } else {
        (0..rows * cols).map(|i| c.frames[i % c.frames.len()]).collect()
    };
    prop_assert!(RawFrame::new(&data[..data.len().saturating_sub(1)], rows, cols).is_err() || data.is_empty());
    let frames: Vec<RawFrame<'_, u16>> =
        (0..mask.snapshots()).filter_map(|_| RawFrame::new(&data, rows, cols).ok()).collect();
    prop_assert_eq!(frames.len(), mask.snapshots());
    let mut sink = Check::default();
    let report = if c.ensemble {
        let Ok(e) = PaperEnsemble::new(DEFAULT_ENSEMBLE) else { return Err(TestCaseError::fail("shipped blob")) };
        let model = PaperEnsembleModel::new(e, MemberChoice::Screened(ChoiceRule::DEFAULT));
        decoder.decode_frame(&model, (1, 2), &mut FrameSource::new(&frames), &mut sink, ws)
    } else {
        decoder.decode_frame(&PaperDictionary::dct(), (2, 1), &mut FrameSource::new(&frames), &mut sink, ws)
    };
    DECODES.fetch_add(1, Ordering::Relaxed);
    PATCHES.fetch_add(sink.accepted + sink.rejected, Ordering::Relaxed);
    prop_assert_eq!(sink.non_finite, 0, "a non-finite patch was delivered");
    prop_assert_eq!(report.patches.decoded, sink.accepted);
    prop_assert_eq!(report.patches.failed, sink.rejected);
    prop_assert_eq!(report.failed_tiles, 0);
    Ok(())
}

#[test]
fn fuzz_tile_decoder() {
    let ws = std::cell::RefCell::new(Box::new(PaperWorkspace::new()));

    runner().run(&decode_cases(), |c| run_decode(&c, &mut ws.borrow_mut())).unwrap();
    let (d, p) = (DECODES.load(Ordering::Relaxed), PATCHES.load(Ordering::Relaxed));
    eprintln!("fuzz tile decoder: {} cases ({d} reached a decode, {p} patches), no failure", cases());
    assert!(d > 0 && p > 0, "the generator must reach the decoder");
}
