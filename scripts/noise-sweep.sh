#!/usr/bin/env bash
# The sensor's noise in the model, measured: for each light field given, from a bright
# sensor to a dark one (electrons at white / read noise in DN), pixel mask k = 1 and 3,
# decode with the exact projection, with the capture's noise model (the default) and with
# the neighbourhood demosaic; prints a markdown table of PSNR / SA and writes it to OUT.
#
#   bash scripts/noise-sweep.sh OUT.md LF.npy [LF.npy ...]
#
# Fewer electrons at white is a darker scene at the same gain: the same signal in
# normalised units with more shot noise.
set -euo pipefail
out=$1
shift
root=$(cd "$(dirname "$0")/.." && pwd)
. "$root/scripts/stamp.sh"
slf="$root/target/release/slf"
cargo build --release -q -p slf-host --manifest-path "$root/Cargo.toml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# metric RECON TRUTH
metric() { "$slf" eval "$2" "$1" | awk '/^PSNR/ { p = $2 } /^SA/ { s = $2 } END { printf "%.2f / %.2f", p, s }'; }
{
  stamp "bash scripts/noise-sweep.sh OUT_DIR ..."
  echo
  echo "| scene | electrons at white / read noise DN | k | exact | capture's noise (default) | demosaic |"
  echo "| --- | --- | --- | --- | --- | --- |"
  for lf in "$@"; do
    name=$(basename "$lf" .npy)
    for sensor in "20000 2" "5000 5" "1000 10" "200 20"; do
      read -r fw rn <<< "$sensor"
      for k in 1 3; do
        cap="$work/cap"
        rm -rf "$cap"
        "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 7 --full-well "$fw" --read-noise "$rn" > /dev/null
        "$slf" decode "$cap" -o "$work/exact.npy" --exact -q > /dev/null
        "$slf" decode "$cap" -o "$work/model.npy" -q > /dev/null
        "$slf" decode "$cap" -o "$work/demosaic.npy" --method demosaic > /dev/null
        echo "| $name | $fw / $rn | $k | $(metric "$work/exact.npy" "$lf") | $(metric "$work/model.npy" "$lf") | $(metric "$work/demosaic.npy" "$lf") |"
      done
    done
  done
} | tee "$out"
