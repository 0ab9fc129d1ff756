#!/usr/bin/env bash
# The real sensor's tables (docs/results-sensor.md, issue 43): for each scene at pixel k = 1
# and 3, the ideal sensor (no leakage, no vignetting, no dark spread) and a real one with 10
# and 30 % filter leakage, each with and without vignetting to 50 % (and a 3 DN dark spread,
# 1 % PRNU, 0.1 % hot pixels); vignetting without leakage is scripts/vignetting-noise.sh's. The
# ideal sensor's decode, the real sensor's uncorrected decode, its calibrated decode
# (`slf simulate --calibration-captures`, `slf calibrate`, `slf decode --calibration`), and
# the calibrated baselines. PSNR / SSIM / SA and the decode's seconds. Nothing is kept but
# the tables: light fields, captures and calibrations go to OUT_DIR.
#
#   bash scripts/sensor-results.sh OUT_DIR > docs/results-sensor.md
#   SLF_SCENES="office" SLF_KS=1 bash scripts/sensor-results.sh OUT_DIR   # smaller, faster
#
# Times are of one run on a shared machine: compare them within a table.
set -euo pipefail
out=${1:?usage: sensor-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-64}
scenes=${SLF_SCENES:-outdoor tungsten office led}
ks=${SLF_KS:-1 3}
exposures=${SLF_EXPOSURES:-8}
mkdir -p "$out"
add_real_scenes

# row CAPTURE LABEL ARGS...: one table row.
row() {
  local cap=$1 label=$2; shift 2
  decode_eval "$cap" "$@"
  printf '| %s | %s | %.2f | %.4f | %.2f | %.2f |\n' "$setting" "$label" "$p" "$q" "$a" "${t:-0}"
}

page_head "A real sensor, calibrated" "bash scripts/sensor-results.sh OUT_DIR"
echo "Made by \`bash scripts/sensor-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5 views,"
echo "$exposures exposures of each calibration capture; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`)."
echo "A real sensor has the leakage and vignetting its row names, a 3 DN dark spread, 1 % PRNU and"
echo "0.1 % hot pixels (\`slf simulate --leakage L --vignetting V --dark-sd 3 --prnu 0.01"
echo "--hot-pixels 0.001\`); \`calibrated\` decodes with what \`slf calibrate\` made of its calibration"
echo "captures, the baselines too: the default decodes the spectra the filters saw and unmixes each"
echo "by the response matrix's inverse, as the baselines do; \`response in the projection\` puts"
echo "each pixel's measurements as rows of the response into every projection of the solve"
echo "(\`--response-model projection\`). The ideal sensor's rows are the reference."
for token in $scenes; do
  scene_light_field "$token"
  echo
  echo "## $scene"
  echo
  echo "| setting | decode | PSNR | SSIM | SA deg | seconds |"
  echo "| --- | --- | --- | --- | --- | --- |"
  for k in $ks; do
    setting="pixel k=$k, ideal sensor"
    cap="$out/cap-$scene-$k-ideal"
    "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 3 > /dev/null 2>&1
    row "$cap" "default"
    row "$cap" "demosaic" --method demosaic
    row "$cap" "ppid" --method ppid
    for leakage in 0.1 0.3; do
      for vignetting in 0 0.5; do
        setting="pixel k=$k, leakage $leakage, vignetting $vignetting"
        cap="$out/cap-$scene-$k-$leakage-$vignetting"
        rm -rf "$cap" "$out/cal" "$out/calibration"
        "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 3 --leakage "$leakage" --vignetting "$vignetting" \
          --dark-sd 3 --prnu 0.01 --hot-pixels 0.001 --calibration-captures "$out/cal" --exposures "$exposures" \
          > /dev/null 2>&1
        "$slf" calibrate "$out/cal" -o "$out/calibration" > /dev/null 2>&1
        row "$cap" "default, uncorrected"
        row "$cap" "default, calibrated" --calibration "$out/calibration"
        row "$cap" "default, calibrated, response in the projection" --calibration "$out/calibration" --response-model projection
        row "$cap" "demosaic, calibrated" --method demosaic --calibration "$out/calibration"
        row "$cap" "ppid, calibrated" --method ppid --calibration "$out/calibration"
      done
    done
  done
done
