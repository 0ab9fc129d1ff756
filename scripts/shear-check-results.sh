#!/usr/bin/env bash
# The shear check's table (docs/results-shear-check.md, issue 49): every test, realistic and
# hard-case scene at pixel k = 1 (half-pixel disparities are searched for one snapshot only),
# decoded by the default with and without `--shear-check` (a half-pixel block is decoded at
# the neighbouring whole disparity whose held-out error estimate is below 0.7 x the half
# one's): PSNR, SA, the blocks at half disparities, the decode's seconds.
#
#   bash scripts/shear-check-results.sh OUT_DIR > docs/results-shear-check.md
set -euo pipefail
out=${1:?usage: shear-check-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-48}
scenes=${SLF_SCENES:-$all_scenes}
mkdir -p "$out"
echo "# The shear check"
echo
echo "Made by \`bash scripts/shear-check-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5"
echo "views, pixel mask, k = 1, \`slf simulate --seed 1\`, the default preset; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`)."
echo "Half blocks: the blocks decoded at a half-pixel disparity."
add_real_scenes
echo
echo "| scene | PSNR | with the check | change | SA deg | with the check | half blocks | with the check | seconds | with the check |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
halves() { echo "$1" | sed -n 's/^disparity: blocks per disparity \([^;]*\);.*/\1/p' | tr ',' '\n' | awk -F': ' '$1 ~ /\.5/ { n += $2 } END { print n + 0 }'; }
for token in $scenes; do
  scene_light_field "$token"
  scene_capture pixel:1 1
  row=()
  for extra in "" "--shear-check"; do
    # shellcheck disable=SC2086
    log=$("$slf" decode "$cap" -o "$out/rec.npy" --quiet $extra)
    ev=$("$slf" eval "$lf" "$out/rec.npy")
    row+=("$(echo "$ev" | awk '/^PSNR/ { print $2 }')" "$(echo "$ev" | awk '/^SA/ { print $2 }')" "$(halves "$log")" \
      "$(echo "$log" | sed -n 's/.* in \([0-9.]*\) s; wrote.*/\1/p')")
  done
  printf '| %s | %.2f | %.2f | %+.2f | %.2f | %.2f | %s | %s | %.2f | %.2f |\n' "$scene" "${row[0]}" "${row[4]}" \
    "$(echo "${row[4]} - ${row[0]}" | bc -l)" "${row[1]}" "${row[5]}" "${row[2]}" "${row[6]}" "${row[3]}" "${row[7]}"
done
