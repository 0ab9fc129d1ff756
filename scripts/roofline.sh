#!/usr/bin/env bash
# The roofline page (issue 62): the decode's arithmetic beside what the machine can do, on one
# host core and on the device, and where the time goes, measured.
#
# 1. The kernels of a solve step on one core (host-sim/examples/roofline.rs): synthesis,
#    analysis and the one-hot projection of the full-view patch, with the DCT and with an
#    ensemble member; achieved multiply-adds a second and a cycle, beside the core's peak
#    (the clock measured by a chain of dependent multiplies; 16 multiply-adds a cycle: AVX2,
#    two 8-lane pipes).
# 2. Decodes of a few scenes (SLF_SCENES, default "depth office canopy" at SLF_SIZE 64 lenslets)
#    at pixel k = 1 and 3 (SLF_SETTINGS) by the default and the preview, one thread, under
#    `perf record --call-graph dwarf`: seconds a patch, solves and steps a patch, the
#    multiply-adds those steps stand for, and the share of the samples by kind of work
#    (scripts/roofline-kinds.py), with the demosaic's time beside.
# 3. The device: instructions a transform multiply-add and a patch, from docs/device.md's budget
#    table (written by `bash scripts/budgets.sh --write`; CI checks it within 3 %), and where a
#    patch's instructions go (scripts/device-profile.sh, where qemu-system-arm is installed).
#
#   bash scripts/roofline.sh OUT_DIR > docs/results-roofline.md
#   SLF_SCENES="depth" SLF_SETTINGS="pixel:1" bash scripts/roofline.sh OUT_DIR
#
# Needs perf (Debian's linux-perf) where the decodes are profiled.
set -euo pipefail
out=${1:?usage: roofline.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
SLF_SIZE=${SLF_SIZE:-64} SLF_SCENES=${SLF_SCENES:-depth office canopy} table_setup
settings=${SLF_SETTINGS:-pixel:1 pixel:3}
export RAYON_NUM_THREADS=1
cargo build --release -q -p slf-host --example roofline
kernels="$out/kernels.txt"
./target/release/examples/roofline > "$kernels"
val() { awk -v k="$1" '$1 == k { print $2 }' "$kernels"; }
ghz=$(val clock_ghz); peak=$(val peak_gmacs); tmacs=$(val transform_macs)
# The kernels' mean share of the core's peak (synthesis, analysis, projection; both dictionaries).
kernel_peak=$(awk '$2 == "ns" && $4 == "macs" { s += $11; n++ } END { printf "%.3f", s / n }' "$kernels")

page_head "Roofline: the decode's arithmetic beside the machine's peak" "bash scripts/roofline.sh OUT_DIR"
echo "Made by \`bash scripts/roofline.sh OUT_DIR\` ($(date -u +%Y-%m-%d), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs),"
echo "one thread, the release build for x86-64-v3). Issue 62: how far the decode is from what the"
echo "machines can do, and where its time goes."
echo
echo "## The machines"
echo
echo "| machine | clock | peak multiply-adds a cycle | peak a second |"
echo "| --- | --- | --- | --- |"
printf '| host: one core | %.2f GHz (measured: dependent xor + imul, 4 cycles a link) | 16 (AVX2: two 8-lane pipes; a multiply-add is a multiply and an add, Rust never fuses them) | %.1f G |\n' "$ghz" "$peak"
echo "| device: Cortex-M7 (STM32H743 class) | 480 MHz | 1 (one f32 multiply-add a cycle, a load dual-issued beside it) | 0.48 G |"
echo
echo "## The kernels of a solve step, one host core"
echo
echo "The full-view patch (5 x 5 x 5 x 5 x 13, N = 8,125), random coefficients; the one-hot"
echo "projection at pixel k = 1 ($(val measurements) measurements, one a pixel). Multiply-adds as a separable"
echo "transform needs them (the DCT's mode products fold mirrored rows and do about half the"
echo "multiplies; counted unfolded). Median of 9 rounds (\`cargo run --release -p slf-host --example roofline\`)."
echo
echo "| kernel | dictionary | us a call | multiply-adds | G a second | a cycle | of the core's peak |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
awk '$2 == "ns" && $4 == "macs" {
    split($1, p, "_"); printf "| %s | %s | %.1f | %d | %.2f | %.2f | %.1f %% |\n", p[1], p[2], $3 / 1000, $5, $7, $9, 100 * $11
  }' "$kernels"
