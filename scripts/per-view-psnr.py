#!/usr/bin/env python3
"""PSNR of a decoded light field per view, as a markdown table (rows the view rows, columns
the view columns), without BORDER lenslets at each edge; peak the truth's maximum over the
whole field (as `slf eval`).

    python3 scripts/per-view-psnr.py TRUTH.npy DECODE.npy [BORDER]
"""
import sys

import numpy as np

truth = np.load(sys.argv[1]).astype(np.float64)
decode = np.load(sys.argv[2]).astype(np.float64)
b = int(sys.argv[3]) if len(sys.argv) > 3 else 0
if truth.shape != decode.shape:
    sys.exit(f"shapes differ: {truth.shape} and {decode.shape}")
h, w = truth.shape[2:4]
err = (decode - truth)[:, :, b:h - b, b:w - b, :] ** 2
db = 10 * np.log10(truth.max() ** 2 / err.mean(axis=(2, 3, 4)))
print("| view row | " + " | ".join(f"column {v}" for v in range(db.shape[1])) + " |")
print("| --- |" + " --- |" * db.shape[1])
for u, row in enumerate(db):
    print(f"| {u} | " + " | ".join(f"{x:.1f}" for x in row) + " |")
