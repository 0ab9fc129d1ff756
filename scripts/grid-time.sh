#!/usr/bin/env bash
# Issue 66, the time behind a turned lenslet array (docs/results-grid-time.md): for each scene
# at pixel k = 1 and 3, the one-thread CPU seconds (user + system) of the decode behind grids
# of 0.3 degrees / 5.04 px and 1 degree / 5.1 px against the aligned sensor's, by the binary
# BEFORE (SLF_BEFORE) and by this one, each run SLF_REPS times (default 3) in turn, BEFORE and
# this one interleaved, the median kept. Three decodes a sensor: the default (whose model
# trial may pick another model behind the grid than on the aligned sensor), the DCT alone and
# the screened ensemble alone (`--dictionary`), so a ratio compares one model with itself.
# Beside each, PSNR without the 2 edge lenslets (`slf eval --border 2`), and whether BEFORE's
# light field is this one's bit for bit. Sensors as scripts/grid-shear.sh makes them: 30 %
# vignetting, 1 % PRNU, shot and read noise, calibrated from their own captures.
#
#   git worktree add /tmp/before e1207e3 && CARGO_TARGET_DIR=/tmp/before-target \
#     cargo build --release -p slf-host --manifest-path /tmp/before/Cargo.toml
#   SLF_BEFORE=/tmp/before-target/release/slf bash scripts/grid-time.sh OUT > docs/results-grid-time.md
#
# SLF_SCENES (default outdoor tungsten office led, 64 x 64 lenslets, and the HCI crops in
# SLF_REAL when present), SLF_KS (1 3), SLF_GRIDS (0.3:5.04 1:5.1), SLF_REPS (3).
# OUT/time-rows.tsv keeps each row. The page ends with scripts/grid-instructions.sh's table
# (instructions by callgrind), made by it here or read from SLF_COUNTS.
set -euo pipefail
out=${1:?usage: grid-time.sh OUT_DIR}
before=${SLF_BEFORE:?SLF_BEFORE: the binary to compare with}
reps=${SLF_REPS:-3}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
grid_table_setup
rows="$out/time-rows.tsv"
: > "$rows"
models="default dct ensemble"

# flags MODEL: the decode's flags for MODEL.
flags() {
  case $1 in
    default) ;;
    *) echo "--dictionary $1" ;;
  esac
}

# cpu BIN CALIBRATION CAPTURE OUTPUT FLAGS...: one-thread CPU seconds of BIN's decode into OUTPUT.
cpu() {
  local bin=$1 cal=$2 cap=$3 rec=$4
  shift 4
  RAYON_NUM_THREADS=1 /usr/bin/time -f "%U %S" -o "$out/time.txt" \
    "$bin" decode "$cap" -o "$rec" --quiet --calibration "$cal" "$@" > /dev/null
  awk '{ printf "%.3f\n", $1 + $2 }' "$out/time.txt"
}

# median: the median of the numbers on standard input.
median() {
  sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

for token in $scenes; do
  scene_light_field "$token"
  for k in $ks; do
    for g in $grids; do
      grid_captures "$k" "$g"
      for model in $models; do
        # shellcheck disable=SC2046 # the flags are words
        set -- $(flags "$model")
        : > "$out/t.tsv"
        for _ in $(seq "$reps"); do
          printf '%s\t%s\t%s\t%s\n' \
            "$(cpu "$before" "$cal_aligned" "$aligned" "$out/a0.npy" "$@")" \
            "$(cpu "$before" "$cal" "$cap" "$out/g0.npy" "$@")" \
            "$(cpu "$slf" "$cal_aligned" "$aligned" "$out/a1.npy" "$@")" \
            "$(cpu "$slf" "$cal" "$cap" "$out/g1.npy" "$@")" >> "$out/t.tsv"
        done
        times=""
        for col in 1 2 3 4; do
          times="$times	$(cut -f "$col" "$out/t.tsv" | median)"
        done
        same=no
        cmp -s "$out/a0.npy" "$out/a1.npy" && cmp -s "$out/g0.npy" "$out/g1.npy" && same=yes
        cp "$out/a1.npy" "$out/rec.npy"
        grid_scores
        pa=$psnr
        cp "$out/g1.npy" "$out/rec.npy"
        grid_scores
        printf '%s\t%s\t%s\t%s%s\t%s\t%s\t%s\n' "$scene" "$k" "$g" "$model" "$times" "$pa" "$psnr" "$same" >> "$rows"
      done
    done
  done
done

page_head "The time behind a lenslet grid" "SLF_BEFORE=... bash scripts/grid-time.sh OUT_DIR"
python3 scripts/grid-time-page.py "$rows" "$before" "$reps"
# The instructions: SLF_COUNTS names scripts/grid-instructions.sh's table when it was made
# apart (it takes about 20 minutes; callgrind's counts do not depend on the machine's load).
printf '\n## Instructions\n\n'
echo "Counted by callgrind in one-thread decodes (\`scripts/grid-instructions.sh\`), repeatable where"
echo "the seconds above are not: the same binaries, calibrated sensors as above at 32 x 32 lenslets,"
echo "the grid of 0.3 degrees / 5.04 px, each model against itself."
echo
if [ -n "${SLF_COUNTS:-}" ]; then
  cat "$SLF_COUNTS"
else
  bash scripts/grid-instructions.sh "$out/instructions"
fi
