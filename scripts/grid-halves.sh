#!/usr/bin/env bash
# Issue 66, half-pixel shears behind a grid (docs/results-grid-halves.md): for each scene at
# pixel k = 1 and 3, behind grids of 0.3 degrees / 5.04 px and 1 degree / 5.1 px, the decode
# with whole disparities (`--disparities -1:1`, the default behind a grid) and with the halves
# (`-1:1:0.5`, the aligned sensor's default at k = 1), the halves by the binary BEFORE
# (SLF_BEFORE: a half-pixel patch reads each view at the pixel under its cell's centre) and by
# this one (a half view's cell is the mean of two grid positions, read by the cells' shares,
# `firmware/src/solver/shares.rs`), against the aligned sensor's default decode. Sensors and
# scores as scripts/grid-shear.sh: 30 % vignetting and 1 % PRNU, shot and read noise, each
# calibrated from its own captures (2 exposures); PSNR without the 2 edge lenslets.
#
#   SLF_BEFORE=<a binary before the shares read half views> bash scripts/grid-halves.sh OUT \
#     > docs/results-grid-halves.md
#
# SLF_SCENES (default outdoor tungsten office led, 64 x 64 lenslets, and the HCI crops in
# SLF_REAL when present), SLF_KS (1 3), SLF_GRIDS (0.3:5.04 1:5.1). OUT/rows.tsv keeps each row;
# scripts/grid-halves-page.py makes the page's tables from one or more of them.
set -euo pipefail
out=${1:?usage: grid-halves.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
grid_table_setup
rows="$out/rows.tsv"
: > "$rows"

for token in $scenes; do
  scene_light_field "$token"
  for k in $ks; do
    for g in $grids; do
      grid_captures "$k" "$g"
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$scene" "$k" "$g" "$(grid_measure "$slf" "$cal_aligned" "$aligned")" \
        "$(grid_measure "$slf" "$cal" "$cap" --disparities -1:1)" \
        "$(grid_measure "$before" "$cal" "$cap" --disparities -1:1:0.5)" \
        "$(grid_measure "$slf" "$cal" "$cap" --disparities -1:1:0.5)" >> "$rows"
    done
  done
done

page_head "Half-pixel shears behind a lenslet grid" "SLF_BEFORE=... bash scripts/grid-halves.sh OUT_DIR"
python3 scripts/grid-halves-page.py "$rows" "$before"
