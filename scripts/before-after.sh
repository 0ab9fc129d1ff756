#!/usr/bin/env bash
# The before / after tables of issue 62 (docs/results-speed.md): every scene `slf scene` names
# (the test, realistic and hard-case sets) and the real crops when present, at pixel k = 1,
# pixel k = 3 and lenslet k = 3, the capture's noise model. Per scene: the demosaic's and PPID's
# PSNR and the demosaic's seconds; the preview and the default decoded by the binary BEFORE
# (SLF_BEFORE) and by this one, each decode right after the other on the same capture, so their
# times compare within a row (one run; the machine is shared: only ratios mean anything).
#
#   git worktree add /tmp/before e25a905 && CARGO_TARGET_DIR=/tmp/before-target \
#     cargo build --release -p slf-host --manifest-path /tmp/before/Cargo.toml
#   SLF_BEFORE=/tmp/before-target/release/slf RAYON_NUM_THREADS=1 \
#     bash scripts/before-after.sh OUT > docs/results-speed.md
#
# OUT/rows.tsv keeps every decode's figures (scene, setting, method, binary, PSNR, SSIM, SA,
# seconds); scripts/before-after.py makes the tables from it.
set -euo pipefail
out=${1:?usage: before-after.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
add_real_scenes
rows="$out/rows.tsv"
: > "$rows"
for token in $scenes; do
  scene_light_field "$token"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    scene_capture "$s" 3
    for m in demosaic=--method,demosaic ppid=--method,ppid preview=--preset,preview default=--preset,default; do
      name=${m%%=*}; args=${m#*=}; args=${args//,/ }
      bins="after"
      case $name in preview | default) bins="before after" ;; esac
      for b in $bins; do
        if [ "$b" = before ]; then bin=$before; else bin=$slf; fi
        # shellcheck disable=SC2086
        log=$("$bin" decode "$cap" -o "$out/rec.npy" --quiet $args)
        t=$(echo "$log" | awk '/ in [0-9.]+ s/ { for (i = 1; i < NF; i++) if ($i == "in") print $(i + 1) }')
        # Scored by this binary's `slf eval`, whichever binary decoded.
        read -r p q a < <("$slf" eval "$lf" "$out/rec.npy" | awk '/^PSNR/ { p = $2 } /^SSIM/ { q = $2 } /^SA/ { a = $2 } END { print p, q, a }')
        printf '%s\t%s:%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$scene" "$mask" "$k" "$name" "$b" "$p" "$q" "$a" "${t:-0}" >> "$rows"
      done
    done
  done
done
STAMP_LINE=$(stamp "SLF_BEFORE=BINARY bash scripts/before-after.sh OUT") && export STAMP_LINE
python3 scripts/before-after.py "$rows" "${RAYON_NUM_THREADS:-all}" "$before" "$size" "$(git rev-parse --short HEAD)"
