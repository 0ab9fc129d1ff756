#!/usr/bin/env bash
# The realistic evaluation of docs/results-real.md: public light fields imported with
# `slf import`, then every baseline, the DCT and the shipped ensemble (`slf evaluate`).
#
#   git clone --depth 1 https://github.com/chshin10/epinet /tmp/epinet
#   bash scripts/real-eval.sh /tmp/epinet/hci_dataset target/real-eval
#
# The HCI 4D light-field benchmark views in that repository are CC BY-NC-SA 4.0: they and
# anything made from them (the imported light fields, the previews) stay out of the
# repository; only the table of numbers is committed.
#
# Scenes: additional/antinous (all 81 views and its disparity map), training/dino and
# training/cotton (33 of 81 views in the repository: the central 5 x 5 window misses 8,
# which are made from their nearest present view moved by a plane-sweep disparity; on
# antinous, where the real views exist, views made so match them at 52.5-54.0 dB).
# Each is the central 256 x 256 pixels, 5 x 5 views, lifted to 13 bands (Mallett & Yuksel
# 2019, D65).
set -euo pipefail
hci=${1:?usage: real-eval.sh HCI_DATASET_DIR OUT_DIR}
out=${2:?usage: real-eval.sh HCI_DATASET_DIR OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host
slf=./target/release/slf
mkdir -p "$out"
for scene in additional/antinous training/dino training/cotton; do
  name=$(basename "$scene")
  "$slf" import views "$hci/$scene" -o "$out/$name.npy" --crop 128,128,256,256 --fill warp 2>&1 | grep -v '^note: .*view ('
done
"$slf" evaluate "$out/antinous.npy" "$out/dino.npy" "$out/cotton.npy" -o "$out"
# The page's stamp, for docs/results-real.md above the table slf evaluate wrote.
stamp "bash scripts/real-eval.sh HCI_DATASET_DIR OUT_DIR" | tee "$out/stamp.md"
