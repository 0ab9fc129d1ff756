#!/usr/bin/env bash
# The preview's table (docs/results-preview.md, issue 49): every test, realistic and
# hard-case scene and the real crops at pixel k = 1 and 3, lenslet k = 3 and kronecker k = 3,
# decoded by the two baselines (demosaic, PPID), by the preview before issue 49's choices
# (--model-trial false --sheared-fallback false: the DCT on every patch, the values between
# blocks sheared otherwise filled from other views), with the sheared fallback alone
# (--model-trial false) and by the preview (the fallback and the model trial leaning to the
# DCT). Per decode: PSNR and seconds; for the preview, the model its trial picked and the
# pilots' held-out RMS errors. Then, per setting: cases below the strongest baseline, the
# preview's gain, and its time over the one before.
#
#   bash scripts/preview-results.sh OUT_DIR > docs/results-preview.md
#   SLF_SIZE=40 SLF_SCENES="smooth canopy" bash scripts/preview-results.sh OUT_DIR
set -euo pipefail
out=${1:?usage: preview-results.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
settings=${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3 kronecker:3}
page_head "The preview and its model trial" "bash scripts/preview-results.sh OUT_DIR"
echo "Made by \`bash scripts/preview-results.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, the real crops"
echo "at their own size, 5 x 5 views, \`slf simulate --seed 3\`; \`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`)."
echo "\"before\": \`--preset preview --model-trial false --sheared-fallback false\` (the DCT on every patch,"
echo "the values between blocks sheared otherwise from their lenslet's other views); \"fallback\":"
echo "\`--model-trial false\` (every sheared block decoded unsheared as well, for those values);"
echo "\"preview\": \`--preset preview\`, whose model trial also gives the frame to the screened ensemble"
echo "where the pilots' held-out RMS error is below 0.8 x the DCT's. Margins: PSNR less the strongest"
echo "baseline's (demosaic or PPID). Times in seconds, one decode each."
add_real_scenes
echo
echo "| scene | setting | strongest baseline | before | fallback | preview | picked (pilots: RMS DCT, ensemble) | s demosaic / before / preview |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
summary=$(mktemp)
for token in $scenes; do
  scene_light_field "$token"
  for s in $settings; do
    scene_capture "$s" 3
    decode_eval "$cap" --method demosaic; dem=$p; tdem=$t
    decode_eval "$cap" --method ppid; base=$(echo "if ($p > $dem) $p else $dem" | bc -l)
    decode_eval "$cap" --preset preview --model-trial false --sheared-fallback false; before=$p; tbefore=$t
    decode_eval "$cap" --preset preview --model-trial false; ens=$p
    decode_eval "$cap" --preset preview; preview=$p; tpreview=$t
    pick=$(echo "$log" \
      | sed -n 's/^model trial: decoded by the \([A-Za-z]*\) (held-out error over \([0-9]*\) pilot patches: DCT \([0-9.]*\), ensemble \([0-9.]*\)).*/\1 (\2: \3, \4)/p')
    printf '| %s | %s k=%s | %.2f | %+.2f | %+.2f | %+.2f | %s | %.3f / %.3f / %.3f |\n' "$scene" "$mask" "$k" "$base" \
      "$(echo "$before - $base" | bc -l)" "$(echo "$ens - $base" | bc -l)" "$(echo "$preview - $base" | bc -l)" \
      "$pick" "$tdem" "$tbefore" "$tpreview"
    echo "$mask:$k $base $before $preview $tbefore $tpreview $tdem" >> "$summary"
  done
done
echo
echo "| setting | before: below the baseline | preview: below the baseline | preview - before: mean / min / max dB | seconds preview / before (summed) | preview / demosaic (summed) |"
echo "| --- | --- | --- | --- | --- | --- |"
for s in $settings; do
  awk -v s="$s" '$1 == s {
      n++; ob += ($3 < $2); nb += ($4 < $2); d = $4 - $3; sum += d
      if (n == 1 || d < lo) lo = d; if (n == 1 || d > hi) hi = d
      tb += $5; tp += $6; td += $7
    }
    END { if (n) printf "| %s | %d of %d | %d of %d | %+.2f / %+.2f / %+.2f | %.2f | %.1f |\n", s, ob, n, nb, n, sum / n, lo, hi, tp / tb, tp / td }' \
    "$summary"
done
rm -f "$summary"
