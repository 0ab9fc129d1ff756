#!/usr/bin/env python3
"""Two decodes of one capture against the truth: each alone, their mean, and the per-block
oracle (each block of 5 x 5 lenslets from the decode nearer the truth there); issue 63's
question whether a choice per block or a blend beats the better decode of the frame.

    python3 scripts/model-blend.py TRUTH.npy A.npy B.npy

Prints `A B mean oracle5 oracle10` PSNRs (dB, data range the truth's maximum, as `slf eval`).
Needs numpy (`pip install numpy`)."""
import sys

import numpy as np


def main():
    t, a, b = (np.load(p).astype(np.float64) for p in sys.argv[1:4])
    assert t.shape == a.shape == b.shape and t.ndim == 5, (t.shape, a.shape, b.shape)
    peak = t.max()

    def psnr(x):
        return 10 * np.log10(peak ** 2 / np.mean((x - t) ** 2))

    # Each lenslet's squared error, (H, W): the light fields are (U, V, H, W, bands).
    ea, eb = (((x - t) ** 2).mean(axis=(0, 1, 4)) for x in (a, b))

    def oracle(s):
        pick = np.zeros(ea.shape, bool)
        for i in range(0, ea.shape[0], s):
            for j in range(0, ea.shape[1], s):
                pick[i:i + s, j:j + s] = ea[i:i + s, j:j + s].sum() < eb[i:i + s, j:j + s].sum()
        return psnr(np.where(pick[None, None, :, :, None], a, b))

    print(f"{psnr(a):.3f} {psnr(b):.3f} {psnr(0.5 * (a + b)):.3f} {oracle(5):.3f} {oracle(10):.3f}")


if __name__ == "__main__":
    main()
