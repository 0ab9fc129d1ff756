#!/usr/bin/env bash
# Peak memory and seconds of a decode against the frame's size (issue 50): the texture scene
# at SIZES lenslets (5 x 5 views, 13 bands), simulated at pixel k = 1 with seed 1, decoded by
# each preset in PRESETS; peak resident memory from /usr/bin/time -v (the whole process: the
# capture, the decode and the written output), with the output's own size beside it. A size
# is N (N x N lenslets) or ROWSxCOLS (wider than tall: the memory against the frame's height
# at equal width). A size whose scene or capture would not fit is reported and skipped.
#
# SLF_PRESETS: presets, or the baseline methods interpolate, demosaic and ppid (`--method`).
#
# SLF_FORMATS: the outputs measured (default "npy"; "npy h5 zarr" for issue 65's table: the
# HDF5 file and the Zarr store are written a band of rows at a time, as the .npy is).
#
# SLF_CALIBRATION=1: the capture simulated with vignetting 0.3 beside its calibration
# captures (one exposure each), calibrated by `slf calibrate`, and every decode given
# `--calibration` (the correction read with the frames, a band at a time).
#
# SLF_BEFORE=PATH: another slf binary (e.g. one built before the streamed decode) measured in
# the same run beside this one, on sizes whose output is at most SLF_BEFORE_MAX_MB (default
# 150: the whole-frame decode needed 35 x its output); SLF_BEFORE_LABEL names it in the table.
#
#   bash scripts/memory-scale.sh OUT_DIR > docs/results-memory.md
#   SLF_SIZES="100 200" SLF_PRESETS=default SLF_BEFORE=/tmp/old/slf bash scripts/memory-scale.sh OUT_DIR
set -euo pipefail
out=${1:?usage: memory-scale.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
sizes=${SLF_SIZES:-100 200 300 500 500x1000 1000}
presets=${SLF_PRESETS:-default preview}
formats=${SLF_FORMATS:-npy}
before=${SLF_BEFORE:-}
before_max=${SLF_BEFORE_MAX_MB:-150}
label=${SLF_BEFORE_LABEL:-$before}
calibration=${SLF_CALIBRATION:-}
export RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-2}
mkdir -p "$out"
page_head "Peak memory against frame size" "bash scripts/memory-scale.sh OUT_DIR"
echo "Made by \`bash scripts/memory-scale.sh OUT_DIR\` with the settings above (texture scene, pixel k = 1,"
echo "\`slf simulate --seed 1\`; \`RAYON_NUM_THREADS=$RAYON_NUM_THREADS\`; $(nproc) cores). Peak resident memory of"
echo "\`slf decode CAP -o OUT.npy\` (the whole process) from \`/usr/bin/time -v\`; output: the decoded light"
echo "field's own size (f32); seconds: wall time of the same run (a shared machine: a benchmark, not a test)."
if [ -n "$calibration" ]; then
  echo "Calibrated: the capture simulated with \`--vignetting 0.3 --calibration-captures CC --exposures 1\`,"
  echo "\`slf calibrate CC -o CAL\`, every decode given \`--calibration CAL\`."
fi
if [ -n "$before" ]; then
  echo "Before: $label, measured in the same run where its"
  echo "output is at most $before_max MB (it held about 35 x its output)."
fi
echo
echo "| lenslets | output MB | preset | format | peak resident MB | peak / output | seconds | before: peak MB | before: seconds |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
# Peak MB and seconds of `$1 decode CAP -o OUT.$5 --preset P` (or `--method P`), or "failed".
measure() {
  local bin=$1 cap=$2 p=$3 log=$4 ext=${5:-npy}
  local how=(--preset "$p")
  case $p in interpolate | demosaic | ppid) how=(--method "$p") ;; esac
  if [ -n "$calibration" ]; then how+=(--calibration "$cap.cal"); fi
  if /usr/bin/time -v "$bin" decode "$cap" -o "$out/rec.$ext" -q "${how[@]}" > /dev/null 2> "$log"; then
    kb=$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$log")
    s=$(awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, a, ":"); t = 0; for (i = 1; i <= n; i++) t = 60 * t + a[i]; print t }' "$log")
    printf '%.0f %.1f' "$(echo "$kb / 1000" | bc -l)" "$s"
  else
    echo "failed"
  fi
  rm -rf "$out/rec.$ext"
}
for n in $sizes; do
  rows=${n%x*}; cols=${n#*x}
  lf="$out/texture-$n.npy"; cap="$out/cap-$n"
  sim=()
  if [ -n "$calibration" ]; then
    cap="$out/calibrated-$n"
    sim=(--vignetting 0.3 --calibration-captures "$cap.cc" --exposures 1)
  fi
  if ! { [ -d "$cap" ] || [ -f "$lf" ] || "$slf" scene texture --size "$cols" --rows "$rows" -o "$lf" > /dev/null 2>&1; } ||
     ! { [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask pixel -s 1 --seed 1 "${sim[@]}" > /dev/null 2>&1; } ||
     ! { [ -z "$calibration" ] || [ -d "$cap.cal" ] || "$slf" calibrate "$cap.cc" -o "$cap.cal" > /dev/null 2>&1; }; then
    echo "| $rows x $cols | | | | could not simulate (memory?) | | | | |"
    continue
  fi
  rm -f "$lf"  # the truth is not needed to decode; keep the disk for the output
  rm -rf "$cap.cc"  # nor the calibration captures once calibrated
  output=$(echo "$rows * $cols * 25 * 13 * 4 / 1000000" | bc -l)
  for p in $presets; do
    for f in $formats; do
      read -r mb s <<< "$(measure "$slf" "$cap" "$p" "$out/time-$n-$p-$f.txt" "$f") "
      if [ "$mb" = failed ]; then
        printf '| %s x %s | %.0f | %s | %s | failed (see %s) | | | | |\n' "$rows" "$cols" "$output" "$p" "$f" "$out/time-$n-$p-$f.txt"
        continue
      fi
      old="| |"
      if [ -n "$before" ] && [ "$f" = npy ] && [ "$(echo "$output <= $before_max" | bc -l)" = 1 ]; then
        read -r bmb bs <<< "$(measure "$before" "$cap" "$p" "$out/before-$n-$p.txt") "
        old="| $bmb | $bs |"
      fi
      printf '| %s x %s | %.0f | %s | %s | %s | %.1f | %s %s\n' "$rows" "$cols" "$output" "$p" "$f" "$mb" "$(echo "$mb / $output" | bc -l)" "$s" "$old"
    done
  done
done
