#!/usr/bin/env python3
"""The summary of docs/results-grid-bound.md: over the rows of its table, per k, the worst,
median and best of each "- aligned" column. `scripts/grid-bound.sh` appends it to the page
it makes; `python3 scripts/grid-bound-summary.py PAGE` prints it for a page made so."""
import statistics
import sys

page = open(sys.argv[1]).read().splitlines()
head = next(l for l in page if l.startswith("| scene |"))
names = [c.strip() for c in head.strip("|").split("|")]
rows = [
    [c.strip() for c in l.strip("|").split("|")]
    for l in page
    if l.startswith("| ") and not l.startswith("| scene") and not l.startswith("| ---")
]
rows = [r for r in rows if len(r) == len(names)]
cols = [i for i, n in enumerate(names) if "- aligned" in n]
print("## Summary of the table above")
print()
print(f"`python3 scripts/grid-bound-summary.py PAGE` over its {len(rows)} rows: each cell is worst / median / best, dB.")
print()
print("| k | rows | " + " | ".join(names[i] for i in cols) + " |")
print("| --- | --- | " + " | ".join("---" for _ in cols) + " |")
for k in sorted({r[1] for r in rows}, key=int):
    of = [r for r in rows if r[1] == k]
    cells = []
    for i in cols:
        v = [float(r[i]) for r in of]
        cells.append(f"{min(v):+.2f} / {statistics.median(v):+.2f} / {max(v):+.2f}")
    print(f"| {k} | {len(of)} | " + " | ".join(cells) + " |")
