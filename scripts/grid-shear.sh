#!/usr/bin/env bash
# Issue 66, the sheared patch behind a grid (docs/results-grid-shear.md): for each scene at
# pixel k = 1 and 3, behind grids of 0.3 degrees / 5.04 px and 1 degree / 5.1 px, the default
# decode by the binary BEFORE (SLF_BEFORE: every pixel a sheared patch reads is its
# measurement) and by this one (at k >= 2 a sheared patch leaves out the pixels more than
# `MAX_OUTSIDE_SHARE` over cells outside it), against the aligned sensor's default decode.
# Every sensor has 30 % vignetting and 1 % PRNU, shot and read noise, and is calibrated from
# its own captures (2 exposures each), as `scripts/grid-results.sh` makes them. PSNR without
# the 2 lenslets at each edge (`slf eval --border 2`: a turned array's corners reach past the
# sensor), SSIM and SA of the whole frame.
#
#   git worktree add /tmp/before b55cdfe~1 && CARGO_TARGET_DIR=/tmp/before-target \
#     cargo build --release -p slf-host --manifest-path /tmp/before/Cargo.toml
#   SLF_BEFORE=/tmp/before-target/release/slf bash scripts/grid-shear.sh OUT > docs/results-grid-shear.md
#
# SLF_SCENES (default outdoor tungsten office led, 64 x 64 lenslets, and the HCI crops in
# SLF_REAL when present), SLF_KS (1 3), SLF_GRIDS (0.3:5.04 1:5.1). OUT/rows.tsv keeps each row;
# scripts/grid-shear-page.py makes the page's tables from one or more of them. SLF_TITLE and
# SLF_ABOUT (what before and after are) make it another change's page with the same tables
# (docs/results-grid-known.md: the cells outside a sheared patch from the first pass).
set -euo pipefail
out=${1:?usage: grid-shear.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
grid_table_setup
rows="$out/rows.tsv"
: > "$rows"

# calibration GRID_FLAGS...: sets $cal and $cal_before, this binary's and BEFORE's
# calibrations of this scene's sensor (once per scene and grid; each binary decodes with its
# own: one before e411fe7 does not read a later calibration's `outside_pixels`).
calibration() {
  cal="$out/cal-$scene-$label" cal_before="$out/cal-before-$scene-$label"
  grid_calibration "$slf" "$cal" "$@" > /dev/null
  grid_calibration "$before" "$cal_before" "$@" > /dev/null
}

for token in $scenes; do
  scene_light_field "$token"
  for k in $ks; do
    label=aligned
    calibration
    cap="$out/cap-$scene-$k-aligned"
    [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 "${sensor[@]}" > /dev/null 2>&1
    ref=$(grid_measure "$slf" "$cal" "$cap")
    for g in $grids; do
      label=$g
      calibration --rotation "${g%:*}" --pitch "${g#*:}"
      cap="$out/cap-$scene-$k-$g"
      [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 "${sensor[@]}" \
        --rotation "${g%:*}" --pitch "${g#*:}" > /dev/null 2>&1
      printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$scene" "$k" "$g" "$ref" "$(grid_measure "$before" "$cal_before" "$cap")" \
        "$(grid_measure "$slf" "$cal" "$cap")" >> "$rows"
    done
  done
done

page_head "${SLF_TITLE:-A sheared patch behind a lenslet grid}" "SLF_BEFORE=... bash scripts/grid-shear.sh OUT_DIR"
python3 scripts/grid-shear-page.py "$rows" "$before"