awk '$1 == "ascent" { printf "| ascent (the weights exp(-s^2 / 2 sigma^2) and the step) | both | %.1f | (%.2f ns a coefficient) | | | |\n", $3 / 1000, $5 }' "$kernels"
echo
echo "## Decodes: where the time goes"
echo
echo "Scenes of ${size} x ${size} lenslets, 5 x 5 views, \`slf simulate --seed 1\`; one decode each"
echo "under \`perf record -F 499 --call-graph dwarf\`, its seconds from its own summary (perf's"
echo "sampling costs a few per cent). Steps are as the decode's summary counts them: the last solve's"
echo "of each patch, so the multiply-adds below are a lower bound: steps x the one-hot projection's"
echo "($(val projection_macs | cut -d. -f1) at k = 1; 26 more a measurement) + solves x a synthesis and an analysis"
echo "($((2 * ${tmacs%.*})))."
echo
echo "The last column is Amdahl's bound on the kernels alone: the decode's time left were its"
echo "projections and transforms (their share of its samples, below) to run at the core's peak"
echo "instead of the kernels' measured mean of $(awk -v x="$kernel_peak" 'BEGIN { printf "%.0f", 100 * x }') % of it."
echo
echo "| scene | setting | decode | s / demosaic's | ms a patch | solves / steps a patch | M multiply-adds a patch (at least) | G a second | of the core's peak | time left, kernels at peak |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
shares="$out/shares.txt"
: > "$shares"
for token in $scenes; do
  scene_light_field "$token"
  for s in $settings; do
    scene_capture "$s" 1
    "$slf" decode "$cap" -o "$out/dem.npy" --quiet --method demosaic > "$out/dem.log"
    tdem=$(awk '/ in [0-9.]+ s/ { for (i = 1; i < NF; i++) if ($i == "in") print $(i + 1) }' "$out/dem.log")
    for preset in default preview; do
      perf record -q -F 499 --call-graph dwarf,16384 -o "$out/perf.data" \
        "$slf" decode "$cap" -o "$out/rec.npy" --quiet --preset "$preset" > "$out/dec.log" 2> /dev/null
      perf script --no-inline -i "$out/perf.data" 2> /dev/null | python3 scripts/roofline-kinds.py > "$out/kinds.txt"
      python3 - "$out/dec.log" "$out/kinds.txt" "$tdem" "$ghz" "$peak" "$(val projection_macs)" "$tmacs" \
        "$scene" "$mask k=$k" "$preset" "$k" "$kernel_peak" >> "$shares" <<'PY'
import re, sys
log, kinds, tdem, ghz, peak, proj1, tmacs, scene, setting, preset, k, kernel_peak = sys.argv[1:13]
text = open(log).read()
t = float(re.search(r" in ([0-9.]+) s", text).group(1))
patches = int(re.search(r"decoded (\d+) patches", text).group(1))
solves, steps = (int(x) for x in re.search(r"sl0: (\d+) solves, (\d+) steps", text).groups())
# The projection's multiply-adds at k measurements a pixel: 26 a measurement past the first.
proj = float(proj1) + 26 * 625 * (int(k) - 1)
macs = (steps * proj + solves * 2 * float(tmacs)) / patches
rate = macs * patches / t / 1e9
kinds = [l.rstrip("\n").split("\t") for l in open(kinds)]
kinds = [(k, float(v)) for k, v in (p for p in kinds if len(p) == 2)]
kernels = sum(v for k, v in kinds if "projection" in k or k.startswith("transforms"))
left = 1 - kernels * (1 - float(kernel_peak))
print(f"ROW | {scene} | {setting} | {preset} | {t / float(tdem):.0f} | {1000 * t / patches:.2f} | "
      f"{solves / patches:.2f} / {steps / patches:.1f} | {macs / 1e6:.1f} | {rate:.2f} | {100 * rate / float(peak):.1f} % | "
      f"{100 * left:.0f} % |")
