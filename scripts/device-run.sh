#!/usr/bin/env bash
# Runs the device binary on qemu's emulated Cortex-M7 (mps2-an500) and checks its decoded patches
# against the host's decode of the same tiles (fails above 1e-5 relative difference).
# Needs: rustup target add thumbv7em-none-eabihf; apt-get install qemu-system-arm.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p target
cargo build --release -p slf-host -q
# The runner in .cargo/config.toml wraps qemu in `timeout`; semihosting exit 0 = success.
cargo run --profile device -q -p slf-device --target thumbv7em-none-eabihf > target/device.log
grep -v '^data' target/device.log
./target/release/slf device-check target/device.log --capture firmware/device/capture
