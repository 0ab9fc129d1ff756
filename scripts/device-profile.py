#!/usr/bin/env python3
"""Where a device window's instructions go, per function (issue 30's per-stage counts).

Reads the `wincount: prof 0xADDR COUNT` lines that scripts/wincount/wincount.c prints with
`prof=FIRST:LAST`, maps each instruction address to the function that holds it (the ELF's
symbols, `llvm-nm --print-size`) and to the innermost slf function of the source it came
from (`llvm-symbolizer --inlining`: what LTO inlined is resolved), and prints a markdown
table of each, instructions and shares, largest first. The total is checked against the profiled windows' own counts, so an
address outside every function cannot hide. With LTO a function includes what was
inlined into it: the names are the device binary's, not the source's call tree.

    python3 scripts/device-profile.py ELF WINCOUNT_LOG FIRST LAST [TITLE]
"""
import bisect
import re
import subprocess
import sys


def symbols(elf):
    out = subprocess.run(["llvm-nm", "--print-size", "--defined-only", "-C", elf], capture_output=True, text=True,
                         check=True).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2].lower() == "t":
            start = int(parts[0], 16) & ~1
            # Hash suffixes and generic parameters are noise in a table.
            name = re.sub(r"::h[0-9a-f]{16}$", "", parts[3])
            syms.append((start, int(parts[1], 16), name))
    syms.sort()
    return syms


def demangle(name):
    """A legacy-mangled Rust path as source text, without its hash."""
    name = re.sub(r"::h[0-9a-f]{16}$", "", name)
    for k, v in (("$LT$", "<"), ("$GT$", ">"), ("$u20$", " "), ("$C$", ","), ("$RF$", "&"), ("..", "::")):
        name = name.replace(k, v)
    return name.lstrip("_")


def source_functions(elf, addrs):
    """Each address's innermost slf function in the source, inlined frames included
    (llvm-symbolizer on the ELF's debug info); the symbol's name where there is none."""
    out = subprocess.run(["llvm-symbolizer", "--obj=" + elf, "--inlining", "--functions=linkage"],
                         input="\n".join(hex(a) for a in addrs) + "\n", capture_output=True, text=True,
                         check=True).stdout
    blocks = out.strip("\n").split("\n\n")
    assert len(blocks) == len(addrs), (len(blocks), len(addrs))
    names = []
    for block in blocks:
        frames = [demangle(f) for f in block.splitlines()[0::2]]
        ours = [f for f in frames if f.startswith("slf_")]
        names.append(ours[0] if ours else frames[0])
    return names


def main():
    elf, log, first, last = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    title = sys.argv[5] if len(sys.argv) > 5 else f"windows {first}..={last}"
    text = open(log).read()
    windows = [int(x) for x in re.findall(r"wincount: end window \d+ insns=(\d+)", text)]
    want = sum(windows[first - 1:last])
    counts = [(int(a, 16), int(n)) for a, n in re.findall(r"wincount: prof (0x[0-9a-f]+) (\d+)", text)]
    syms = symbols(elf)
    starts = [s[0] for s in syms]
    per, inner = {}, {}
    names = source_functions(elf, [a for a, _ in counts])
    for (addr, n), source in zip(counts, names):
        i = bisect.bisect_right(starts, addr) - 1
        name = demangle(syms[i][2]) if i >= 0 and addr < syms[i][0] + max(syms[i][1], 2) else "(outside every symbol)"
        per[name] = per.get(name, 0) + n
        inner[source] = inner.get(source, 0) + n
    total = sum(per.values())
    assert total == want, f"profiled {total} instructions, the windows counted {want}"
    print(f"{title}: {total:,} instructions")
    for label, table in (("function of the binary (with what LTO inlined into it)", per),
                         ("innermost source function (inlined frames resolved by the debug info)", inner)):
        print()
        print(f"| {label} | instructions | share |")
        print("| --- | --- | --- |")
        shown = 0
        for name, n in sorted(table.items(), key=lambda kv: -kv[1]):
            if n < total * 0.005:
                break
            shown += n
            print(f"| `{name}` | {n:,} | {100 * n / total:.1f} % |")
        print(f"| everything else (under 0.5 % each) | {total - shown:,} | {100 * (total - shown) / total:.1f} % |")


if __name__ == "__main__":
    main()
