#!/usr/bin/env bash
# Issue 63: the model trial by pilot patches (the default) against the trial by held-out
# decodes (`--trial-by decode`: the frame decoded again by each model from seven in eight
# samples, the one whose decode predicts the eighth better decoding the frame), each against
# the better of the two models alone (`--dictionary dct`, `--model-trial false`), on every
# scene `slf scene` names and the real crops when present (SLF_REAL), at each setting of
# SLF_SETTINGS (default pixel k = 1 and 3, lenslet k = 3, kronecker k = 3), `--seed 1`.
#
# SLF_RESUME=1 keeps the captures OUT_DIR's table already holds (a run that stopped).
#
#   bash scripts/trial-by-decode.sh OUT_DIR > OUT.md
set -euo pipefail
out=${1:?usage: trial-by-decode.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
add_real_scenes
rows="$out/trial-by.tsv"
[ -n "${SLF_RESUME:-}" ] && [ -f "$rows" ] || : > "$rows"
row() {
  local pd td pe te pp tp pq tq
  awk -F'\t' -v s="$s" -v c="$scene" '$1 == s && $2 == c { found = 1 } END { exit !found }' "$rows" && return 0
  decode_eval "$cap" --dictionary dct; pd=$p; td=$t
  decode_eval "$cap" --model-trial false; pe=$p; te=$t
  decode_eval "$cap"; pp=$p; tp=$t
  decode_eval "$cap" --trial-by decode; pq=$p; tq=$t
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$s" "$scene" "$pd" "$pe" "$pp" "$pq" "$td" "$te" "$tp" "$tq" >> "$rows"
}
settings=${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3 kronecker:3}
each_capture "$settings" 1 row
STAMP_LINE=$(stamp "bash scripts/trial-by-decode.sh OUT_DIR") && export STAMP_LINE
python3 - "$rows" "$size" "$(git rev-parse --short HEAD)" "${RAYON_NUM_THREADS:-all}" "$settings" <<'PY'
import statistics, sys
asked = sys.argv[5].split()
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
rows = [r for r in rows if r[0] in asked]
print("# The model trial: by pilot patches or by held-out decodes (issue 63)")
print()
print(__import__("os").environ["STAMP_LINE"])
print()
print(f"Made by `bash scripts/trial-by-decode.sh OUT_DIR` at {sys.argv[3]}: synthetic scenes at {sys.argv[2]} x "
      f"{sys.argv[2]} lenslets and the real crops, `slf simulate --seed 1`, `RAYON_NUM_THREADS={sys.argv[4]}`. "
      "PSNR in dB against the better of the DCT alone and the screened ensemble alone (\"best\"); \"pilots\" is the "
      "default (the trial by pilot patches), \"decode\" is `--trial-by decode`; times are one decode each, over "
      "the default's.")
for setting in dict.fromkeys(r[0] for r in rows):
    sel = [r for r in rows if r[0] == setting]
    gaps = {"pilots": [], "decode": []}
    lines = []
    for _, scene, pd, pe, pp, pq, td, te, tp, tq in sel:
        best = max(float(pd), float(pe))
        gp, gq = float(pp) - best, float(pq) - best
        gaps["pilots"].append(gp)
        gaps["decode"].append(gq)
        lines.append(f"| {scene} | {float(pd):.2f} | {float(pe):.2f} | {gp:+.2f} | {gq:+.2f} | {float(tq) / float(tp):.2f} |")
    mask, k = setting.split(":")
    print()
    print(f"**{mask} k = {k}** ({len(sel)} scenes): more than 0.1 dB under the best: pilots "
          f"{sum(g < -0.1 for g in gaps['pilots'])} (worst {min(gaps['pilots']):+.2f}, mean {statistics.mean(gaps['pilots']):+.2f}), "
          f"decode {sum(g < -0.1 for g in gaps['decode'])} (worst {min(gaps['decode']):+.2f}, mean "
          f"{statistics.mean(gaps['decode']):+.2f}).")
    print()
    print("| scene | DCT | ensemble | pilots - best | decode - best | time, decode / pilots |")
    print("| --- | --- | --- | --- | --- | --- |")
    print("\n".join(lines))
PY