for k, v in kinds:
    print(f"KIND\t{preset}\t{scene} {setting}\t{k}\t{v}")
PY
      grep '^ROW ' "$shares" | tail -1 | sed 's/^ROW //'
    done
  done
done
echo
echo "Share of each decode's samples by kind of work (\`scripts/roofline-kinds.py\`: a sample counts for"
echo "the first function from the leaf up that names a kind, so an inlined mode product counts for the"
echo "projection or transform that runs it, and memset or an iterator for its caller):"
echo
python3 - "$shares" <<'PY'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.startswith("KIND\t")]
for preset in ("default", "preview"):
    cases = []
    for _, p, case, _, _ in rows:
        if p == preset and case not in cases:
            cases.append(case)
    share = {(c, k): float(v) for _, p, c, k, v in rows if p == preset}
    kinds = sorted({k for (_, k) in share}, key=lambda k: -sum(share.get((c, k), 0) for c in cases))
    print(f"**{preset}**\n")
    print("| kind | " + " | ".join(cases) + " |")
    print("| --- |" + " --- |" * len(cases))
    for k in kinds:
        print(f"| {k} | " + " | ".join(f"{100 * share.get((c, k), 0):.1f} %" for c in cases) + " |")
    print()
PY
echo "## The device"
echo
echo "From docs/device.md's budget table (\`bash scripts/budgets.sh --write\`, qemu's Cortex-M7 counting"
echo "instructions; CI checks it within 3 %). At one instruction a cycle (the M7 dual-issues, so a"
echo "cycle can hold more), an instruction a multiply-add is the device's peak:"
echo
echo "| measure | instructions | a multiply-add | at 480 MHz |"
echo "| --- | --- | --- | --- |"
python3 - docs/device.md "$tmacs" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
tmacs = float(sys.argv[2])
def row(pattern):
    m = re.search(r"^\| " + pattern + r"[^|]*\| ([0-9,]+)", text, re.M)
    return int(m.group(1).replace(",", "")) if m else None
t = row(r"instructions per transform")
if t:
    print(f"| one transform ({int(tmacs):,} multiply-adds) | {t:,} | {t / tmacs:.2f} | {t / 480e3:.2f} ms (at peak {tmacs / 480e3:.2f} ms) |")
for label, pattern in [("a patch, 5D DCT", r"instructions per patch, 5D DCT "),
                       ("a patch, screened ensemble", r"instructions per patch, ensemble \(8 members\), screened")]:
    n = row(pattern)
    if n:
        print(f"| {label} | {n:,} | | {n / 480e3:.0f} ms |")
PY
echo
if command -v qemu-system-arm > /dev/null; then
  echo "### Where the device's instructions go"
  echo
  echo "\`bash scripts/device-profile.sh\`: the counting plugin's profile of one tile (a full-view"
  echo "patch) of the device binary, per function of the binary and per innermost source function."
  echo
  bash scripts/device-profile.sh
  echo
