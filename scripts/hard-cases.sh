#!/usr/bin/env bash
# The hard-case set's tables (docs/results-hard.md, issue 42): the baselines and every preset
# on each hard-case scene (`slf scene NAME`, host-sim/src/sim/hard.rs), at pixel k = 1 and 3,
# lenslet k = 3 and kronecker k = 3, with the capture's noise model. One table per scene:
# PSNR / SSIM / SA, the decode's wall time, and the default's and the preview's margins over the
# strongest baseline. Nothing is kept but the tables: the light fields are rendered into
# OUT_DIR, which may be deleted after.
#
#   bash scripts/hard-cases.sh OUT_DIR > docs/results-hard.md
#   SLF_SIZE=40 SLF_SETTINGS="pixel:1" bash scripts/hard-cases.sh OUT_DIR   # smaller, faster
#   RAYON_NUM_THREADS=1 bash scripts/hard-cases.sh OUT_DIR                  # times of one thread
#
# Times are of one run on a shared machine: compare them within a table, not across runs.
set -euo pipefail
out=${1:?usage: hard-cases.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-64}
scenes=${SLF_SCENES:-mosaic mosaic-2 field print speculars narrow dim canopy canopy-dim}
methods="demosaic=--method,demosaic ppid=--method,ppid preview=--preset,preview default=--preset,default best=--preset,best"
mkdir -p "$out"
page_head "The hard-case set" "bash scripts/hard-cases.sh OUT_DIR"
echo "Made by \`bash scripts/hard-cases.sh OUT_DIR\` (scenes of ${size} x ${size} lenslets, 5 x 5 views;"
echo "\`RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all}\`). Each scene is described in"
echo "\`host-sim/src/sim/hard.rs\`. Margins: the default's and the preview's PSNR less the"
echo "strongest baseline's (demosaic or PPID). The presets decode with the shipped blob's trained"
echo "schedules (\`--schedule trained\`, the default since issue 42)."
add_real_scenes
for token in $scenes; do
  scene_light_field "$token"
  echo
  echo "## $scene"
  echo
  echo "| setting | method | PSNR | SSIM | SA deg | seconds |"
  echo "| --- | --- | --- | --- | --- | --- |"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3 kronecker:3}; do
    mask=${s%:*}; k=${s#*:}
    cap="$out/cap-$scene-$mask-$k"
    [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask "$mask" -s "$k" --seed 3 > /dev/null 2>&1
    baseline=-1000; default=0; preview=0
    for m in $methods; do
      name=${m%%=*}; args=${m#*=}; args=${args//,/ }
      # shellcheck disable=SC2086
      decode_eval "$cap" $args
      printf '| %s k=%s | %s | %.2f | %.4f | %.2f | %.2f |\n' "$mask" "$k" "$name" "$p" "$q" "$a" "${t:-0}"
      case $name in
        demosaic | ppid) baseline=$(echo "if ($p > $baseline) $p else $baseline" | bc -l) ;;
        default) default=$p ;;
        preview) preview=$p ;;
      esac
    done
    printf '| %s k=%s | **margins** | default %+.2f, preview %+.2f | | | |\n' "$mask" "$k" \
      "$(echo "$default - $baseline" | bc -l)" "$(echo "$preview - $baseline" | bc -l)"
  done
done
