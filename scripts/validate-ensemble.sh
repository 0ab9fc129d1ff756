#!/usr/bin/env bash
# Validation of ensemble candidates (issue 18): each model decodes the same captures of
# held-out light fields at pixel k = 1, pixel k = 3 and lenslet k = 3 (disjoint patches,
# the capture's noise model); prints PSNR per scene and the mean, as a markdown table.
#
#   bash scripts/validate-ensemble.sh OUT_DIR "name=BLOB ..." LIGHT_FIELD.npy ...
#
# BLOB is a blob file, or "dct" (the 5D DCT alone), or a baseline without compressed
# sensing: "demosaic", "ppid", "interpolate" (`slf decode --method`). A CS model ending in
# ":off" decodes without white balance (`--balance off`; the default balances each capture
# by its grey world). The light fields are held out: never training data of the
# candidates (the realistic named scenes use seeds below 1000; `slf train` renders seeds
# from 1000 up). Real light fields (e.g. the HCI crops of scripts/real-eval.sh) are
# for validation only: their licence forbids training what we ship.
#
# SLF_PATCH_VIEWS=4|5 decodes every CS model with that patch (`--patch-views`; a blob of the
# other patch is refused); unset, the DCT uses the decode's default and a blob its own patch:
#
#   SLF_PATCH_VIEWS=5 bash scripts/validate-ensemble.sh OUT \
#     "dct=dct fullview8=firmware/dictionaries/fullview8.slfd" LF.npy ...
set -euo pipefail
out=${1:?usage: validate-ensemble.sh OUT_DIR "name=BLOB ..." LF.npy ...}
models=${2:?models}
shift 2
cd "$(dirname "$0")/.."
. scripts/stamp.sh
cargo build --release -q -p slf-host
slf=./target/release/slf
mkdir -p "$out"
settings="pixel:1 pixel:3 lenslet:3"
header="| model |"
rule="| --- |"
for s in $settings; do
  for lf in "$@"; do header="$header $(basename "$lf" .npy) ${s/:/ k=} |"; rule="$rule --- |"; done
  header="$header mean ${s/:/ k=} |"; rule="$rule --- |"
done
stamp "bash scripts/validate-ensemble.sh OUT_DIR ..."
echo
echo "$header"
echo "$rule"
psnr() { "$slf" eval "$1" "$2" | awk '/PSNR/ { for (i = 1; i <= NF; i++) if ($i ~ /^[0-9.]+$/) { print $i; exit } }'; }
for m in $models; do
  name=${m%%=*}; blob=${m#*=}; extra=""
  case "$blob" in *:off) blob=${blob%:off}; extra="--balance off" ;; esac
  if [ -n "${SLF_PATCH_VIEWS:-}" ]; then extra="$extra --patch-views $SLF_PATCH_VIEWS"; fi
  row="| $name |"
  for s in $settings; do
    mask=${s%:*}; k=${s#*:}; sum=0; n=0
    for lf in "$@"; do
      base=$(basename "$lf" .npy)
      cap="$out/cap-$base-$mask-$k"
      [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask "$mask" -s "$k" --seed 3 > /dev/null
      rec="$out/rec.npy"
      case "$blob" in
        demosaic|ppid|interpolate) "$slf" decode "$cap" -o "$rec" --method "$blob" > /dev/null ;;
        dct) "$slf" decode "$cap" -o "$rec" --dictionary dct --stride 5 --window uniform $extra > /dev/null ;;
        *) "$slf" decode "$cap" -o "$rec" --blob "$blob" --stride 5 --window uniform $extra > /dev/null ;;
      esac
      p=$(psnr "$lf" "$rec")
      row="$row $p |"; sum=$(echo "$sum + $p" | bc -l); n=$((n + 1))
    done
    row="$row $(printf '%.2f' "$(echo "$sum / $n" | bc -l)") |"
  done
  echo "$row"
done
