#!/usr/bin/env bash
# The error estimate's tables (docs/results-error-map.md, issue 49): every test, realistic
# and hard-case scene at pixel k = 1 and 3 and lenslet k = 3, decoded by the default and the
# preview with `--error-map`, and the map compared with the truth by `slf eval --error-map`:
# the true and the estimated PSNR, the rank correlation of the estimated and true RMS errors
# of blocks of 5 x 5 lenslets, the share of blocks estimated within 2 x, and the decode's
# time with the estimate against without it (one run each, same machine).
#
#   bash scripts/error-map-results.sh OUT_DIR > docs/results-error-map.md
#   SLF_SIZE=40 SLF_SCENES="canopy dim" bash scripts/error-map-results.sh OUT_DIR
set -euo pipefail
out=${1:?usage: error-map-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
echo "# The error estimate"
echo
echo "Made by \`bash scripts/error-map-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5"
echo "views, \`slf simulate --seed 1\`; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). Per decode: the true PSNR and"
echo "the one the map estimates (at the truth's data range), the rank correlation (Spearman) of the"
echo "estimated and the true RMS error of blocks of 5 x 5 lenslets, the share of blocks estimated"
echo "within a factor of 2, and the decode's seconds with the estimate over those without."
add_real_scenes
echo
echo "| scene | setting | preset | PSNR | estimated PSNR | rank correlation | within 2 x | time with / without |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for token in $scenes; do
  scene_light_field "$token"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    scene_capture "$s" 1
    for preset in default preview; do
      t0=$("$slf" decode "$cap" -o "$out/plain.npy" --quiet --preset "$preset" | sed -n 's/.* in \([0-9.]*\) s; wrote.*/\1/p')
      t1=$("$slf" decode "$cap" -o "$out/rec.npy" --quiet --preset "$preset" --error-map "$out/map.npy" |
        sed -n 's/.* in \([0-9.]*\) s; wrote.*/\1/p')
      ev=$("$slf" eval "$lf" "$out/rec.npy" --error-map "$out/map.npy")
      read -r p e rho w < <(echo "$ev" | awk '/^estimate PSNR/ { e = $3; t = $6; r = $15; w = $16 } END { sub(/\);/, "", t); sub(/,/, "", r); print t, e, r, w }')
      printf '| %s | %s k=%s | %s | %.2f | %.2f | %.3f | %s %% | %.2f |\n' "$scene" "$mask" "$k" "$preset" "$p" "$e" "$rho" "$w" \
        "$(echo "$t1 / $t0" | bc -l)"
    done
  done
done
