#!/usr/bin/env bash
# Issue 63's first measurement: does a choice per block, or the mean of the two models'
# decodes, beat the better model of the frame? Every scene `slf scene` names and the real
# crops when present (SLF_REAL), at each setting of SLF_SETTINGS (default pixel k = 1 and 3,
# lenslet k = 3), one thread: each capture decoded by the DCT alone (`--dictionary dct`), by
# the screened ensemble alone (`--model-trial false`) and by the default (the model trial's
# pick for the frame); scripts/model-blend.py scores both models alone, their mean and the
# per-block oracle (blocks of 5 x 5 and 10 x 10 lenslets) against the truth.
#
#   SLF_PYTHON=VENV/bin/python bash scripts/model-blend.sh OUT_DIR > OUT.md   # numpy needed
set -euo pipefail
out=${1:?usage: model-blend.sh OUT_DIR}
py=${SLF_PYTHON:-python3}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
add_real_scenes
export RAYON_NUM_THREADS=1
rows="$out/blend.tsv"
: > "$rows"
row() {
  "$slf" decode "$cap" -o "$out/dct.npy" --dictionary dct --quiet > /dev/null
  "$slf" decode "$cap" -o "$out/ens.npy" --model-trial false --quiet > /dev/null
  local pick
  pick=$("$slf" decode "$cap" -o "$out/trial.npy" --quiet | sed -n 's/^model trial: decoded by the \([A-Za-z]*\) .*/\1/p')
  printf '%s\t%s\t%s\t%s\n' "$s" "$scene" "${pick:-none}" "$("$py" scripts/model-blend.py "$lf" "$out/dct.npy" "$out/ens.npy")" >> "$rows"
}
each_capture "${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}" 1 row
STAMP_LINE=$(stamp "bash scripts/model-blend.sh OUT_DIR") && export STAMP_LINE
"$py" - "$rows" "$size" "$(git rev-parse --short HEAD)" <<'PY'
import statistics, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
print("# A choice per block, or the mean, against the frame's better model (issue 63)")
print()
print(__import__("os").environ["STAMP_LINE"])
print()
print(f"Made by `bash scripts/model-blend.sh OUT_DIR` at {sys.argv[3]}: synthetic scenes at {sys.argv[2]} x "
      f"{sys.argv[2]} lenslets and the real crops, `slf simulate --seed 1`, one thread. PSNR in dB; \"best\" is "
      "the better of the DCT alone and the ensemble alone for the frame; the trial is the default's pick; the "
      "mean is the two decodes averaged; the oracle takes each block of 5 x 5 lenslets from the decode nearer "
      "the truth there (it needs the truth: an upper bound for a choice per block).")
for setting in dict.fromkeys(r[0] for r in rows):
    sel = []
    for s, scene, pick, scores in (r for r in rows if r[0] == setting):
        dct, ens, mean, o5, o10 = (float(x) for x in scores.split())
        best = max(dct, ens)
        trial = dct if pick == "DCT" else ens
        sel.append((scene, dct, ens, pick, trial - best, mean - best, o5 - best, o10 - best, abs(dct - ens)))
    mask, k = setting.split(":")
    print()
    print(f"**{mask} k = {k}** ({len(sel)} scenes): the trial's pick more than 0.1 dB under the best on "
          f"{sum(x[4] < -0.1 for x in sel)} (worst {min(x[4] for x in sel):+.2f}); the mean above the best on "
          f"{sum(x[5] > 0 for x in sel)}, more than 0.1 dB under it on {sum(x[5] < -0.1 for x in sel)} (worst "
          f"{min(x[5] for x in sel):+.2f}, mean {statistics.mean(x[5] for x in sel):+.2f}); where the models are "
          f"within 0.3 dB of each other the mean gains {min([x[5] for x in sel if x[8] < 0.3] or [0]):+.2f} to "
          f"{max([x[5] for x in sel if x[8] < 0.3] or [0]):+.2f}; the per-block oracle {statistics.mean(x[6] for x in sel):+.2f} "
          "on average.")
    print()
    print("| scene | DCT | ensemble | trial's pick - best | mean - best | oracle 5 x 5 - best | oracle 10 x 10 - best |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for x in sorted(sel, key=lambda x: x[8]):
        print(f"| {x[0]} | {x[1]:.2f} | {x[2]:.2f} | {x[4]:+.2f} ({x[3]}) | {x[5]:+.2f} | {x[6]:+.2f} | {x[7]:+.2f} |")
PY
