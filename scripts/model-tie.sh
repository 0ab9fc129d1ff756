#!/usr/bin/env bash
# Issue 63: the model trial's tie rule. Where the pilots' errors of the DCT and the ensemble
# are within two standard errors of their paired differences, the default takes the model the
# mask and snapshot count favour (`slf_firmware::dct_where_tied`); elsewhere, and on kronecker
# masks, the lower sum, as before. Each capture is decoded by the default, `--dictionary dct`
# and `--model-trial false` (all with `--baseline-blend false`: the model's choice alone); the
# pick the lower sum would have made is read from the trial's line. Three sets:
#
# - the set the priors were read from: every scene at 48 x 48 lenslets and the real crops
#   (SLF_REAL), `--seed 1`;
# - a second set, not looked at before: every scene at 60 x 60 lenslets, `--seed 2`;
# - the issue's two frames: depth at 60 and texture at 300 lenslets, pixel k = 1, `--seed 1`.
#
# SLF_RESUME=1 keeps the rows OUT_DIR already holds.
#
#   bash scripts/model-tie.sh OUT_DIR > OUT.md
set -euo pipefail
root=${1:?usage: model-tie.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
out=$root
table_setup
rows="$root/tie.tsv"
[ -n "${SLF_RESUME:-}" ] && [ -f "$rows" ] || : > "$rows"
row() {
  local pd pe trial
  awk -F'\t' -v g="$group" -v s="$s" -v c="$scene" '$1 == g && $2 == s && $3 == c { found = 1 } END { exit !found }' \
    "$rows" && return 0
  decode_eval "$cap" --baseline-blend false --dictionary dct; pd=$p
  decode_eval "$cap" --baseline-blend false --model-trial false; pe=$p
  decode_eval "$cap" --baseline-blend false
  trial=$(echo "$log" | grep "^model trial" || true)
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$group" "$s" "$scene" "$pd" "$pe" "$p" "$trial" >> "$rows"
}
settings="pixel:1 pixel:3 lenslet:3 kronecker:3"
group="48 x 48, seed 1, with the real crops"
out="$root/seed1"; size=48; mkdir -p "$out"
add_real_scenes
each_capture "$settings" 1 row
group="60 x 60, seed 2"
out="$root/seed2"; size=60; scenes=${SLF_SCENES:-$all_scenes}; mkdir -p "$out"
each_capture "$settings" 2 row
group="the issue's frames"
out="$root/issue"; mkdir -p "$out"
for pair in depth:60 texture:300; do
  scenes=${pair%:*}; size=${pair#*:}; out="$root/issue/$size"; mkdir -p "$out"
  each_capture "pixel:1" 1 row
done
STAMP_LINE=$(stamp "bash scripts/model-tie.sh OUT_DIR") && export STAMP_LINE
python3 - "$rows" "$(git rev-parse --short HEAD)" "${RAYON_NUM_THREADS:-all}" <<'PY'
import re, statistics, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
print("# The model trial's tie rule (issue 63)")
print()
print(__import__("os").environ["STAMP_LINE"])
print()
print(f"Made by `bash scripts/model-tie.sh OUT_DIR` at {sys.argv[2]}, `RAYON_NUM_THREADS={sys.argv[3]}`. PSNR in dB "
      "against the better of the DCT alone and the screened ensemble alone (\"best\"), all without the baseline "
      "blend. \"default\": the lower of the pilots' two sums, unless they are within two standard errors of "
      "their paired differences (\"tied\"), then the model the mask and snapshot count favour (the DCT at pixel "
      "k > 1, the ensemble at pixel k = 1 and on the lenslet mask; none on the kronecker mask). \"lower\": the "
      "lower sum alone, the rule before. \"prior\": the favoured model on every frame.")
prior = {("pixel", "1"): "ensemble", ("pixel", "3"): "dct", ("lenslet", "3"): "ensemble"}
for group in dict.fromkeys(r[0] for r in rows):
    for setting in dict.fromkeys(r[1] for r in rows if r[0] == group):
        sel = [r for r in rows if r[0] == group and r[1] == setting]
        mask, k = setting.split(":")
        gaps = {"default": [], "lower": [], "prior": []}
        lines = []
        for _, _, scene, pd, pe, p, trial in sel:
            d, e, p = float(pd), float(pe), float(p)
            best = max(d, e)
            m = re.search(r"DCT ([\d.]+), ensemble ([\d.]+)", trial)
            lower = (d if float(m.group(1)) < float(m.group(2)) else e) if m else p
            fav = prior.get((mask, k))
            pr = (d if fav == "dct" else e) if fav else lower
            tied = "within their spread" in trial
            gaps["default"].append(p - best)
            gaps["lower"].append(lower - best)
            gaps["prior"].append(pr - best)
            pilots = f"{m.group(1)} / {m.group(2)}" if m else "none"
            lines.append(f"| {scene} | {d:.2f} | {e:.2f} | {pilots} | {'yes' if tied else ''} | {p - best:+.2f} | "
                         f"{lower - best:+.2f} |")
        def said(g):
            return f"{sum(x < -0.1 for x in g)} (worst {min(g):+.2f}, mean {statistics.mean(g):+.2f})"
        print()
        print(f"**{group}, {mask} k = {k}** ({len(sel)} scenes, {sum('within their spread' in r[6] for r in sel)} "
              f"tied). More than 0.1 dB under the best: default {said(gaps['default'])}, lower "
              f"{said(gaps['lower'])}, prior {said(gaps['prior'])}.")
        print()
        print("| scene | DCT | ensemble | pilots' RMS, DCT / ensemble | tied | default - best | lower - best |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
        print("\n".join(lines))
PY
