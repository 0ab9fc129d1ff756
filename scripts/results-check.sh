#!/usr/bin/env bash
# Makes a few figures of the results pages again and fails when one moved past its tolerance
# (issue 64; CI runs it, as it runs `budgets.sh --check` for the device's table). Each check
# below names a page, the table (the first after a line holding the marker), the row (its
# first cell), the column (its header) and how the figure is made: a scene rendered at a size,
# simulated with a mask, k and seed, decoded with the flags, and scored by `slf eval` (PSNR,
# dB). A page whose figures the current decode no longer gives is stale: make it again with
# its script (its stamp names the command) or, if the change was meant, move the check.
#
#   bash scripts/results-check.sh [OUT_DIR]
#
# The checks run on 48 x 48-lenslet scenes: under a minute on 2 cores after the build.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/results-check}
mkdir -p "$out"
cargo build --release -q -p slf-host
SLF_BIN=${SLF_BIN:-./target/release/slf} python3 - "$out" <<'PY'
import os, re, subprocess, sys

out, slf = sys.argv[1], os.environ["SLF_BIN"]
TOLERANCE = 0.011  # dB: the pages print two decimals
TIE = "**48 x 48, seed 1, with the real crops, pixel k = 1**"
BLEND = "**kronecker k = 3**"
# page, marker, row, column, scene, size, mask:k, seed, decode flags
CHECKS = [
    ("results-model-tie.md", TIE, "smooth", "DCT", "smooth", 48, "pixel:1", 1, "--baseline-blend false --dictionary dct"),
    ("results-model-tie.md", TIE, "smooth", "ensemble", "smooth", 48, "pixel:1", 1, "--baseline-blend false --model-trial false"),
    ("results-model-tie.md", TIE, "depth", "DCT", "depth", 48, "pixel:1", 1, "--baseline-blend false --dictionary dct"),
    ("results-model-tie.md", TIE, "depth", "ensemble", "depth", 48, "pixel:1", 1, "--baseline-blend false --model-trial false"),
    ("results-baseline-blend.md", BLEND, "smooth", "blend", "smooth", 48, "kronecker:3", 1, ""),
    ("results-baseline-blend.md", BLEND, "smooth", "decode", "smooth", 48, "kronecker:3", 1, "--baseline-blend false"),
    ("results-baseline-blend.md", BLEND, "smooth", "PPID", "smooth", 48, "kronecker:3", 1, "--method ppid"),
]


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


def run(*args):
    return subprocess.run([slf, *args], check=True, capture_output=True, text=True).stdout


def psnr(scene, size, setting, seed, flags):
    lf = os.path.join(out, f"{scene}-{size}.npy")
    if not os.path.exists(lf):
        run("scene", scene, "--size", str(size), "-o", lf)
    mask, k = setting.split(":")
    cap = os.path.join(out, f"cap-{scene}-{size}-{mask}-{k}-{seed}")
    if not os.path.isdir(cap):
        run("simulate", lf, "-o", cap, "--mask", mask, "-s", k, "--seed", str(seed))
    rec = os.path.join(out, "rec.npy")
    run("decode", cap, "-o", rec, "--quiet", *flags.split())
    return float(re.search(r"^PSNR\s+([-\d.]+)", run("eval", lf, rec), re.M).group(1))


moved = 0
print("| page | row | column | page says | made now | difference |")
print("| --- | --- | --- | --- | --- | --- |")
for page, marker, row, column, scene, size, setting, seed, flags in CHECKS:
    want = cell(page, marker, row, column)
    have = psnr(scene, size, setting, seed, flags)
    bad = abs(have - want) > TOLERANCE
    moved += bad
    print(f"| {page} | {row} | {column} | {want:.2f} | {have:.2f} | {have - want:+.2f}{' MOVED' if bad else ''} |")
if moved:
    sys.exit(f"{moved} figure(s) moved past {TOLERANCE} dB: make the page again with the command its stamp names")
print(f"every figure within {TOLERANCE} dB of its page")
PY
