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
table_setup
page_head "The model trial" "bash scripts/model-trial-results.sh OUT_DIR"
echo "Made by \`bash scripts/model-trial-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, the real crops"
echo "at their own size, 5 x 5 views, \`slf simulate --seed 1\`; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). \"before\": \`--model-trial false\`"
echo "(the screened ensemble on every patch; the shear trial on in all three, as in the default:"
echo "docs/results-shear-check.md); \"dct\": \`--dictionary dct\`; \"trial\": the default. \"best\":"
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
# Per setting: cases, cases within 0.1 dB of the better of before and dct, the worst
# trial - best, and the same two for before (the default without the trial) and for dct.
declare -A cases near worst bnear bworst dnear dworst secs_b secs_t
for token in $scenes; do
  scene_light_field "$token"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    scene_capture "$s" 1
    run --model-trial false; pb=$p; tb=$t; sb=$sp
    run --dictionary dct; pd=$p; td=$t
    run; pt=$p; tt=$t; st=$sp; read -r who ed ee <<< "$reg"; rt="$who ($ed, $ee)"
    best=$(echo "if ($pb > $pd) $pb else $pd" | bc -l)
    key="$mask k=$k"
    cases[$key]=$(( ${cases[$key]:-0} + 1 ))
    secs_b[$key]=$(echo "${secs_b[$key]:-0} + $tb" | bc -l)
    secs_t[$key]=$(echo "${secs_t[$key]:-0} + $tt" | bc -l)
    for v in t:$pt b:$pb d:$pd; do
      who=${v%%:*}; x=${v#*:}; gap=$(echo "$x - $best" | bc -l)
      case $who in t) n=near; w=worst ;; b) n=bnear; w=bworst ;; d) n=dnear; w=dworst ;; esac
      if [ "$(echo "$gap >= -0.1" | bc -l)" = 1 ]; then eval "$n[\$key]=\$(( \${$n[\$key]:-0} + 1 ))"; fi
      eval "old=\${$w[\$key]:-0}"
      if [ "$(echo "$gap < $old" | bc -l)" = 1 ]; then eval "$w[\$key]=\$gap"; fi
    done
    printf '| %s | %s k=%s | %.2f | %.2f | %.2f | %+.2f | %s | %s / %s / %s | %s / %s |\n' "$scene" "$mask" "$k" \
      "$pb" "$pd" "$pt" "$(echo "$pt - $best" | bc -l)" "$rt" "$tb" "$td" "$tt" "$sb" "$st"
  done
done
echo
echo "Within 0.1 dB of the better of the two models, of the scenes (the worst gap in brackets):"
echo
echo "| setting | scenes | trial | before (ensemble everywhere) | dct everywhere | seconds, trial / before (sum over the scenes) |"
echo "| --- | --- | --- | --- | --- | --- |"
for key in "${!cases[@]}"; do
  printf '| %s | %s | %s (%+.2f) | %s (%+.2f) | %s (%+.2f) | %.1f / %.1f = %.2f |\n' "$key" "${cases[$key]}" "${near[$key]:-0}" \
    "${worst[$key]:-0}" "${bnear[$key]:-0}" "${bworst[$key]:-0}" "${dnear[$key]:-0}" "${dworst[$key]:-0}" \
    "${secs_t[$key]}" "${secs_b[$key]}" "$(echo "${secs_t[$key]} / ${secs_b[$key]}" | bc -l)"
done | sort
