#!/usr/bin/env python3
"""Counts the call sites of panic entry points in an ELF, by calling function.

Usage: panic-sites.py ELF [--allow REGEX]...

Reads `llvm-objdump -d` of the ELF and lists every branch to a panic entry point
(`core::panicking::*`, `core::slice::index::*_fail`, `unwrap_failed`, `expect_failed`,
`core::cell::panic_*`, `core::result`/`option` failures, `rust_begin_unwind`), grouped by
the function it sits in. The panic machinery's own calls to itself are not counted. Exits 1
when any other call site is found (functions matching an --allow pattern excepted), so
CI fails if decoder code can panic.
"""
import re
import subprocess
import sys
from collections import Counter

PANIC = re.compile(
    r"<(core::panicking::[^>+]*|core::slice::index::[a-z_]*fail[^>+]*|core::str::slice_error_fail[^>+]*"
    r"|core::option::unwrap_failed|core::option::expect_failed|core::result::unwrap_failed"
    r"|core::cell::panic_[a-z_]*|core::array::[a-z_]*fail[^>+]*|rust_begin_unwind|core::panicking[^>+]*)(\+0x[0-9a-f]+)?>"
)
# The panic machinery itself: its calls to itself are not call sites of other code.
MACHINERY = re.compile(r"^(core::panicking::|core::slice::index::[a-z_]*fail|core::str::slice_error_fail|"
                       r"core::option::(unwrap|expect)_failed|core::result::unwrap_failed|core::cell::panic_|"
                       r"core::array::[a-z_]*fail|rust_begin_unwind|core::fmt::|panic_semihosting::)")


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    elf, allow = args[0], []
    rest = args[1:]
    while rest:
        if rest[0] == "--allow" and len(rest) > 1:
            allow.append(re.compile(rest[1]))
            rest = rest[2:]
        else:
            print(f"unknown argument {rest[0]}")
            return 2
    dis = subprocess.run(["llvm-objdump", "-d", "-C", "--no-show-raw-insn", elf],
                         check=True, capture_output=True, text=True).stdout
    sites, current = Counter(), "?"
    for line in dis.splitlines():
        label = re.match(r"^[0-9a-f]+ <(.*)>:$", line)
        if label:
            if not label.group(1).startswith("$"):  # $t / $d are ARM mapping symbols
                current = label.group(1)
            continue
        hit = PANIC.search(line)
        if hit and re.search(r"\sb[a-z.]*\s", line):
            sites[(current, hit.group(1))] += 1
    counted = {k: n for k, n in sites.items() if not MACHINERY.match(k[0])}
    bad = {k: n for k, n in counted.items() if not any(a.search(k[0]) for a in allow)}
    for (func, target), n in sorted(counted.items(), key=lambda kv: -kv[1]):
        mark = "" if (func, target) in bad else " (allowed)"
        print(f"{n:4} {func[:120]} -> {target}{mark}")
    print(f"panic call sites outside the panic machinery: {sum(counted.values())}, "
          f"not allowed: {sum(bad.values())}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
