#!/usr/bin/env bash
# The table of docs/results-grid.md's "What a turned grid's pixels cannot tell": office at
# 64 x 64 lenslets, pixel k = 3, noiseless, decoded on disjoint unsheared patches, on an
# aligned sensor, behind a grid turned 0.3 degrees at 5.04 px, and behind an unturned grid
# offset half a pixel in rows (every pixel the mean of two view rows): the loss an exact model
# cannot win back, as the measurements lost it.
#
#   bash scripts/grid-blur.sh OUT_DIR
set -euo pipefail
out=${1:?usage: grid-blur.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
lf="$out/office.npy"
[ -f "$lf" ] || "$slf" scene office --size 64 -o "$lf" > /dev/null
stamp "bash scripts/grid-blur.sh OUT_DIR"
echo
echo "| sensor | PSNR dB |"
echo "| --- | --- |"
row() {
  local name=$1 cap="$out/cap-$2"; shift 2
  [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask pixel -s 3 --read-noise 0 --full-well 1e12 "$@" > /dev/null 2>&1
  "$slf" decode "$cap" -o "$out/rec.npy" --quiet --disparities 0:0 --stride 5 > /dev/null
  echo "| $name | $("$slf" eval "$lf" "$out/rec.npy" | awk '/^PSNR/ { printf "%.2f", $2 }') |"
}
row "aligned" aligned
row "turned 0.3 degrees at 5.04 px (the pixels' places vary over the sensor)" turned --rotation 0.3 --pitch 5.04
row "unturned 5.00 px, offset half a pixel in rows (\`--pitch 5.0 --grid-offset 2.0,2.5\`: every pixel the mean of two view rows, the model exact)" offset --pitch 5.0 --grid-offset 2.0,2.5
