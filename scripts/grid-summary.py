#!/usr/bin/env python3
"""The summary of scripts/grid-results.sh's tables (docs/results-grid.md): per pixel k, the
calibrated grid's decode (c) against the aligned sensor's (ref), worst / median / best dB over
every scene and grid, and the same scored without the 2 edge lenslets (interior); its gain over
reading the frame as aligned (a); the worst SA ratio; the
median and worst time ratio; and the same per grid for the issue's target grids (0.3 degrees
at 5.04 px: within 1 dB, 1 degree at 5.1 px: within 2 dB, SA within 10 %).

    python3 scripts/grid-summary.py PAGE.md
"""
import statistics
import sys


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def metric(cell):
    p, q, a = (float(x) for x in cell.split("/"))
    return p, q, a


def main(path):
    rows = []
    for line in open(path):
        c = cells(line)
        if len(c) != 10 or c[0] not in ("1", "3"):
            continue
        k, rot, pitch = c[0], c[1], c[2]
        a, b, cal, ref = (metric(x) for x in c[3:7])
        inner = float(c[8])
        t_c, t_ref = (float(x) for x in c[9].split("/"))
        rows.append(dict(k=k, grid=f"{rot}:{pitch}", a=a, b=b, c=cal, ref=ref, inner=inner, t=t_c / t_ref))
    if not rows:
        sys.exit(f"{path}: no table rows")
    print("| k | grids | (c) - ref, worst / median / best dB | interior, worst / median / best dB | (c) - (a), median dB | SA (c) / ref, worst | seconds (c) / ref, median / worst |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    groups = [(k, None) for k in ("1", "3")] + [(k, g) for g in ("0.3:5.04", "1:5.1") for k in ("1", "3")]
    for k, g in groups:
        sel = [r for r in rows if r["k"] == k and (g is None or r["grid"] == g)]
        if not sel:
            continue
        d = [r["c"][0] - r["ref"][0] for r in sel]
        i = [r["inner"] for r in sel]
        gain = [r["c"][0] - r["a"][0] for r in sel]
        sa = [r["c"][2] / r["ref"][2] for r in sel]
        t = [r["t"] for r in sel]
        label = "all" if g is None else g.replace(":", " deg, ") + " px"
        print(
            f"| {k} | {label} ({len(sel)} rows) | {min(d):+.2f} / {statistics.median(d):+.2f} / {max(d):+.2f} "
            f"| {min(i):+.2f} / {statistics.median(i):+.2f} / {max(i):+.2f} "
            f"| {statistics.median(gain):+.2f} | {max(sa):.2f} | {statistics.median(t):.2f} / {max(t):.2f} |"
        )
    worst_b = max(abs(r["b"][0] - r["c"][0]) for r in rows)
    print()
    print(f"(b) and (c) differ by at most {worst_b:.2f} dB over {len(rows)} rows.")


if __name__ == "__main__":
    main(sys.argv[1])