fi
echo "## Against issue 62's targets"
echo
python3 - "$shares" docs/device.md "$kernel_peak" <<'PY'
import re, statistics, sys
KERNEL_PEAK = float(sys.argv[3])
rows = [l[4:].strip().strip("|").split("|") for l in open(sys.argv[1]) if l.startswith("ROW ")]
rows = [[c.strip() for c in r] for r in rows]
readme = open(sys.argv[2]).read()
for preset, target in (("default", 10), ("preview", 3)):
    rs = [r for r in rows if r[2] == preset]
    if not rs:
        continue
    ratio = [float(r[3]) for r in rs]
    left = [float(r[9].rstrip(" %")) / 100 for r in rs]
    print(f"- **{preset}**: {min(ratio):.0f} to {max(ratio):.0f} times the demosaic's time here (median "
          f"{statistics.median(ratio):.0f}); the target of {target}x needs {min(ratio) / target:.1f} to "
          f"{max(ratio) / target:.1f} times less time. The kernels at the core's peak would leave "
          f"{100 * min(left):.0f} to {100 * max(left):.0f} % of it ({1 / max(left):.2f} to {1 / min(left):.2f} times "
          f"faster): the rest of each step (the ascent's weights, the strip, the reads, the solver's "
          f"bookkeeping) and the number of steps must fall too.")
    # The arithmetic's own bound: this decode's multiply-adds at the core's full peak.
    at_peak = [float(r[3]) * float(r[8].rstrip(" %")) / 100 for r in rs]
    print(f"  Its arithmetic alone (the multiply-adds a patch above, at least) at 100 % of the core's peak "
          f"would take {min(at_peak):.1f} to {max(at_peak):.1f} times the demosaic's time: to meet {target}x the "
          f"whole decode would have to run at {100 * min(at_peak) / target:.0f} to {100 * max(at_peak) / target:.0f} % "
          f"of the peak (it runs at {min(float(r[8].rstrip(' %')) for r in rs):.1f} to "
          f"{max(float(r[8].rstrip(' %')) for r in rs):.1f} %, its kernels alone at {100 * KERNEL_PEAK:.0f} %)"
          + (", more than the machine has: the target needs fewer multiply-adds, not faster ones."
             if max(at_peak) > target else "."))
macs = statistics.median(float(r[6]) for r in rows if r[2] == "default") if rows else 0
m = re.search(r"^\| instructions per patch, ensemble \(8 members\), screened[^|]*\| ([0-9,]+)", readme, re.M)
if m and macs:
    n = int(m.group(1).replace(",", ""))
    print(f"- **device**: a default patch's arithmetic (the median above, {macs:.1f} M multiply-adds, at "
          f"least) at one multiply-add a cycle is {1000 * macs * 1e6 / 480e6:.0f} ms at 480 MHz; the device's "
          f"screened patch (the budget table's, a disjoint patch's cold solve and screen) takes {n / 1e6:.1f} M "
          f"instructions ({1000 * n / 480e6:.0f} ms at one a cycle), {n / (macs * 1e6):.1f} instructions a "
          f"multiply-add of that arithmetic.")
solves = re.search(r"the host's default \(stride 2, seeded\), screened ensemble \(([0-9,]+) patch solves", readme)
if solves and rows:
    per_solve = statistics.median(float(r[6]) / float(r[5].split("/")[0]) for r in rows if r[2] == "default")
    n = int(solves.group(1).replace(",", ""))
    secs = n * per_solve * 1e6 / 480e6
    print(f"- **device frame**: the 100 x 100-lenslet frame's {n:,} patch solves (docs/device.md's budget table) at "
          f"{per_solve:.1f} M multiply-adds a solve (the median default's, at least) take {secs:.0f} s at one "
          f"multiply-add a cycle at 480 MHz: the target of 60 s needs {100 * secs / 60:.0f} % of that peak"
          + (", more than the core has." if secs > 60 else "."))
PY
echo
echo "Fused multiply-adds, the device's cheapest lever (one VFMA.F32 instead of a VMUL and a VADD):"
echo "\`f32::mul_add\` is not in \`core\` on stable Rust, and libm's \`fmaf\` on 32-bit Arm is its"
echo "generic software routine; so the M7's VFMA needs \`core::arch::asm!\`, the crate's first"
echo "\`unsafe\`, on both sides at once (fused sums round differently: device = host holds only if"
echo "the host fuses the same multiply-adds, \`vfmadd\` under x86-64-v3)."
