#!/usr/bin/env python3
"""The summary of docs/results-grid-baselines.md from its table (scripts/grid-baselines.sh's
output): per k and method, the gap to the method on the aligned sensor, the gain over reading
the frame as aligned, and the CS decode's lead through the grid.

    python3 scripts/grid-baselines-summary.py docs/results-grid-baselines.md
"""
import statistics
import sys

rows = []
for line in open(sys.argv[1]):
    cells = [c.strip() for c in line.split("|")[1:-1]]
    if len(cells) == 9 and cells[1].isdigit():
        rows.append(cells)
psnr = lambda cell: float(cell.split()[0])
print("## Summary")
print()
print("| k | method | decodes | gap dB: worst / median / best | within 1 dB | over as aligned: worst / median / best | CS through the grid ahead by: worst / median |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for k in sorted({r[1] for r in rows}):
    for method in ["demosaic", "ppid"]:
        sel = [r for r in rows if r[1] == k and r[3] == method]
        gap = [float(r[7]) for r in sel]
        gain = [psnr(r[6]) - psnr(r[5]) for r in sel]
        lead = [psnr(r[8]) - psnr(r[6]) for r in sel]
        print(f"| {k} | {method} | {len(sel)} | {min(gap):+.2f} / {statistics.median(gap):+.2f} / {max(gap):+.2f} | "
              f"{sum(g >= -1 for g in gap)} of {len(sel)} | {min(gain):+.2f} / {statistics.median(gain):+.2f} / "
              f"{max(gain):+.2f} | {min(lead):+.2f} / {statistics.median(lead):+.2f} |")
