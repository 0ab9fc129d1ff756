#!/usr/bin/env bash
# Vignetting's share of the calibrated decode's loss is noise, not calibration (the claim of
# docs/design.md, "The real sensor"): the office scene at pixel k = 1, a sensor with
# vignetting to 50 % and no leakage (3 DN dark spread, 1 % PRNU, 0.1 % hot pixels), decoded
# with its calibration, against the ideal sensor's decode; once with noise (the captures as
# simulated) and once noise-free (`--no-noise` on the scene's and the calibration captures).
# Prints a markdown table of PSNR / SSIM / SA; the design doc's figures are its.
#
#   bash scripts/vignetting-noise.sh OUT_DIR
set -euo pipefail
out=${1:?usage: vignetting-noise.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-64}
mkdir -p "$out"
scene_light_field office
echo "| captures | decode | PSNR | SSIM | SA deg |"
echo "| --- | --- | --- | --- | --- |"
for noise in "with noise:" "noise-free:--no-noise"; do
  label=${noise%%:*}; flag=${noise#*:}
  ideal="$out/vn-ideal-$label" real="$out/vn-real-$label" cal="$out/vn-cal-$label" cc="$out/vn-cc-$label"
  rm -rf "$ideal" "$real" "$cal" "$cc"
  # shellcheck disable=SC2086
  "$slf" simulate "$lf" -o "$ideal" -s 1 --seed 3 $flag > /dev/null 2>&1
  # shellcheck disable=SC2086
  "$slf" simulate "$lf" -o "$real" -s 1 --seed 3 $flag --vignetting 0.5 --dark-sd 3 --prnu 0.01 --hot-pixels 0.001 \
    --calibration-captures "$cc" --exposures 8 > /dev/null 2>&1
  "$slf" calibrate "$cc" -o "$cal" > /dev/null 2>&1
  decode_eval "$ideal"
  printf '| %s | ideal sensor | %.2f | %.4f | %.2f |\n' "$label" "$p" "$q" "$a"
  pi=$p ai=$a
  decode_eval "$real" --calibration "$cal"
  printf '| %s | vignetting 50 %%, calibrated | %.2f | %.4f | %.2f |\n' "$label" "$p" "$q" "$a"
  python3 -c "import sys; p, pi, a, ai = map(float, sys.argv[1:5]); print(f'| {sys.argv[5]} | difference | {p - pi:+.2f} dB | | {100 * (a - ai) / ai:+.1f} % |')" "$p" "$pi" "$a" "$ai" "$label"
done
