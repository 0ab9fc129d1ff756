#!/usr/bin/env bash
# How well `slf calibrate` finds the lenslet grid (issue 52): for each rotation and pitch, a
# 100 x 100-lenslet sensor's calibration captures (shot and read noise as `slf simulate`
# makes them, 30 % vignetting, 1 % PRNU, 2 exposures of each kind) are calibrated, and the
# grid found is compared with the one simulated: rotation and pitch errors, the RMS
# distance between the two grids' micro-image centres over all lenslets, the found centres'
# own RMS residual about the fitted grid, and the calibration's time. Prints a markdown
# table; docs/results-grid.md's calibration table is its.
#
#   bash scripts/grid-calibration.sh OUT_DIR
set -euo pipefail
out=${1:?usage: grid-calibration.sh OUT_DIR}
cd "$(dirname "$0")/.."
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
size=${SLF_SIZE:-100}
vignetting=${SLF_VIGNETTING:-0.3}
mkdir -p "$out"
"$slf" scene smooth --size "$size" -o "$out/flat-scene.npy" > /dev/null
echo "| rotation deg | pitch px | rotation error deg | pitch error px | centres vs truth, RMS px | centres' residual, RMS px | calibrate s |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for rotation in 0 0.1 0.3 1; do
  for pitch in 4.9 5.0 5.02 5.1 5.2; do
    offset=()
    # The aligned grid is no grid: an offset of a quarter pixel keeps it one.
    if [ "$rotation" = 0 ] && [ "$pitch" = 5.0 ]; then offset=(--grid-offset 2.75,2.25); fi
    cap="$out/g-$rotation-$pitch" cc="$out/gc-$rotation-$pitch" cal="$out/gcal-$rotation-$pitch"
    rm -rf "$cap" "$cc" "$cal"
    "$slf" simulate "$out/flat-scene.npy" -o "$cap" --rotation "$rotation" --pitch "$pitch" "${offset[@]}" \
      --vignetting "$vignetting" --prnu 0.01 --calibration-captures "$cc" --exposures 2 > /dev/null
    start=$(date +%s.%N)
    "$slf" calibrate "$cc" -o "$cal" > /dev/null
    end=$(date +%s.%N)
    python3 - "$cap/capture.json" "$cal/calibration.json" "$rotation" "$pitch" "$start" "$end" <<'PY'
import json, math, sys
truth = json.load(open(sys.argv[1]))
found = json.load(open(sys.argv[2]))["lenslet_grid"]
t = truth["lenslet_grid"]
S, T = truth["lenslets"]
def centre(g, s, u):
    a = math.radians(g["rotation_deg"])
    d = (s * g["pitch"][0], u * g["pitch"][1])
    return (g["offset"][0] + d[0] * math.cos(a) + d[1] * math.sin(a), g["offset"][1] - d[0] * math.sin(a) + d[1] * math.cos(a))
sq = 0.0
for s in range(S):
    for u in range(T):
        p, q = centre(t, s, u), centre(found, s, u)
        sq += (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2
rms = math.sqrt(sq / (S * T))
rot = abs(found["rotation_deg"] - t["rotation_deg"])
pitch = max(abs(found["pitch"][i] - t["pitch"][i]) for i in range(2))
secs = float(sys.argv[6]) - float(sys.argv[5])
print(f"| {sys.argv[3]} | {sys.argv[4]} | {rot:.5f} | {pitch:.5f} | {rms:.4f} | {found['centres_rms_px']:.4f} | {secs:.1f} |")
PY
  done
done
