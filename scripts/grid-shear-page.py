#!/usr/bin/env python3
"""The tables of docs/results-grid-shear.md from scripts/grid-shear.sh's rows (one or more
rows.tsv files, then the BEFORE binary's name): per row the aligned sensor's, the before and
the after decode's PSNR (interior) / SSIM / SA / seconds; a summary per k.

    python3 scripts/grid-shear-page.py OUT/rows.tsv [MORE/rows.tsv ...] BEFORE

SLF_ABOUT, when set, is the sentence that says what before and after are (default: the
change of docs/results-grid-shear.md).
"""
import os, statistics, sys

rows = [l.rstrip("\n").split("\t") for f in sys.argv[1:-1] for l in open(f) if l.strip()]
print(f"Before: `{sys.argv[-1]}`. Each cell: PSNR dB without")
print("the 2 edge lenslets / SSIM / SA degrees, then the decode's seconds (one run on a shared")
print("machine: compare within a row).")
print(os.environ.get("SLF_ABOUT") or
      "*before*: a patch sheared by whole lenslets behind the grid\n"
      "takes every pixel it reads as its measurement, a share of its square over a cell outside the\n"
      "patch given to the pixel's own cell; *after*: at k >= 2 it leaves out the pixels more than\n"
      "a quarter outside (`MAX_OUTSIDE_SHARE`, `firmware/src/solver/shares.rs`).")
print("Calibrated sensors with 30 % vignetting, 1 % PRNU, shot and read noise, seed 1.")
print()
print("| scene | k | grid (deg:px) | aligned sensor | before | after | after - before dB | after - aligned dB |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
gains, gaps = {}, {}
for scene, k, g, *v in rows:
    ref, b, a = v[0].split(), v[1].split(), v[2].split()
    cell = lambda x: f"{float(x[0]):.2f} / {float(x[1]):.4f} / {float(x[2]):.2f}, {x[3]} s"
    d, gap = float(a[0]) - float(b[0]), float(a[0]) - float(ref[0])
    gains.setdefault(k, []).append(d)
    gaps.setdefault(k, []).append((gap, float(b[0]) - float(ref[0])))
    print(f"| {scene} | {k} | {g} | {cell(ref)} | {cell(b)} | {cell(a)} | {d:+.2f} | {gap:+.2f} |")
print()
print("## Summary")
print()
print("| k | decodes | after - before: worst / median / best dB | against the aligned sensor, before: worst / median | after: worst / median |")
print("| --- | --- | --- | --- | --- |")
for k in sorted(gains):
    g = gains[k]
    after = [x for x, _ in gaps[k]]
    bef = [y for _, y in gaps[k]]
    print(f"| {k} | {len(g)} | {min(g):+.2f} / {statistics.median(g):+.2f} / {max(g):+.2f} | "
          f"{min(bef):+.2f} / {statistics.median(bef):+.2f} | {min(after):+.2f} / {statistics.median(after):+.2f} |")
