#!/usr/bin/env python3
"""Where a decode's time goes, by kind of work (issue 62's roofline): reads `perf script`
output of a `perf record --call-graph dwarf` run and attributes each sample to the first
frame, from the leaf up, whose function names a kind (so the generic iterator folds, memset
and memcpy count for the code that called them). Prints `kind share` lines, shares of all
samples, largest first.

    perf script -i perf.data | python3 scripts/roofline-kinds.py
"""
import re
import sys

# (kind, pattern on the demangled function name), first match wins; checked from the
# sample's leaf frame up.
KINDS = [
    ("ascent (the SL0 step's weights)", r"solver::ascent::"),
    ("half-pixel projection", r"solver::fractional::"),
    ("grid shares projection", r"solver::shares::"),
    ("mixing projection", r"solver::mixing::"),
    ("projection (one-hot)", r"solver::projection::"),
    ("transforms (synthesis, analysis)", r"operators::transform::"),
    ("screen (choosing a member)", r"solver::choice::ChoiceRule|choice::screen"),
    ("estimate (held-out)", r"solver::holdout::"),
    ("plausibility", r"solver::plausible::"),
    ("disparity choice", r"choose_disparity|operators::disparity::"),
    ("measurements read (mask, frame)", r"sensor::mask::|sensor::raw::|sensor::source::|read_patch|TileDecoder.*::read"),
    ("strip (sums, seeds, rows)", r"decode::strip::|decode::tile_sums::|decode::engine::|FrameSeed|io::npy_rows|io::rows::"),
    ("solver, rest", r"solver::sl0::|solver::"),
    ("tile decoder, rest", r"decode::tile::|decode::overlap::"),
    ("trials and plan", r"decode::trial::|decode::plan::"),
]
COMPILED = [(k, re.compile(p)) for k, p in KINDS]


def kind_of(frames):
    for name in frames:
        for kind, pattern in COMPILED:
            if pattern.search(name):
                return kind
    return "other (start-up, I/O, libc)"


def samples(lines):
    """Each sample's frames (function names, leaf first)."""
    frames = []
    for line in lines:
        if not line.strip():
            if frames:
                yield frames
            frames = []
            continue
        if line[0] in " \t":
            parts = line.split(None, 1)
            if len(parts) == 2:
                # "addr name+0xoff (dso)"
                name = parts[1].rsplit(" (", 1)[0]
                frames.append(re.sub(r"\+0x[0-9a-f]+$", "", name))
        else:
            if frames:
                yield frames
            frames = []
    if frames:
        yield frames


def main():
    counts = {}
    total = 0
    for frames in samples(sys.stdin):
        k = kind_of(frames)
        counts[k] = counts.get(k, 0) + 1
        total += 1
    if total == 0:
        sys.exit("no samples")
    print(f"samples {total}")
    for k, n in sorted(counts.items(), key=lambda kv: -kv[1]):
        print(f"{k}\t{n / total:.4f}")


if __name__ == "__main__":
    main()
