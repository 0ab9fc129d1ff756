#!/usr/bin/env bash
# The model trial's tables (docs/results-model-trial.md, issue 49): every test, realistic
# and hard-case scene at pixel k = 1 and 3 and lenslet k = 3, decoded by the default
# without the trial (--model-trial false: the screened ensemble everywhere, the default
# before it), by the DCT alone (--dictionary dct) and by the default (the trial picking
# one of the two per region). Per decode: PSNR, seconds (one decode, this machine) and
# solves a patch; for the trial, the regions it gave the DCT.
#
#   bash scripts/model-trial-results.sh OUT_DIR > docs/results-model-trial.md
#   SLF_SIZE=40 SLF_SCENES="smooth canopy" bash scripts/model-trial-results.sh OUT_DIR
set -euo pipefail
out=${1:?usage: model-trial-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-48}
scenes=${SLF_SCENES:-$all_scenes}
mkdir -p "$out"
echo "# The model trial"
echo
echo "Made by \`bash scripts/model-trial-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5"
echo "views, \`slf simulate --seed 1\`; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). \"before\": \`--model-trial false\`"
echo "(the screened ensemble on every patch); \"dct\": \`--dictionary dct\`; \"trial\": the default. \"best\":"
echo "the trial's PSNR minus the better of the other two. Times in seconds, one decode each; the"
echo "held-out errors are the trial's, RMS over its pilot patches in the output's units."
add_real_scenes
echo
echo "| scene | setting | before | dct | trial | trial - best | picked (held-out RMS DCT, ensemble) | s before / dct / trial | solves a patch before / trial |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
run() {
  local log
  log=$("$slf" decode "$cap" -o "$out/rec.npy" --quiet "$@")
  t=$(echo "$log" | awk '/ in [0-9.]+ s/ { for (i = 1; i < NF; i++) if ($i == "in") print $(i + 1) }')
  sp=$(echo "$log" | sed -n 's/.*(\([0-9.]*\) solves and.*/\1/p')
  reg=$(echo "$log" | sed -n 's/^model trial: decoded by the \([A-Za-z]*\) (held-out error over [0-9]* pilot patches: DCT \([0-9.]*\), ensemble \([0-9.]*\)).*/\1 \2 \3/p')
  p=$("$slf" eval "$lf" "$out/rec.npy" | awk '/^PSNR/ { print $2 }')
}
for token in $scenes; do
  scene_light_field "$token"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    scene_capture "$s" 1
    run --model-trial false; pb=$p; tb=$t; sb=$sp
    run --dictionary dct; pd=$p; td=$t
    run; pt=$p; tt=$t; st=$sp; read -r who ed ee <<< "$reg"; rt="$who ($ed, $ee)"
    best=$(echo "if ($pb > $pd) $pb else $pd" | bc -l)
    printf '| %s | %s k=%s | %.2f | %.2f | %.2f | %+.2f | %s | %s / %s / %s | %s / %s |\n' "$scene" "$mask" "$k" \
      "$pb" "$pd" "$pt" "$(echo "$pt - $best" | bc -l)" "$rt" "$tb" "$td" "$tt" "$sb" "$st"
  done
done
