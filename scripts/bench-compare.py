#!/usr/bin/env python3
"""Two `slf bench` CSVs side by side: each setting both hold, before -> now.

    python3 scripts/bench-compare.py BEFORE/bench.csv NOW/bench.csv [SUBSTRING]

Prints a markdown table of PSNR, SA, milliseconds a patch on one thread and solves a patch
for every (mask, k, setting) in both files whose setting contains SUBSTRING (default: every
setting). Run both benches in one sitting on the same machine (e.g. side by side, one
thread each): times compare only within a run.
"""
import csv
import sys


def load(path):
    with open(path, newline="") as f:
        return {(r["mask"], r["k"], r["setting"]): r for r in csv.DictReader(f)}


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__.strip().splitlines()[2].strip())
    before, now = load(sys.argv[1]), load(sys.argv[2])
    only = sys.argv[3] if len(sys.argv) == 4 else ""
    cols = [("psnr_db", "PSNR dB", 2), ("sa_deg", "SA deg", 2), ("ms_per_patch_1_thread", "ms / patch, 1 thread", 2),
            ("solves_per_patch", "solves a patch", 2)]
    print("| mask | k | setting | " + " | ".join(f"{name}, before -> now" for _, name, _ in cols) + " |")
    print("| --- " * (3 + len(cols)) + "|")
    for key, row in now.items():
        if only not in key[2] or key not in before:
            continue
        old = before[key]
        cells = [f"{float(old[c]):.{d}f} -> {float(row[c]):.{d}f}" for c, _, d in cols]
        print(f"| {key[0]} | {key[1]} | {key[2]} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
