#!/usr/bin/env python3
"""The tables of scripts/before-after.sh from its rows.tsv.

    python3 scripts/before-after.py ROWS.tsv THREADS BEFORE_BINARY SIZE AFTER_COMMIT

rows.tsv: scene, setting, method, binary (before / after), PSNR, SSIM, SA, seconds; one line a
decode. Prints markdown: issue 62's targets against every scene, then a table per setting with
every scene, time and PSNR side by side.
"""
import statistics
import sys
from collections import defaultdict


def read(path):
    rows = {}
    order, settings = [], []
    for line in open(path):
        scene, setting, method, binary, p, q, a, t = line.rstrip("\n").split("\t")
        rows[(scene, setting, method, binary)] = (float(p), float(q), float(a), float(t))
        if scene not in order:
            order.append(scene)
        if setting not in settings:
            settings.append(setting)
    return rows, order, settings


def main():
    path, threads, before, size, after = sys.argv[1:6]
    rows, scenes, settings = read(path)
    print("# Speed before and after issue 62, every scene")
    print()
    print(__import__("os").environ.get("STAMP_LINE", "> Made by `before-after.py` outside its script."))
    print()
    print(f"Made by `SLF_BEFORE={before} bash scripts/before-after.sh OUT` at commit {after}")
    print(f"(`RAYON_NUM_THREADS={threads}`); the binary before is built as the script's header says, from")
    print("e25a905, the commit before issue 62's first change.")
    print("Each preset decodes every capture with the binary before and with this one, one right")
    print("after the other, so the two times of a row compare; the demosaic and PPID run once, with")
    print("this binary. Times are one run's on a shared machine: compare ratios within a row.")
    print(f"Light fields: `slf scene NAME --size {size}` (the test, realistic and hard-case sets) and the")
    print("HCI crops (`_128`, evaluation only), simulated with `--seed 3` at the capture's noise model.")
    print()
    summary = defaultdict(list)
    tables = []
    for setting in settings:
        lines = [
            f"## {setting.replace(':', ' k=')}",
            "",
            "| scene | demosaic s | baseline dB | preview dB, before -> after | preview s, before -> after "
            "| preview / demosaic | preview - baseline dB | default dB, before -> after | default s, before -> after "
            "| default after / before | default / demosaic |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        ]
        for scene in scenes:
            get = lambda m, b="after": rows.get((scene, setting, m, b))  # noqa: E731
            dem, ppid = get("demosaic"), get("ppid")
            pb, pa, db, da = get("preview", "before"), get("preview"), get("default", "before"), get("default")
            if None in (dem, ppid, pb, pa, db, da):
                continue
            base = max(dem[0], ppid[0])
            which = "demosaic" if dem[0] >= ppid[0] else "PPID"
            dt = max(dem[3], 1e-3)
            s = summary[setting]
            s.append(
                {
                    "scene": scene,
                    "default_x": da[3] / dt,
                    "preview_x": pa[3] / dt,
                    "d_db": da[0] - db[0],
                    "p_db": pa[0] - pb[0],
                    "speed": da[3] / max(db[3], 1e-3),
                    "p_margin": pa[0] - base,
                }
            )
            lines.append(
                f"| {scene} | {dem[3]:.2f} | {base:.2f} ({which}) | {pb[0]:.2f} -> {pa[0]:.2f} | "
                f"{pb[3]:.2f} -> {pa[3]:.2f} | {pa[3] / dt:.1f} | {pa[0] - base:+.2f} | {db[0]:.2f} -> {da[0]:.2f} | "
                f"{db[3]:.2f} -> {da[3]:.2f} | {da[3] / max(db[3], 1e-3):.2f} | {da[3] / dt:.1f} |"
            )
        tables.append(lines)
    print("## Against the targets")
    print()
    print("| setting | scenes | default / demosaic: median (worst, scene) | default dB after - before: worst | "
          "default time after / before: median (range) | preview / demosaic: median (worst, scene) | "
          "preview dB after - before: worst | scenes the preview is below the strongest baseline |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for setting in settings:
        s = summary[setting]
        if not s:
            continue
        wd = max(s, key=lambda r: r["default_x"])
        wp = max(s, key=lambda r: r["preview_x"])
        below = [r["scene"] for r in s if r["p_margin"] < 0]
        speeds = [r["speed"] for r in s]
        print(
            f"| {setting.replace(':', ' k=')} | {len(s)} | {statistics.median(r['default_x'] for r in s):.1f}x "
            f"({wd['default_x']:.1f}x, {wd['scene']}) | {min(r['d_db'] for r in s):+.2f} | "
            f"{statistics.median(speeds):.2f} ({min(speeds):.2f}-{max(speeds):.2f}) | "
            f"{statistics.median(r['preview_x'] for r in s):.1f}x ({wp['preview_x']:.1f}x, {wp['scene']}) | "
            f"{min(r['p_db'] for r in s):+.2f} | {len(below)}: {', '.join(below) if below else 'none'} |"
        )
    print()
    print("Issue 62's targets: the default at most 10 times the demosaic's time on every scene at")
    print("no less than its quality before - 0.1 dB; the preview at most 3 times, above the strongest")
    print("baseline on every scene.")
    for lines in tables:
        print()
        print("\n".join(lines))


if __name__ == "__main__":
    main()
