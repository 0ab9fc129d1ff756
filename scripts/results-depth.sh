#!/usr/bin/env bash
# The tables of docs/results-depth.md (issue 19): sheared decoding (`slf decode
# --disparities`) against the decode before it and the baselines, on the realistic set
# (three real light fields and slf's four realistic named scenes) and on slf's five
# synthetic test scenes, at pixel k = 1, pixel k = 3 and lenslet k = 3, at the default
# stride (3, tapered) and the capture's noise model. Per setting: PSNR per scene, then the
# means of PSNR / SSIM / SA and the decode's wall time summed over the scenes (one run, so
# the times compare; the machine is shared, so only their ratios mean anything).
#
#   bash scripts/results-depth.sh OUT_DIR > tables.md
#   SLF_MODELS="ensemble ensemble+halves" bash scripts/results-depth.sh OUT_DIR  # some rows
#   SLF_SETTINGS="pixel:1" SLF_MODELS="demosaic ppid preview default best" \
#     RAYON_NUM_THREADS=1 bash scripts/results-depth.sh OUT_DIR  # the presets, one thread
#   SLF_MODELS="demosaic ppid preview preview-before default default-before default-stride3 best best-before" \
#     RAYON_NUM_THREADS=1 bash scripts/results-depth.sh OUT_DIR  # the presets before and after issue 40
#
# The `-before` rows are the presets with the paper's patch as they were before issue 40 (4 x 4
# views, default stride 3, best stride 2); `default-stride3` the full-view patch at stride 3;
# the `-annealed` rows the presets with the hand-set schedule (before issue 42's trained one):
#   SLF_MODELS="demosaic ppid preview-annealed preview default-annealed default" \
#     RAYON_NUM_THREADS=1 bash scripts/results-depth.sh OUT > docs/results-schedule.md
#
# The real light fields are scripts/real-eval.sh's 128 x 128 crops, in $SLF_REAL (default
# /tmp/hci/real); their licence allows evaluation only.
set -euo pipefail
out=${1:?usage: results-depth.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host
slf=${SLF_BIN:-./target/release/slf}
hci=${SLF_REAL:-/tmp/hci/real}
mkdir -p "$out/lf"
for n in outdoor tungsten office led; do
  [ -f "$out/lf/$n.npy" ] || "$slf" scene "$n" --size 64 -o "$out/lf/$n.npy" > /dev/null
done
for n in smooth texture depth saturated dark; do
  [ -f "$out/lf/$n.npy" ] || "$slf" scene "$n" --size 40 -o "$out/lf/$n.npy" > /dev/null
done
# name=decode arguments (commas for spaces); SLF_MODELS picks some of them by name.
all="demosaic=--method,demosaic ppid=--method,ppid dct=--dictionary,dct,--disparities=0:0
dct+depth=--dictionary,dct,--disparities=-1:1 dct+halves=--dictionary,dct,--disparities=-1:1:0.5
ensemble=--disparities=0:0 ensemble+depth=--disparities=-1:1 ensemble+depth2=--disparities=-2:2
ensemble+halves=--disparities=-1:1:0.5
preview=--preset,preview default=--preset,default best=--preset,best
default-unseeded=--preset,default,--seeded,false best-unseeded=--preset,best,--seeded,false
preview-before=--preset,preview,--patch-views,4 default-before=--preset,default,--patch-views,4,--stride,3
best-before=--preset,best,--patch-views,4,--stride,2 default-stride3=--preset,default,--stride,3
preview-annealed=--preset,preview,--schedule,annealed default-annealed=--preset,default,--schedule,annealed
best-annealed=--preset,best,--schedule,annealed"
models=""
for m in $all; do
  case " ${SLF_MODELS:-${m%%=*}} " in *" ${m%%=*} "*) models="$models $m" ;; esac
done
table() {
  local dir=$1
  shift
  local header="| model | setting |" rule="| --- | --- |"
  for lf in "$@"; do header="$header $(basename "$lf" .npy) |"; rule="$rule --- |"; done
  echo "$header mean PSNR | mean SSIM | mean SA | seconds | patches | steps a patch |"
  echo "$rule --- | --- | --- | --- | --- | --- |"
  for s in ${SLF_SETTINGS:-pixel:1 pixel:3 lenslet:3}; do
    mask=${s%:*}; k=${s#*:}
    for m in $models; do
      name=${m%%=*}; args=${m#*=}; args=${args//,/ }
      row="| $name | $mask k=$k |"; sp=0; ss=0; sa=0; secs=0; n=0; patches=0; steps=0
      for lf in "$@"; do
        base=$(basename "$lf" .npy)
        cap="$dir/cap-$base-$mask-$k"
        [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask "$mask" -s "$k" --seed 3 > /dev/null
        rec="$dir/rec.npy"
        # shellcheck disable=SC2086
        log=$("$slf" decode "$cap" -o "$rec" --quiet $args)
        t=$(echo "$log" | awk '/ in [0-9.]+ s/ { for (i = 1; i < NF; i++) if ($i == "in") print $(i + 1) }')
        # Patches and SL0 steps (the CS methods' `sl0:` line; none for a baseline).
        read -r np ns < <(echo "$log" | awk '/^decoded / { p = $2 } /^sl0: / { s = $4 } END { print p + 0, s + 0 }')
        patches=$((patches + np)); steps=$((steps + ns))
        read -r p q a < <("$slf" eval "$lf" "$rec" | awk '/^PSNR/ { p = $2 } /^SSIM/ { q = $2 } /^SA/ { a = $2 } END { print p, q, a }')
        row="$row $p |"
        sp=$(echo "$sp + $p" | bc -l); ss=$(echo "$ss + $q" | bc -l); sa=$(echo "$sa + $a" | bc -l)
        secs=$(echo "$secs + ${t:-0}" | bc -l); n=$((n + 1))
      done
      if [ "$steps" -gt 0 ]; then per=$(echo "$steps / $patches" | bc -l); else per=0; fi
      printf '%s %.2f | %.4f | %.2f | %.2f | %d | %.1f |\n' "$row" "$(echo "$sp / $n" | bc -l)" \
        "$(echo "$ss / $n" | bc -l)" "$(echo "$sa / $n" | bc -l)" "$secs" "$patches" "$per"
    done
  done
}
stamp "bash scripts/results-depth.sh OUT_DIR"
echo
echo "## Realistic set"
echo
table "$out/real" "$hci/antinous_128.npy" "$hci/dino_128.npy" "$hci/cotton_128.npy" "$out/lf/outdoor.npy" \
  "$out/lf/tungsten.npy" "$out/lf/office.npy" "$out/lf/led.npy"
echo
echo "## Synthetic test scenes"
echo
table "$out/syn" "$out/lf/smooth.npy" "$out/lf/texture.npy" "$out/lf/depth.npy" "$out/lf/saturated.npy" \
  "$out/lf/dark.npy"
