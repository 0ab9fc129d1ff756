#!/usr/bin/env bash
# The tables of docs/results-ensemble.md (issue 18): the DCT and the ensembles against the
# baselines without compressed sensing, on the realistic set (three real light fields and
# slf's four realistic named scenes) and on slf's five synthetic test scenes, at pixel
# k = 1, pixel k = 3 and lenslet k = 3 (disjoint patches, the capture's noise model).
#
#   bash scripts/results-ensemble.sh OUT_DIR OLD.slfd REAL.slfd > tables.md
#
# OLD.slfd: the previously shipped ensemble (`git show 1251224:firmware/dictionaries/ensemble8.slfd`);
# REAL.slfd: an ensemble trained on real light fields (`slf train --input ...`; the HCI
# data's licence allows evaluation only, so it is never shipped). The real light fields are
# scripts/real-eval.sh's 128 x 128 crops, in $SLF_REAL (default /tmp/hci/real).
set -euo pipefail
out=${1:?usage: results-ensemble.sh OUT_DIR OLD.slfd REAL.slfd}
old=${2:?old blob}
real=${3:?real-trained blob}
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host
slf=./target/release/slf
hci=${SLF_REAL:-/tmp/hci/real}
mkdir -p "$out/lf"
for n in outdoor tungsten office led; do
  [ -f "$out/lf/$n.npy" ] || "$slf" scene "$n" --size 64 -o "$out/lf/$n.npy" > /dev/null
done
for n in smooth texture depth saturated dark; do
  [ -f "$out/lf/$n.npy" ] || "$slf" scene "$n" --size 40 -o "$out/lf/$n.npy" > /dev/null
done
models="demosaic=demosaic ppid=ppid interpolate=interpolate dct-plain=dct:off dct=dct old-plain=$old:off old=$old new=firmware/dictionaries/ensemble8.slfd real-trained=$real"
stamp "bash scripts/results-ensemble.sh OUT_DIR ..."
echo
echo "## Realistic set"
echo
bash scripts/validate-ensemble.sh "$out/real" "$models" "$hci/antinous_128.npy" "$hci/dino_128.npy" \
  "$hci/cotton_128.npy" "$out/lf/outdoor.npy" "$out/lf/tungsten.npy" "$out/lf/office.npy" "$out/lf/led.npy"
echo
echo "## Synthetic test scenes"
echo
bash scripts/validate-ensemble.sh "$out/syn" "$models" "$out/lf/smooth.npy" "$out/lf/texture.npy" \
  "$out/lf/depth.npy" "$out/lf/saturated.npy" "$out/lf/dark.npy"
