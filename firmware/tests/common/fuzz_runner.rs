//! The fuzz targets' runner, shared by `firmware/tests/fuzz.rs` and `host-sim/tests/fuzz.rs`
//! (the host's includes this file by path): cases from `SLF_FUZZ_CASES` (default 64, what
//! `cargo test` runs), a fixed seed from `SLF_FUZZ_SEED` (default 1), no failure files.

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Cases per target, from `SLF_FUZZ_CASES`.
pub fn cases() -> u32 {
    std::env::var("SLF_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64)
}

/// A fresh runner (a runner counts its successes across `run` calls, so each generator
/// gets its own) with the fixed seed.
pub fn runner() -> TestRunner {
    let seed: u64 = std::env::var("SLF_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config { cases: cases(), failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}
