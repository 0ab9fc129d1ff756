#!/usr/bin/env bash
# The shear check's and the shear trial's table (docs/results-shear-check.md, issue 49):
# every test, realistic and hard-case scene at pixel k = 1 (half-pixel disparities are
# searched for one snapshot only), decoded by the default preset three ways: without either
# (`--shear-trial false`, the default before the trial), with the shear trial (the default:
# whole disparities only for the frame where its pilots' held-out error estimates at the
# whole disparities are below 0.7 x the half ones'), and with the shear check instead
# (`--shear-trial false --shear-check`: each half-pixel block at the neighbouring whole
# disparity whose estimate is below 0.7 x the half one's). PSNR, SA, the blocks at half
# disparities, the decode's seconds.
#
#   bash scripts/shear-check-results.sh OUT_DIR > docs/results-shear-check.md
set -euo pipefail
out=${1:?usage: shear-check-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
page_head "The shear check and the shear trial" "bash scripts/shear-check-results.sh OUT_DIR"
echo "Made by \`bash scripts/shear-check-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, the real"
echo "crops at their own size, 5 x 5 views, pixel mask, k = 1, \`slf simulate --seed 1\`, the default preset;"
echo "\`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). \"none\": \`--shear-trial false\`; \"trial\": the default;"
echo "\"check\": \`--shear-trial false --shear-check\`. Half blocks: the blocks decoded at a half-pixel"
echo "disparity. Trial: what the shear trial's pilots estimated (RMS at the half disparities, at the"
echo "better whole ones) and whether it kept the half ones."
add_real_scenes
echo
echo "| scene | PSNR none / trial / check | SA deg none / trial / check | half blocks none / trial / check | seconds none / trial / check | trial |"
echo "| --- | --- | --- | --- | --- | --- |"
halves() { echo "$1" | sed -n 's/^disparity: blocks per disparity \([^;]*\);.*/\1/p' | tr ',' '\n' | awk -F': ' '$1 ~ /\.5/ { n += $2 } END { print n + 0 }'; }
for token in $scenes; do
  scene_light_field "$token"
  scene_capture pixel:1 1
  row=()
  trial=""
  for extra in "--shear-trial false" "" "--shear-trial false --shear-check"; do
    # shellcheck disable=SC2086
    log=$("$slf" decode "$cap" -o "$out/rec.npy" --quiet $extra)
    ev=$("$slf" eval "$lf" "$out/rec.npy")
    row+=("$(echo "$ev" | awk '/^PSNR/ { print $2 }')" "$(echo "$ev" | awk '/^SA/ { print $2 }')" "$(halves "$log")" \
      "$(echo "$log" | sed -n 's/.* in \([0-9.]*\) s; wrote.*/\1/p')")
    [ -n "$extra" ] || trial=$(echo "$log" | sed -n 's/^shear trial: \([a-z-]*\) .*half \([0-9.]*\), whole \([0-9.]*\)).*/\2, \3: \1/p')
  done
  printf '| %s | %.2f / %.2f / %.2f | %.2f / %.2f / %.2f | %s / %s / %s | %.2f / %.2f / %.2f | %s |\n' "$scene" \
    "${row[0]}" "${row[4]}" "${row[8]}" "${row[1]}" "${row[5]}" "${row[9]}" "${row[2]}" "${row[6]}" "${row[10]}" \
    "${row[3]}" "${row[7]}" "${row[11]}" "${trial:-no half-pixel pilot}"
done
