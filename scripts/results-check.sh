#!/usr/bin/env bash
# Makes a few figures of the results pages again and fails when one moved past its tolerance
# (issue 64; CI runs it, as it runs `budgets.sh --check` for the device's table). Each check
# below names a page, the table (the first after a line holding the marker), the row (its
# first cell), the column (its header) and how the figure is made: a scene at 48 x 48
# lenslets, simulated with a mask, k and seed, decoded with the flags, and scored by
# `slf eval` (PSNR, dB), by the same helpers the table scripts use (scene-tables.sh). A page
# whose figures the current decode no longer gives is stale: make it again with its script
# (its stamp names the command) or, if the change was meant, move the check.
#
#   bash scripts/results-check.sh [OUT_DIR]
#
# Under a minute on 2 cores after the build.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
out=${1:-target/results-check}
table_setup
size=48
tie="**48 x 48, seed 1, with the real crops, pixel k = 1**"
blend="**kronecker k = 3**"
# page | marker | row | column | scene | mask:k | seed | decode flags
checks=(
  "results-model-tie.md|$tie|smooth|DCT|smooth|pixel:1|1|--baseline-blend false --dictionary dct"
  "results-model-tie.md|$tie|smooth|ensemble|smooth|pixel:1|1|--baseline-blend false --model-trial false"
  "results-model-tie.md|$tie|depth|DCT|depth|pixel:1|1|--baseline-blend false --dictionary dct"
  "results-model-tie.md|$tie|depth|ensemble|depth|pixel:1|1|--baseline-blend false --model-trial false"
  "results-baseline-blend.md|$blend|smooth|blend|smooth|kronecker:3|1|"
  "results-baseline-blend.md|$blend|smooth|decode|smooth|kronecker:3|1|--baseline-blend false"
  "results-baseline-blend.md|$blend|smooth|PPID|smooth|kronecker:3|1|--method ppid"
)
made="$out/made.tsv"
: > "$made"
for c in "${checks[@]}"; do
  IFS='|' read -r page marker row column name setting seed flags <<< "$c"
  scene_light_field "$name"
  scene_capture "$setting" "$seed"
  # shellcheck disable=SC2086 # the flags are words
  decode_eval "$cap" $flags
  printf '%s\t%s\t%s\t%s\t%s\n' "$page" "$marker" "$row" "$column" "$p" >> "$made"
done
python3 - "$made" <<'PY'
import os, sys

TOLERANCE = 0.011  # dB: the pages print two decimals


def cell(page, marker, row, column):
    """The figure a page gives: the table after `marker`, its `row`, its `column`."""
    lines = open(os.path.join("docs", page)).read().splitlines()
    start = next(i for i, l in enumerate(lines) if marker in l)
    table = []
    for line in lines[start + 1:]:
        if line.startswith("|"):
            table.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif table:
            break
    header = table[0]
    body = [r for r in table[2:] if r[0] == row]
    if not body or column not in header:
        sys.exit(f"{page}: no row {row!r} or column {column!r} in the table after {marker!r}")
    return float(body[0][header.index(column)])


moved = 0
print("| page | row | column | page says | made now | difference |")
print("| --- | --- | --- | --- | --- | --- |")
for line in open(sys.argv[1]):
    page, marker, row, column, have = line.rstrip("\n").split("\t")
    want, have = cell(page, marker, row, column), float(have)
    bad = abs(have - want) > TOLERANCE
    moved += bad
    print(f"| {page} | {row} | {column} | {want:.2f} | {have:.2f} | {have - want:+.2f}{' MOVED' if bad else ''} |")
if moved:
    sys.exit(f"{moved} figure(s) moved past {TOLERANCE} dB: make the page again with the command its stamp names")
print(f"every figure within {TOLERANCE} dB of its page")
PY
