#!/usr/bin/env python3
"""The tables of docs/results-grid-halves.md from scripts/grid-halves.sh's rows (one or more
rows.tsv files, then the BEFORE binary's name): per row the aligned sensor's default decode,
the grid's with whole disparities, with the halves read at the cells' centres (before) and by
the cells' shares (after), each PSNR (interior) / SSIM / SA / seconds; a summary per k.

    python3 scripts/grid-halves-page.py OUT/rows.tsv [MORE/rows.tsv ...] BEFORE
"""
import statistics, sys

rows = [l.rstrip("\n").split("\t") for f in sys.argv[1:-1] for l in open(f) if l.strip()]
print(f"Before: `{sys.argv[-1]}`. Each cell: PSNR dB without the 2 edge lenslets / SSIM / SA")
print("degrees, then the decode's seconds (one run on a shared machine: compare within a row).")
print("*whole*: `--disparities -1:1` (the default behind a grid); *halves*: `-1:1:0.5` (the")
print("aligned sensor's default at k = 1), the shear trial on, *before* each half view read at the")
print("pixel under its cell's centre, *after* by the cells' shares, a half view's cell the mean of")
print("two grid positions. Calibrated sensors with 30 % vignetting, 1 % PRNU, shot and read noise,")
print("seed 1.")
print()
print("| scene | k | grid (deg:px) | aligned sensor | whole | halves before | halves after "
      "| after - before dB | after - whole dB |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
gains, wins = {}, {}
for scene, k, g, *v in rows:
    ref, whole, b, a = (x.split() for x in v[:4])
    cell = lambda x: f"{float(x[0]):.2f} / {float(x[1]):.4f} / {float(x[2]):.2f}, {x[3]} s"
    d, w = float(a[0]) - float(b[0]), float(a[0]) - float(whole[0])
    gains.setdefault(k, []).append(d)
    wins.setdefault(k, []).append(w)
    print(f"| {scene} | {k} | {g} | {cell(ref)} | {cell(whole)} | {cell(b)} | {cell(a)} | {d:+.2f} | {w:+.2f} |")
print()
print("## Summary")
print()
print("| k | decodes | halves after - before: worst / median / best dB | halves after - whole: worst / "
      "median / best dB | halves ahead of whole by more than 0.1 dB |")
print("| --- | --- | --- | --- | --- |")
for k in sorted(gains):
    g, w = gains[k], wins[k]
    print(f"| {k} | {len(g)} | {min(g):+.2f} / {statistics.median(g):+.2f} / {max(g):+.2f} | "
          f"{min(w):+.2f} / {statistics.median(w):+.2f} / {max(w):+.2f} | {sum(x > 0.1 for x in w)} of {len(w)} |")
