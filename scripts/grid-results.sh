#!/usr/bin/env bash
# A real lenslet array (issue 52), docs/results-grid.md's decode tables: for each scene at
# pixel k = 1 and 3 and each grid (rotation 0, 0.1, 0.3, 1 degree x pitch 5.00, 5.02, 5.1 px),
# the capture decoded (a) as if its array were aligned (`--grid aligned`, slf before grids),
# (b) through the grid it was simulated with (`--grid capture`), (c) through the grid `slf
# calibrate` found from its flats (the default), against (ref) the aligned sensor's default
# decode. Every sensor has 30 % vignetting (which the grid is found from) and 1 % PRNU, with
# shot and read noise, and every decode is calibrated (2 exposures of each calibration
# capture). PSNR / SSIM / SA and the decode's seconds. Nothing is kept but the tables.
#
#   bash scripts/grid-results.sh OUT_DIR > docs/results-grid.md
#   SLF_SCENES="office" SLF_KS=1 SLF_GRIDS="0.3:5.02" bash scripts/grid-results.sh OUT_DIR   # faster
#
# Times are of one run on a shared machine: compare them within a table.
set -euo pipefail
out=${1:?usage: grid-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-64}
scenes=${SLF_SCENES:-outdoor tungsten office led}
ks=${SLF_KS:-1 3}
grids=${SLF_GRIDS:-0:5.02 0:5.1 0.1:5.0 0.1:5.02 0.1:5.1 0.3:5.0 0.3:5.02 0.3:5.1 1:5.0 1:5.02 1:5.1}
sensor=(--vignetting 0.3 --prnu 0.01)
mkdir -p "$out"
add_real_scenes

# calibration_for LABEL FLAGS...: sets $cal, the calibration of the sensor FLAGS describe for
# $lf's size (made once per size and grid, from k = 1 captures: a flat does not see the mask).
calibration_for() {
  local label=$1; shift
  local n
  n=$(python3 -c "import numpy as np, sys; print(np.load(sys.argv[1], mmap_mode='r').shape[2])" "$lf")
  cal="$out/cal-$n-$label"
  grid_calibration "$slf" "$cal" "$@" > /dev/null
}

cell() { printf ' %.2f / %.4f / %.2f |' "$p" "$q" "$a"; }

# interior_psnr: the PSNR of the last decode without the 2 lenslets at each edge of the frame
# (`slf eval --border 2`): a turned array's corner lenslets reach past the sensor.
interior_psnr() { "$slf" eval "$lf" "$out/rec.npy" --border 2 | awk '/^PSNR/ { print $2 }'; }

page_head "A real lenslet array" "bash scripts/grid-results.sh OUT_DIR"
echo "Made by \`bash scripts/grid-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets and the HCI"
echo "crops present, 5 x 5 views; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). Each cell is PSNR / SSIM /"
echo "SA (degrees). (a) reads the capture as if its array were aligned (\`--grid aligned\`), (b)"
echo "through the grid it was simulated with (\`--grid capture\`), (c) through the grid \`slf calibrate\`"
echo "found (the default); ref is the aligned sensor's default decode. All calibrated; 30 % vignetting,"
echo "1 % PRNU, shot and read noise. \"Interior\" scores both without the 2 lenslets at each edge"
echo "of the frame (\`slf eval --border 2\`): a turned array's corners reach past the sensor. Seconds"
echo "are (c)'s decode and ref's."
for token in $scenes; do
  scene_light_field "$token"
  echo
  echo "## $scene"
  echo
  echo "| k | rotation deg | pitch px | (a) aligned | (b) true grid | (c) calibrated grid | ref aligned sensor | (c) - ref dB | (c) - ref dB, interior | s (c) / ref |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
  for k in $ks; do
    calibration_for aligned
    ref="$out/cap-$scene-$k-aligned"
    rm -rf "$ref"
    "$slf" simulate "$lf" -o "$ref" -s "$k" --seed 3 "${sensor[@]}" > /dev/null 2>&1
    decode_eval "$ref" --calibration "$cal"
    rp=$p rq=$q ra=$a rt=$t
    rb=$(interior_psnr)
    for g in $grids; do
      rot=${g%:*} pitch=${g#*:}
      calibration_for "$rot-$pitch" --rotation "$rot" --pitch "$pitch"
      cap="$out/cap-$scene-$k-$rot-$pitch"
      rm -rf "$cap"
      "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 3 "${sensor[@]}" --rotation "$rot" --pitch "$pitch" > /dev/null 2>&1
      printf '| %s | %s | %s |' "$k" "$rot" "$pitch"
      decode_eval "$cap" --calibration "$cal" --grid aligned; cell
      decode_eval "$cap" --calibration "$cal" --grid capture; cell
      decode_eval "$cap" --calibration "$cal"; cell
      ct=$t cp=$p cb=$(interior_psnr)
      printf ' %.2f / %.4f / %.2f |' "$rp" "$rq" "$ra"
      python3 -c "import sys; a = [float(x) for x in sys.argv[1:]]; print(f' {a[0] - a[1]:+.2f} | {a[2] - a[3]:+.2f} | {a[4]:.2f} / {a[5]:.2f} |')" "$cp" "$rp" "$cb" "$rb" "$ct" "$rt"
      rm -rf "$cap"
    done
    rm -rf "$ref"
  done
done
