#!/usr/bin/env bash
# Issue 66, where a sheared patch loses behind a grid (docs/results-grid-views.md): office at
# 64 x 64 lenslets, pixel k = 1 and 3, noiseless (`--no-noise`: the model's error alone), the
# aligned sensor and a grid turned 0.3 degrees at 5.04 px, each decoded unsheared
# (`--disparities 0:0`) and with the whole disparities (`-1:1`, the default behind a grid);
# PSNR without the 2 edge lenslets, then per view (scripts/per-view-psnr.py).
#
#   bash scripts/grid-views.sh OUT > docs/results-grid-views.md
#
# SLF_SCENES (default office), SLF_KS (1 3), SLF_GRIDS (0.3:5.04).
set -euo pipefail
out=${1:?usage: grid-views.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
SLF_SIZE=${SLF_SIZE:-64} SLF_SCENES=${SLF_SCENES:-office} table_setup
ks=${SLF_KS:-1 3}
grids=${SLF_GRIDS:-0.3:5.04}

page_head "Where a sheared patch loses behind a lenslet grid" "bash scripts/grid-views.sh OUT_DIR"
cat <<'TEXT'
Each table: a decode's PSNR (dB, without the 2 edge lenslets) per view, rows the view rows,
columns the view columns, from noiseless captures (no shot or read noise, an ideal sensor:
the decoder's model alone). On the aligned sensor the shears raise every view; behind the
grid the inner views rise with them and the outer ring falls: in a patch sheared by `d = -1`
the cell across a micro-image border from an outer view's pixel (view `U - 1` of lenslet `L`
beside view 0 of `L + 1`) lies `1 - (U - 1) d` = 5 grid positions on, outside the patch, for
every lenslet of it, not only at its rim, so that pixel's share there is given to its own
cell (or the pixel left out, `MAX_OUTSIDE_SHARE`).
TEXT
for token in $scenes; do
  scene_light_field "$token"
  for k in $ks; do
    for g in aligned $grids; do
      cap="$out/cap-$scene-$k-$g"
      if [ "$g" = aligned ]; then
        [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 --no-noise > /dev/null 2>&1
      else
        [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 --no-noise \
          --rotation "${g%:*}" --pitch "${g#*:}" > /dev/null 2>&1
      fi
      for d in 0:0 -1:1; do
        "$slf" decode "$cap" -o "$out/rec.npy" --quiet --disparities "$d" > /dev/null
        psnr=$("$slf" eval "$lf" "$out/rec.npy" --border 2 | awk '/^PSNR/ { print $2 }')
        printf '\n## %s, k = %s, %s, disparities %s: %s dB\n\n' "$scene" "$k" "$g" "$d" "$psnr"
        python3 scripts/per-view-psnr.py "$lf" "$out/rec.npy" 2
      done
    done
  done
done
