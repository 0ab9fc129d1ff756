#!/usr/bin/env bash
# The bound behind a turned lenslet array (issue 66), docs/results-grid-bound.md: for each
# scene, k = 1 and 3 (pixel mask) and each grid, 16 disjoint 5 x 5-lenslet full-view
# patches of a noiseless 16-bit capture decoded in f64 from the aligned sensor's
# measurements, from the grid's read as the decoder reads them (nearest: the pixel under
# each view cell's centre), and from the grid's with the exact box-share model, by SL0 and
# by the oracle (least squares on the truth's largest DCT coefficients). Everything is
# `host-sim/examples/grid_model.rs`; this script runs it over scenes and writes the page.
#
#   bash scripts/grid-bound.sh > docs/results-grid-bound.md
#   SLF_SCENES=office SLF_KS=3 SLF_GRIDS=0.3:5.04 bash scripts/grid-bound.sh   # faster
#   SLF_NOISE=1 bash scripts/grid-bound.sh > docs/results-grid-bound-noise.md
#
# With SLF_NOISE=1 the captures carry the decode tables' sensor noise (`grid_model
# --noise`) and only the oracles are found: what the light loses behind the grid when the
# measurements are as noisy as the decodes' (7 minutes a scene and k on 2 cores).
#
# HCI crops (`SLF_REAL`, default /tmp/hci/real/*_128.npy, made as scripts/scene-tables.sh
# says) are added where present: evaluation only, never committed.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host --example grid_model
bin=./target/release/examples/grid_model
scenes=${SLF_SCENES:-outdoor tungsten office led}
for f in "${SLF_REAL:-/tmp/hci/real}"/*_128.npy; do
  [ -f "$f" ] && scenes="$scenes $f"
done
ks=${SLF_KS:-1 3}
read -r -a grids <<< "${SLF_GRIDS:-0.3:5.04 1:5.1}"

noise=()
if [ "${SLF_NOISE:-0}" = 1 ]; then
  noise=(--noise)
  page_head "The bound behind a turned lenslet array, with the decodes' noise" "SLF_NOISE=1 bash scripts/grid-bound.sh"
  cat <<'TEXT'
What the light itself loses behind a turned array when the measurements are as noisy as the
decodes' (issue 66). The patches, scenes and grids of `docs/results-grid-bound.md`, whose
frames are noiseless; here each frame (16 bits) carries the sensor noise of the decode tables
(`scripts/scene-tables.sh`: shot noise of a 20,000-electron well, 2 DN of read noise on a
12-bit range 90 % full, scaled to the 16-bit frame), the aligned sensor's and the grid's
alike. Only the oracle is found (least squares on the truth's K largest DCT coefficients,
the best K from m/8 to m, in f64), for the aligned sensor's measurements and for the grid's
with the exact box-share model. PSNR in dB over the 16 patches' values together, peak the
light field's maximum.

TEXT
else
page_head "The bound behind a turned lenslet array" "bash scripts/grid-bound.sh"
cat <<'TEXT'
How much of the turned array's loss is the light's, and how much the decoder's (issue 66)?
Each row: 16 disjoint 5 x 5-lenslet full-view patches (25 x 25 view cells x 13 bands), 4 x 4
spread over the scene the decode tables decode (a realistic scene at 64 x 64 lenslets, an HCI
crop whole), pixel mask, noiseless 16-bit frames, decoded in f64. PSNR in dB over the patches'
values together, peak the light field's maximum.

- **aligned**: the aligned sensor's capture (each pixel one view cell's value);
- **nearest**: the grid's capture read as the decoder reads it today (each view cell from the
  pixel under its centre, taken as that cell's value);
- **exact**: the grid's capture with each pixel's measurement the shares of the view cells
  its square covers (`sim/footprint.rs`, the simulator's own model), pixels reaching outside
  the patch left out.
- **SL0**: the hand-set schedule on the 5D DCT, grey-world balanced, projecting onto the
  patch's own measurements `M x = y` by solving `(M M^T) z = M x - y`: exactly (Cholesky),
  by the firmware's step today (each residual over its row of `M M^T` summed,
  `solver/shares.rs`: exact for a measurement alone), or by 4 conjugate-gradient steps
  preconditioned by those row sums.
- **oracle**: least squares on the truth's K largest DCT coefficients, the best K from m/8
  to m (m measurements). SL0 beats it on some rows: it is the field's oracle-support
  reference, not a strict bound; where SL0 is above it, SL0 is the better figure.

"exact - aligned, oracle" is what the light itself loses behind the grid; "nearest -
aligned, SL0" is what a selection loses; "row-sum - aligned" what the firmware's step loses
on the exact model; "exact - aligned, SL0" what is left with the exact projection.

TEXT
fi
table=$(mktemp)
trap 'rm -f "$table"' EXIT
first=1
for scene in $scenes; do
  for k in $ks; do
    if [ $first = 1 ]; then
      "$bin" "$scene" "$k" "${grids[@]}" "${noise[@]}"
      first=0
    else
      "$bin" "$scene" "$k" "${grids[@]}" "${noise[@]}" | tail -n +3
    fi
  done
done | tee "$table"
echo
python3 scripts/grid-bound-summary.py "$table"
