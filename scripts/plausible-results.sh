#!/usr/bin/env bash
# The plausibility check's tables (docs/results-plausible.md, issue 49): every test,
# realistic and hard-case scene at pixel k = 1 and 3 and lenslet k = 3, decoded by the
# default, the DCT alone and the preview, each with the check (the default, --plausible
# 3:0.05) and without it (--plausible off). Per decode: PSNR, the blocks of 5 x 5 lenslets
# decoded above 2 x the truth's maximum + 0.05 (`slf eval`'s "over"), the patches the check
# found implausible and decoded again (of them clipped), and the SL0 solves a patch.
#
#   bash scripts/plausible-results.sh OUT_DIR > docs/results-plausible.md
#   SLF_SIZE=40 SLF_SCENES="canopy dim" bash scripts/plausible-results.sh OUT_DIR
set -euo pipefail
out=${1:?usage: plausible-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
methods="default=--preset,default dct=--dictionary,dct preview=--preset,preview"
page_head "The plausibility check" "bash scripts/plausible-results.sh OUT_DIR"
echo "Made by \`bash scripts/plausible-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5"
echo "views, \`slf simulate --seed 1\`; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). \"over\": blocks of 5 x 5"
echo "lenslets decoded above 2 x the truth's maximum + 0.05. \"implausible\": patches the check"
echo "decoded again (clipped: of them, those the safe path left above a bound too)."
add_real_scenes
echo
echo "| scene | setting | method | PSNR off | PSNR on | change | over off | over on | implausible (clipped) of patches | solves a patch off / on |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for token in $scenes; do
  scene_light_field "$token"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    scene_capture "$s" 1
    for m in $methods; do
      name=${m%%=*}; args=${m#*=}; args=${args//,/ }
      row=()
      for check in off 3:0.05; do
        # shellcheck disable=SC2086
        log=$("$slf" decode "$cap" -o "$out/rec.npy" --quiet $args --plausible "$check")
        ev=$("$slf" eval "$lf" "$out/rec.npy")
        p=$(echo "$ev" | awk '/^PSNR/ { print $2 }')
        o=$(echo "$ev" | awk '/^over/ { print $2 }')
        n=$(echo "$log" | sed -n 's/.*decoded \([0-9]*\) patches.*/\1/p')
        imp=$(echo "$log" | sed -n 's/^plausibility: \([0-9]*\) implausible patches decoded again, \([0-9]*\) of them clipped.*/\1 (\2)/p')
        sp=$(echo "$log" | sed -n 's/.*(\([0-9.]*\) solves and.*/\1/p')
        row+=("$p" "$o" "$imp" "$n" "$sp")
      done
      printf '| %s | %s k=%s | %s | %.2f | %.2f | %+.2f | %s | %s | %s of %s | %s / %s |\n' "$scene" "$mask" "$k" "$name" \
        "${row[0]}" "${row[5]}" "$(echo "${row[5]} - ${row[0]}" | bc -l)" "${row[1]}" "${row[6]}" "${row[7]}" "${row[8]}" "${row[4]}" "${row[9]}"
    done
  done
done
