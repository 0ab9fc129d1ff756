#!/usr/bin/env bash
# Issue 66, item 4, pixels outside a turned array (docs/results-grid-outside.md): for each
# scene behind grids of 0.3 degrees / 5.04 px and 1 degree / 5.1 px, each binary (BEFORE,
# SLF_BEFORE, and this one) calibrates the sensor from its own calibration captures (the
# same captures: `simulate` is the same code) and decodes the scene's capture at pixel
# k = 1 and 3 with its calibration. A row: the pixels each calibration lists as hot or dead
# (and this one's outside the array), the lenslets past the sensor, and each decode's PSNR
# without the 2 edge lenslets / SSIM / SA. Sensors as scripts/grid-shear.sh makes them
# (30 % vignetting, 1 % PRNU, shot and read noise, no defect, seed 1).
#
#   SLF_BEFORE=<binary of the commit before> bash scripts/grid-outside.sh OUT > docs/results-grid-outside.md
#
# SLF_SCENES (default outdoor tungsten office led, 64 x 64 lenslets, and the HCI crops in
# SLF_REAL when present), SLF_KS (1 3), SLF_GRIDS (0.3:5.04 1:5.1).
set -euo pipefail
out=${1:?usage: grid-outside.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
grid_table_setup

# calibrate BIN NAME GRID_FLAGS...: BIN's calibration of this scene's sensor into $out/NAME,
# made again; prints its hot-pixel line.
calibrate() {
  local bin=$1 name=$2
  shift 2
  rm -rf "${out:?}/$name"
  grid_calibration "$bin" "$out/$name" "$@" | grep 'hot, dead or defective'
}

# measure BIN CAL CAPTURE: PSNR (interior) / SSIM / SA of BIN's default decode with CAL.
measure() {
  "$1" decode "$3" -o "$out/rec.npy" --quiet --calibration "$2" > "$out/summary.txt"
  grid_scores
  echo "$psnr / $q / $a"
}

page_head "Pixels outside a turned lenslet array" "SLF_BEFORE=<binary of the commit before> bash scripts/grid-outside.sh OUT_DIR"
echo "Before: \`$before\`. A turned array leaves pixels at the sensor's edges that no lenslet"
echo "lights. Before, \`slf calibrate\` listed them as hot or dead, and the decode's grey world"
echo "counted the partly lit ones among them; after, they are \`outside_pixels\`, and no part of"
echo "the decode. Each decode: PSNR dB without the 2 edge lenslets / SSIM / SA degrees, with its"
echo "own binary's calibration. The lenslets past the sensor are marked by \`--coverage-map\`"
echo "and left out of the estimated PSNR."
echo
echo "| scene | grid (deg:px) | before: hot or dead | after: hot or dead / outside the array | lenslets past the sensor | k | before | after | after - before dB |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for token in $scenes; do
  scene_light_field "$token"
  for g in $grids; do
    flags=(--rotation "${g%:*}" --pitch "${g#*:}")
    old=$(calibrate "$before" cal-before "${flags[@]}" | awk '{ print $1 }')
    line=$(calibrate "$slf" cal-after "${flags[@]}")
    new=$(echo "$line" | awk '{ print $1 }')
    outside=$(echo "$line" | sed -n 's/.*(\([0-9]*\) more outside the lenslet array.*/\1/p')
    for k in $ks; do
      cap="$out/cap-$scene-$k-$g"
      [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 "${sensor[@]}" "${flags[@]}" > /dev/null 2>&1
      b=$(measure "$before" "$out/cal-before" "$cap")
      a=$(measure "$slf" "$out/cal-after" "$cap")
      past=$(sed -n 's/.*; \([0-9]*\) lenslets reach past the sensor.*/\1/p' "$out/summary.txt")
      d=$(python3 -c "print(f'{${a%% *} - ${b%% *}:+.3f}')")
      echo "| $scene | $g | $old | $new / ${outside:-0} | ${past:-0} | $k | $b | $a | $d |"
    done
  done
done
