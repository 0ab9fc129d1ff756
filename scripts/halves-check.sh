#!/usr/bin/env bash
# Half-pixel disparities against whole ones per scene (issue 62's item 4: the default's search
# on the lenslet mask, `DisparityRange::for_capture`): every scene `slf scene` names and the
# real crops when present (SLF_REAL), at each setting of SLF_SETTINGS (default lenslet k = 2,
# 3 and 5), one thread, each capture decoded with `--disparities -1:1` and with
# `--disparities -1:1:0.5` (the shear trial deciding per frame), one after the other so their
# times compare within a row (the machine is shared: only ratios mean anything).
#
#   bash scripts/halves-check.sh OUT_DIR > OUT.md
#   SLF_SETTINGS="pixel:3" SLF_SCENES="office depth" bash scripts/halves-check.sh OUT_DIR
set -euo pipefail
out=${1:?usage: halves-check.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
SLF_SIZE=${SLF_SIZE:-64} table_setup
add_real_scenes
export RAYON_NUM_THREADS=1
rows="$out/halves.tsv"
: > "$rows"
row() {
  decode_eval "$cap" --disparities -1:1
  local pw=$p tw=$t
  decode_eval "$cap" --disparities -1:1:0.5
  printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$s" "$scene" "$pw" "$tw" "$p" "$t" >> "$rows"
}
each_capture "${SLF_SETTINGS:-lenslet:2 lenslet:3 lenslet:5}" 2 row
STAMP_LINE=$(stamp "bash scripts/halves-check.sh OUT_DIR") && export STAMP_LINE
python3 - "$rows" "$size" "$(git rev-parse --short HEAD)" <<'PY'
import statistics, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
print(__import__("os").environ["STAMP_LINE"])
print()
print(f"Made by `bash scripts/halves-check.sh OUT_DIR` at {sys.argv[3]}: synthetic scenes at {sys.argv[2]} x "
      f"{sys.argv[2]} lenslets and the real crops, `slf simulate --seed 2`, one thread; PSNR in dB, "
      "times as halves' over whole disparities' in the same row.")
for setting in dict.fromkeys(r[0] for r in rows):
    sel = [r for r in rows if r[0] == setting]
    d = [(float(r[4]) - float(r[2]), float(r[5]) / max(float(r[3]), 1e-9), r) for r in sel]
    d.sort(key=lambda x: x[0])
    gain = sum(x[0] > 0.1 for x in d); lose = sum(x[0] < -0.1 for x in d)
    mask, k = setting.split(":")
    print()
    print(f"**{mask} k = {k}**: halves gain more than 0.1 dB on {gain} of {len(d)} scenes, tie on "
          f"{len(d) - gain - lose}, lose on {lose} (worst {d[0][0]:+.2f}, {d[0][2][1]}); mean "
          f"{statistics.mean(x[0] for x in d):+.2f} dB; time {statistics.median(x[1] for x in d):.2f} times "
          f"(median; {min(x[1] for x in d):.2f} to {max(x[1] for x in d):.2f}).")
    print()
    print("| scene | whole dB | halves dB | difference | time, halves / whole |")
    print("| --- | --- | --- | --- | --- |")
    for diff, ratio, r in d:
        print(f"| {r[1]} | {float(r[2]):.2f} | {float(r[4]):.2f} | {diff:+.2f} | {ratio:.2f} |")
PY
