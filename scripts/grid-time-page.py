#!/usr/bin/env python3
"""The tables of docs/results-grid-time.md from scripts/grid-time.sh's rows.

    python3 scripts/grid-time-page.py ROWS.tsv BEFORE REPS

Each row: scene, k, grid, model, then the median one-thread CPU seconds of BEFORE's aligned
and grid decodes and of this binary's, PSNR (interior) of this binary's aligned and grid
decodes, and whether BEFORE's light fields are this one's bit for bit. The summary gives, per
model and k, the worst / median / best ratio of the grid decode's time to the aligned one's.
"""
import statistics
import sys

rows_path, before, reps = sys.argv[1], sys.argv[2], sys.argv[3]
rows = []
with open(rows_path) as f:
    for line in f:
        scene, k, grid, model, a0, g0, a1, g1, pa, pg, same = line.rstrip("\n").split("\t")
        rows.append((scene, int(k), grid, model, float(a0), float(g0), float(a1), float(g1), float(pa), float(pg), same))

print(f"Before: `{before}`. One-thread CPU seconds (user + system) of each decode, the median of {reps} runs")
print("made in turn (before and after interleaved), on a shared machine: compare within a row. *ratio*: the")
print("grid decode's seconds over the aligned sensor's, by the same binary and model. PSNR without the 2 edge")
print("lenslets. *same bits*: the before binary's light fields equal this one's.")
print()
print("| scene | k | grid (deg:px) | model | aligned s: before / after | grid s: before / after | ratio: before / after | PSNR aligned / grid dB | same bits |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for scene, k, grid, model, a0, g0, a1, g1, pa, pg, same in rows:
    print(f"| {scene} | {k} | {grid} | {model} | {a0:.2f} / {a1:.2f} | {g0:.2f} / {g1:.2f} | "
          f"{g0 / a0:.2f} / {g1 / a1:.2f} | {pa:.2f} / {pg:.2f} | {same} |")
print()
print("## Summary")
print()
print(f"`python3 scripts/grid-time-page.py` over the table's {len(rows)} rows: the grid decode's time over the")
print("aligned sensor's, worst / median / best (the target of issue 66: at most 1.3).")
print()
print("| model | k | rows | ratio before | ratio after | rows at most 1.3 after |")
print("| --- | --- | --- | --- | --- | --- |")
for model in ("default", "dct", "ensemble"):
    for k in sorted({r[1] for r in rows}):
        sel = [r for r in rows if r[3] == model and r[1] == k]
        if not sel:
            continue
        r0 = [r[5] / r[4] for r in sel]
        r1 = [r[7] / r[6] for r in sel]
        cell = lambda v: f"{max(v):.2f} / {statistics.median(v):.2f} / {min(v):.2f}"
        print(f"| {model} | {k} | {len(sel)} | {cell(r0)} | {cell(r1)} | {sum(x <= 1.3 for x in r1)} of {len(sel)} |")
