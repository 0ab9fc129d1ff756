#!/usr/bin/env python3
"""The summary of docs/results-grid-baselines.md from its table (scripts/grid-baselines.sh's
output): per k and method, the gap to the method on the aligned sensor, the gain over reading
the frame as aligned, and the CS decode's lead through the grid; then, per k and set (the
realistic scenes, the HCI crops `*_128`), what reading through the grid adds: the error the
read adds as a PSNR of its own (`-10 log10(mse_grid - mse_aligned)`, mse `10^(-PSNR / 10)`
of the peak; the errors taken as independent), beside the methods' PSNR on the aligned
sensor. The same added error costs more dB where the method is more accurate.

    python3 scripts/grid-baselines-summary.py docs/results-grid-baselines.md
"""
import math
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

print()
print("## What the read through the grid adds")
print()
print("| k | set | decodes | aligned sensor PSNR dB: lowest / median / highest | added error as PSNR dB: largest / median / smallest | decodes where the grid read is no worse |")
print("| --- | --- | --- | --- | --- | --- |")
for k in sorted({r[1] for r in rows}):
    for name, hci in [("realistic", False), ("HCI crops", True)]:
        sel = [r for r in rows if r[1] == k and r[0].endswith("_128") == hci]
        if not sel:
            continue
        aligned = [psnr(r[4]) for r in sel]
        added = []
        for r in sel:
            mse = 10 ** (-psnr(r[6]) / 10) - 10 ** (-psnr(r[4]) / 10)
            if mse > 0:
                added.append(-10 * math.log10(mse))
        print(f"| {k} | {name} | {len(sel)} | {min(aligned):.2f} / {statistics.median(aligned):.2f} / {max(aligned):.2f} | "
              + (f"{min(added):.1f} / {statistics.median(added):.1f} / {max(added):.1f}" if added else "none")
              + f" | {len(sel) - len(added)} |")
