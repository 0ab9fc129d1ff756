#!/usr/bin/env bash
# SHA-256 of the outputs a refactor must not change: the demo's decodes at k = 1 and 3, a
# `--method demosaic` and a `--method ppid` decode, a default CS decode, the retrained
# ensemble blob, and the device run's log (every decoded patch's checksum line).
#
#   bash scripts/output-hashes.sh [DIR] > before.txt   # ... move code ...
#   bash scripts/output-hashes.sh [DIR] > after.txt && diff before.txt after.txt
#
# Needs what scripts/device-run.sh needs (the thumbv7em target and qemu-system-arm); set
# SLF_NO_DEVICE=1 to skip the device run.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-target/output-hashes}"
rm -rf "$dir" && mkdir -p "$dir"
cargo build --release -p slf-host -q
slf=./target/release/slf

$slf demo --out "$dir/demo" > "$dir/demo.log"
$slf scene depth --size 60 -o "$dir/depth.npy" > /dev/null
$slf simulate "$dir/depth.npy" -o "$dir/capture" --seed 1 > /dev/null
$slf decode "$dir/capture" --method demosaic -o "$dir/demosaic.npy" > /dev/null
$slf decode "$dir/capture" --method ppid -o "$dir/ppid.npy" > /dev/null
$slf decode "$dir/capture" -q -o "$dir/cs.npy" > /dev/null
$slf train -o "$dir/ensemble8.slfd" > /dev/null
if [ -z "${SLF_NO_DEVICE:-}" ]; then
  bash scripts/device-run.sh > /dev/null
  cp target/device.log "$dir/device.log"
fi

cd "$dir"
sha256sum demo/recon_k1.npy demo/recon_k3.npy demo/preview_k1.png demo/preview_k3.png \
  demosaic.npy ppid.npy cs.npy ensemble8.slfd $( [ -f device.log ] && echo device.log )
