#!/usr/bin/env bash
# Peak memory and seconds of a decode against the frame's size (issue 50): the texture scene
# at SIZES lenslets a side (5 x 5 views, 13 bands), simulated at pixel k = 1 with seed 1, decoded
# by each preset in PRESETS; peak resident memory from /usr/bin/time -v (the whole process:
# the capture, the decode and the written output), with the output's own size beside it.
# A size whose scene or capture would not fit is reported and skipped, not fatal.
#
#   bash scripts/memory-scale.sh OUT_DIR > table.md
#   SLF_SIZES="100 200 300" SLF_PRESETS="default preview" RAYON_NUM_THREADS=2 bash scripts/memory-scale.sh OUT_DIR
set -euo pipefail
out=${1:?usage: memory-scale.sh OUT_DIR}
cd "$(dirname "$0")/.."
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
sizes=${SLF_SIZES:-100 200 300}
presets=${SLF_PRESETS:-default preview}
mkdir -p "$out"
echo "# Peak memory against frame size"
echo
echo "Made by \`bash scripts/memory-scale.sh OUT_DIR\` (texture scene, pixel k = 1, \`slf simulate --seed 1\`;"
echo "\`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). Peak resident memory of \`slf decode\` (the whole process)"
echo "from \`/usr/bin/time -v\`; output: the decoded light field's own size (f32)."
echo
echo "| lenslets | output MB | preset | peak resident MB | peak / output | seconds |"
echo "| --- | --- | --- | --- | --- | --- |"
for n in $sizes; do
  lf="$out/texture-$n.npy"; cap="$out/cap-$n"
  if ! { [ -f "$lf" ] || "$slf" scene texture --size "$n" -o "$lf" > /dev/null 2>&1; } ||
     ! { [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask pixel -s 1 --seed 1 > /dev/null 2>&1; }; then
    echo "| $n x $n | | | could not simulate (memory?) | | |"
    continue
  fi
  rm -f "$lf"  # the truth is not needed to decode; keep the disk for the output
  output=$(echo "$n * $n * 25 * 13 * 4 / 1000000" | bc -l)
  for p in $presets; do
    log="$out/time-$n-$p.txt"
    if /usr/bin/time -v "$slf" decode "$cap" -o "$out/rec.npy" -q --preset "$p" > /dev/null 2> "$log"; then
      kb=$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$log")
      s=$(awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, a, ":"); t = 0; for (i = 1; i <= n; i++) t = 60 * t + a[i]; print t }' "$log")
      printf '| %s x %s | %.0f | %s | %.0f | %.1f | %.1f |\n' "$n" "$n" "$output" "$p" "$(echo "$kb / 1000" | bc -l)" \
        "$(echo "$kb / 1000 / $output" | bc -l)" "$s"
    else
      printf '| %s x %s | %.0f | %s | failed (see %s) | | |\n' "$n" "$n" "$output" "$p" "$log"
    fi
    rm -f "$out/rec.npy"
  done
done
