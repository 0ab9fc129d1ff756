#!/usr/bin/env python3
"""The error of a decoded disparity map (`slf decode --disparity-map MAP.npy`) against a
ground-truth disparity map, as in docs/results-depth.md.

    python3 scripts/disparity-error.py MAP.npy TRUTH.npy [--offset ROW,COL] [--border N]
        [--range=MIN:MAX[:STEP]]

MAP is the decoder's per-lenslet map (rows x cols, float32); TRUTH the scene's disparity
in the same pixels per view, of which MAP covers the window at OFFSET (the crop the light
field was cut from; scripts/real-eval.sh's 128 x 128 crops are the centre of the 256 x 256
imports: --offset 64,64). N lenslets of border are left out (edge blocks fall back to fewer
views). RANGE is the search's (default -1:1:1): the last column counts the lenslets whose
map, rounded to the search's step, equals the truth rounded to that step and clipped to
the range, so it reads as "chose the candidate nearest the truth".

Prints one markdown table row: the truth's range, mean absolute error, the share within
0.25 and 0.5, and that agreement.
"""
import argparse
import sys

import numpy as np


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("map")
    p.add_argument("truth")
    p.add_argument("--offset", default="0,0")
    p.add_argument("--border", type=int, default=5)
    p.add_argument("--range", default="-1:1:1")
    a = p.parse_args()
    m = np.load(a.map).astype(np.float64)
    t = np.load(a.truth).astype(np.float64)
    if m.ndim != 2 or t.ndim != 2:
        sys.exit(f"error: maps must be 2-D (map {m.shape}, truth {t.shape})")
    r0, c0 = (int(x) for x in a.offset.split(","))
    rows, cols = m.shape
    if r0 + rows > t.shape[0] or c0 + cols > t.shape[1]:
        sys.exit(f"error: a {m.shape} map at {r0},{c0} lies outside the {t.shape} truth")
    t = t[r0:r0 + rows, c0:c0 + cols]
    b = a.border
    if 2 * b >= min(rows, cols):
        sys.exit(f"error: a border of {b} leaves nothing of a {m.shape} map")
    m, t = m[b:rows - b, b:cols - b], t[b:rows - b, b:cols - b]
    parts = [float(x) for x in a.range.split(":")]
    lo, hi = parts[0], parts[1]
    step = parts[2] if len(parts) > 2 else 1.0
    err = np.abs(m - t)
    quant = lambda x: np.round(x / step) * step
    agree = quant(m) == np.clip(quant(t), lo, hi)
    print(f"| {t.min():.2f}..{t.max():.2f} | {err.mean():.3f} | {100 * (err <= 0.25).mean():.1f} % "
          f"| {100 * (err <= 0.5).mean():.1f} % | {100 * agree.mean():.1f} % |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
