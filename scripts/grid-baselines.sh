#!/usr/bin/env bash
# Issue 66, item 3, baselines behind a turned array (docs/results-grid-baselines.md): for
# each scene at pixel k = 1 and 3 and each baseline (demosaic, PPID), its decode of the
# aligned sensor's capture, and of the capture behind grids of 0.3 degrees / 5.04 px and
# 1 degree / 5.1 px read as if aligned (`--grid aligned`, before: the baselines' only way)
# and through the grid (each view cell the pixel under its centre). The default CS decode
# through the grid beside them. Sensors as scripts/grid-shear.sh makes them (30 %
# vignetting, 1 % PRNU, shot and read noise, each calibrated from its own captures, seed
# 1); PSNR without the 2 edge lenslets / SSIM / SA.
#
#   bash scripts/grid-baselines.sh OUT > docs/results-grid-baselines.md
#
# SLF_SCENES (default outdoor tungsten office led, 64 x 64 lenslets, and the HCI crops in
# SLF_REAL when present), SLF_KS (1 3), SLF_GRIDS (0.3:5.04 1:5.1).
set -euo pipefail
out=${1:?usage: grid-baselines.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
grid_table_setup

# calibrate NAME GRID_FLAGS...: the calibration of this scene's sensor into $out/NAME.
calibrate() {
  local name=$1
  shift
  grid_calibration "$slf" "$out/$name" "$@" > /dev/null
}

# measure CAL CAPTURE FLAGS...: PSNR (interior) / SSIM / SA of the decode.
measure() {
  local cal=$1 cap=$2
  shift 2
  "$slf" decode "$cap" -o "$out/rec.npy" --quiet --calibration "$cal" "$@" > /dev/null
  grid_scores
  echo "$psnr / $q / $a"
}

page_head "Baselines behind a turned lenslet array" "bash scripts/grid-baselines.sh OUT_DIR"
echo "Each cell: PSNR dB without the 2 edge lenslets / SSIM / SA degrees. *As aligned*: the"
echo "frame behind the grid read as an aligned array (\`--grid aligned\`, before the baselines"
echo "read grids); *through the grid*: each view cell the sensor pixel under its centre, with"
echo "that pixel's filters. *Gap*: through the grid against the same method on the aligned"
echo "sensor. The default CS decode through the grid for comparison."
echo
echo "| scene | k | grid (deg:px) | method | aligned sensor | as aligned | through the grid | gap dB | CS through the grid |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for token in $scenes; do
  scene_light_field "$token"
  calibrate "cal-$scene-aligned"
  for g in $grids; do
    calibrate "cal-$scene-$g" --rotation "${g%:*}" --pitch "${g#*:}"
  done
  for k in $ks; do
    ref="$out/cap-$scene-$k-aligned"
    [ -d "$ref" ] || "$slf" simulate "$lf" -o "$ref" -s "$k" --seed 1 "${sensor[@]}" > /dev/null 2>&1
    for g in $grids; do
      cap="$out/cap-$scene-$k-$g"
      [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 "${sensor[@]}" \
        --rotation "${g%:*}" --pitch "${g#*:}" > /dev/null 2>&1
      cs=$(measure "$out/cal-$scene-$g" "$cap")
      for method in demosaic ppid; do
        self=$(measure "$out/cal-$scene-aligned" "$ref" --method "$method")
        as=$(measure "$out/cal-$scene-$g" "$cap" --method "$method" --grid aligned)
        through=$(measure "$out/cal-$scene-$g" "$cap" --method "$method")
        gap=$(python3 -c "print(f'{${through%% *} - ${self%% *}:+.2f}')")
        echo "| $scene | $k | $g | $method | $self | $as | $through | $gap | $cs |"
      done
    done
  done
done
