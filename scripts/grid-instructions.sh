#!/usr/bin/env bash
# Issue 66, the time behind a turned lenslet array in instructions (docs/results-grid-time.md,
# its second table): a repeatable figure beside scripts/grid-time.sh's seconds on a shared
# machine. For each scene (SLF_COUNT_SCENES, default office outdoor) at SLF_COUNT_SIZE x
# SLF_COUNT_SIZE lenslets (32) and pixel k = 1 and 3 (SLF_KS), the instructions callgrind
# counts in one-thread decodes by BEFORE (SLF_BEFORE) and by this binary, with the DCT and
# with the screened ensemble (`--dictionary`), on the aligned sensor and behind a grid of
# 0.3 degrees / 5.04 px (SLF_COUNT_GRIDS), sensors as scripts/grid-time.sh makes them.
# Prints a markdown table; scripts/grid-time.sh puts it on its page.
#
#   SLF_BEFORE=/tmp/before-target/release/slf bash scripts/grid-instructions.sh OUT
#
# Needs valgrind. About 35 s a decode at 32 x 32 lenslets.
set -euo pipefail
out=${1:?usage: grid-instructions.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
SLF_SIZE=${SLF_COUNT_SIZE:-32} SLF_SCENES=${SLF_COUNT_SCENES:-office outdoor} SLF_GRIDS=${SLF_COUNT_GRIDS:-0.3:5.04} SLF_REAL=/nonexistent \
  grid_table_setup

# count BIN CALIBRATION CAPTURE MODEL: the instructions of BIN's one-thread decode.
count() {
  RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$out/cg.out" \
    "$1" decode "$3" -o "$out/rec.npy" --quiet --calibration "$2" --dictionary "$4" > /dev/null 2>&1
  callgrind_annotate "$out/cg.out" | awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1 }'
}

echo "| scene | k | grid (deg:px) | model | aligned: before / after | grid: before / after | ratio: before / after |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for token in $scenes; do
  scene_light_field "$token"
  for k in $ks; do
    for g in $grids; do
      grid_captures "$k" "$g"
      for model in dct ensemble; do
        a0=$(count "$before" "$cal_aligned" "$aligned" "$model")
        g0=$(count "$before" "$cal" "$cap" "$model")
        a1=$(count "$slf" "$cal_aligned" "$aligned" "$model")
        g1=$(count "$slf" "$cal" "$cap" "$model")
        python3 -c "
a0, g0, a1, g1 = $a0, $g0, $a1, $g1
print(f'| $scene | $k | $g | $model | {a0 / 1e9:.3f} G / {a1 / 1e9:.3f} G | {g0 / 1e9:.3f} G / {g1 / 1e9:.3f} G | {g0 / a0:.2f} / {g1 / a1:.2f} |')"
      done
    done
  done
done
rm -f "$out/cg.out"
