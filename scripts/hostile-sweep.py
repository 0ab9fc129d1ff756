#!/usr/bin/env python3
"""Bad and odd inputs through the `slf` command, as a new user or an adversary would give
them: missing, empty, random, truncated and lying files, FIFOs and devices, sparse files
claiming gigabytes, every numeric flag of `slf decode` with values out of range, outputs
over inputs. Each run gets a memory limit and a time limit; the sweep fails on any abort,
hang, panic, multi-line error or exit 0 that leaves a destroyed input or a light field slf
itself refuses.

    python3 scripts/hostile-sweep.py [SLF]        # default: target/release/slf

Prints one line per failure and a summary (cases, refused, accepted, failures); exit 1 when
any case failed. Standard library only (no numpy): files are written byte by byte.
"""

import os
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

SLF = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "target/release/slf")
MEMORY = 3 << 30  # bytes of address space a run may take
SECONDS = 120


def limits():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def npy(descr, shape, body=b""):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': (%s), }" % (descr, "".join(f"{d}, " for d in shape))
    header = header.encode()
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + body


def sparse(path, head, length):
    with open(path, "wb") as f:
        f.write(head)
        f.truncate(length)


class Sweep:
    def __init__(self, work):
        self.work = work
        self.cases = self.refused = self.accepted = 0
        self.failures = []

    def run(self, args, name, outputs=(), keep=()):
        """Runs `slf ARGS`; `outputs` are .npy light fields an exit 0 must leave readable,
        `keep` files no run may change."""
        self.cases += 1
        before = {p: Path(p).read_bytes() for p in keep if Path(p).is_file()}
        try:
            p = subprocess.run(
                [SLF, *map(str, args)],
                cwd=self.work,
                capture_output=True,
                text=True,
                timeout=SECONDS,
                preexec_fn=limits,
            )
        except subprocess.TimeoutExpired:
            self.failures.append(f"{name}: hang (over {SECONDS} s)")
            return
        err = p.stderr.strip()
        if p.returncode < 0:
            self.failures.append(f"{name}: killed by {signal.Signals(-p.returncode).name}: {err[-200:]}")
        elif "panicked" in err or "memory allocation" in err:
            self.failures.append(f"{name}: abort: {err[-300:]}")
        elif p.returncode != 0:
            self.refused += 1
            lines = [line for line in err.splitlines() if not line.startswith(("note:", "warning:"))]
            if len(lines) != 1 or not lines[0].startswith("error"):
                self.failures.append(f"{name}: not one error line: {err!r}")
        else:
            self.accepted += 1
            for out in outputs:
                check = subprocess.run([SLF, "eval", out, out], cwd=self.work, capture_output=True, text=True)
                if Path(out).exists() and check.returncode != 0 and "not finite" in check.stderr:
                    self.failures.append(f"{name}: exit 0 wrote a light field slf refuses: {check.stderr.strip()}")
        for path, data in before.items():
            if not Path(path).is_file() or Path(path).read_bytes() != data:
                self.failures.append(f"{name}: {path} changed or destroyed")


def main():
    work = Path(tempfile.mkdtemp(prefix="slf-sweep-"))
    s = Sweep(work)
    ok = lambda *a: subprocess.run([SLF, *map(str, a)], cwd=work, check=True, capture_output=True)
    ok("scene", "smooth", "--size", "12", "-o", "truth.npy")
    ok("simulate", "truth.npy", "-o", "cap", "--format", "npy")
    ok("simulate", "truth.npy", "-o", "cap-pgm", "--format", "pgm")
    capture_files = [str(work / "cap" / f) for f in os.listdir(work / "cap")]

    # Files that are not what they claim.
    (work / "empty.npy").write_bytes(b"")
    (work / "random.npy").write_bytes(os.urandom(4096))
    (work / "truncated.npy").write_bytes((work / "truth.npy").read_bytes()[:-100])
    sparse(work / "huge-lf.npy", npy("<f4", (5, 5, 4000, 4000, 13)), 128 + 4 * 5 * 5 * 4000 * 4000 * 13)
    sparse(work / "huge-f8.npy", npy("<f8", (5, 5, 3000, 3000, 13)), 128 + 8 * 5 * 5 * 3000 * 3000 * 13)
    (work / "nan.npy").write_bytes(npy("<f4", (5, 5, 12, 12, 13), struct.pack("<f", float("nan")) * 23400))
    (work / "big-f8.npy").write_bytes(npy("<f8", (5, 5, 12, 12, 13), struct.pack("<d", 1e300) * 23400))
    (work / "two-bands.npy").write_bytes(npy("<f4", (5, 5, 12, 12, 2), struct.pack("<f", 0.5) * 3600))
    (work / "three-views.npy").write_bytes(npy("<f4", (3, 3, 12, 12, 13), struct.pack("<f", 0.5) * 16848))
    os.mkfifo(work / "fifo.npy")
    lying = {}
    for name, frame in [
        ("pgm", ("snapshot_0.pgm", b"P5\n65535 65535\n65535\n", 2 * 65535 * 65535)),
        ("npy", ("snapshot_0.npy", npy("<u2", (65535, 65535)), 2 * 65535 * 65535)),
    ]:
        d = work / f"lying-{name}"
        shutil.copytree(work / ("cap-pgm" if name == "pgm" else "cap"), d)
        fname, head, length = frame
        sparse(d / fname, head, len(head) + length)
        lying[name] = d
    bad_files = ["nope.npy", ".", "empty.npy", "random.npy", "truncated.npy", "huge-lf.npy", "huge-f8.npy",
                 "nan.npy", "big-f8.npy", "two-bands.npy", "three-views.npy", "fifo.npy", "/dev/zero"]

    for f in bad_files:
        s.run(["eval", "truth.npy", f], f"eval {f}")
        s.run(["simulate", f, "-o", "sim-out"], f"simulate {f}")
        s.run(["evaluate", f, "-o", "ev-out"], f"evaluate {f}")
        s.run(["import", "bands", f, "--wavelengths", "400:700:25", "-o", "imp.npy"], f"import bands {f}",
              outputs=["imp.npy"])
        s.run(["train", "--input", f, "-o", "t.slfd", "--patches", "100", "--iterations", "1"], f"train {f}")
        s.run(["train-schedule", f, "-o", "ts.slfd", "--patches", "4", "--iterations", "1", "--scenes", "1",
               "--size", "12"], f"train-schedule {f}")
        s.run(["device-check", f, "--capture", "cap"], f"device-check {f}")
        s.run(["bench", "--from", f, "--out", "bench-out"], f"bench --from {f}")
        s.run(["decode", f, "-o", "x.npy"], f"decode {f}")
        s.run(["calibrate", f, "-o", "cal-out"], f"calibrate {f}")
        s.run(["decode", "cap", "-o", "x.npy", "--calibration", f], f"decode --calibration {f}")
    for name, d in lying.items():
        s.run(["decode", d, "-o", "x.npy", "-q"], f"decode a {name} frame claiming 65535 x 65535")

    # The real sensor's flags of simulate, with values no flag takes.
    for flag in ["--leakage", "--filter-width", "--secondary", "--secondary-nm", "--leak-floor", "--dark-sd",
                 "--hot-pixels", "--prnu", "--vignetting", "--sensor-seed", "--exposures"]:
        for v in ["nan", "inf", "-1", "1e39", "", "x", "0.99"]:
            s.run(["simulate", "truth.npy", "-o", "sim-out", "--calibration-captures", "cal-caps", flag, v],
                  f"simulate {flag} {v!r}")

    # Every numeric flag of decode, with values no flag takes, for each method.
    flags = ["--sigma-f", "--steps", "--mu", "--sigma-min", "--max-iterations", "--noise", "--shot",
             "--tolerance", "--warm-start", "--warm-sigma-f", "--warm-steps", "--seed-sigma-f", "--cold-start",
             "--flat", "--min-bands", "--stride", "--adaptive", "--patch-views"]
    values = ["nan", "inf", "-1", "-0.1", "0", "1e39", "1e-40", "", "x", "65536", "3.5"]
    for flag in flags:
        for v in values:
            for method in ["cs", "demosaic"]:
                s.run(["decode", "cap", "-o", "x.npy", "-q", "--method", method, f"{flag}={v}"],
                      f"decode --method {method} {flag}={v}", outputs=["x.npy"], keep=capture_files)
    for v in ["nan", "1,2", "0,0,0,0,0,0,0,0,0,0,0,0,0", "1e39," * 12 + "1", "x"]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", f"--gains={v}"], f"decode --gains={v}", keep=capture_files)
    for v in ["5:1", "1e9:1e9", "-1:1:0", "nan:1", "-1:1:0.3", "x"]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", f"--disparities={v}"], f"decode --disparities={v}",
              keep=capture_files)
    for v in ["0.5:0", "2:-1", "nan:0.1", "inf:0", "1e39:0", "2", "2:0.1:3", "", "x", "on"]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", f"--plausible={v}"], f"decode --plausible={v}",
              keep=capture_files)
    for flag in ["--model-trial", "--sheared-fallback"]:
        for v in ["yes", "", "1", "x"]:
            s.run(["decode", "cap", "-o", "x.npy", "-q", f"{flag}={v}"], f"decode {flag}={v}", keep=capture_files)
    for extra in [["--error-map", "cap/capture.json"], ["--error-map", "x.npy"], ["--method", "ppid", "--estimate"],
                  ["--model-trial", "true", "--dictionary", "dct"], ["--model-trial", "true", "--preset", "preview"],
                  ["--sheared-fallback", "true", "--disparities", "0:0"], ["--sheared-fallback", "true", "--stride", "1"],
                  ["--format", "hdf5"], ["--format", "x"], ["--deflate", "4"], ["--format", "hdf5", "--deflate", "0"],
                  ["--format", "hdf5", "--deflate", "10"], ["--format", "hdf5", "--dtype", "u16"],
                  ["--format", "hdf5", "--deflate", "9", "--method", "ppid"]]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", *extra], f"decode {' '.join(extra)}", keep=capture_files)

    # Outputs over inputs, and over each other.
    for out, extra in [("cap/capture.json", []), ("cap/snapshot_0.npy", []),
                       ("x.npy", ["--member-map", "x.npy"]), ("x.npy", ["--disparity-map", "cap/capture.json"])]:
        s.run(["decode", "cap", "-o", out, "-q", *extra], f"decode -o {out} {' '.join(extra)}", keep=capture_files)
    s.run(["simulate", "cap/snapshot_0.npy", "-o", "cap", "--format", "npy"], "simulate over its own input",
          keep=capture_files)

    # Sizes and options without bounds before issue 41.
    for v in ["1e9", "inf", "-1", "0", "33", "32"]:
        s.run(["import", "views", "cap", "--fill", "warp", "--max-disparity", v, "-o", "v.npy"],
              f"import views --max-disparity {v}")
    (work / "cube.npy").write_bytes(npy("<f4", (6, 7, 4), struct.pack("<f", 0.5) * 168))
    for v in ["1e-40", "0", "-1", "inf", "nan"]:
        s.run(["import", "cube", "cube.npy", "--wavelengths", "400,500,600,700", "--white", v, "-o", "w.npy"],
              f"import cube --white {v}", outputs=["w.npy"])
    for size in ["0", "4", "10", "11", "5000"]:
        s.run(["scene", "smooth", "--size", size, "-o", "s.npy"], f"scene --size {size}", outputs=["s.npy"])
    for only in ["bogus", ""]:
        s.run(["bench", "--quick", "--only", only, "--out", "bench-out"], f"bench --only {only!r}")
    (work / "header.csv").write_text("mask,k,setting,psnr_db,ssim,sa_deg,ms_per_patch_1_thread,"
                                      "ms_per_patch_all_threads,solves_per_patch,frame_512_s_1_thread,pareto\n")
    s.run(["bench", "--from", "header.csv", "--out", "bench-out"], "bench --from a header only")
    for row in ["pixel,3,x,30,0.9,4,0,0.5,1,2,true", "pixel,3,x,NaN,0.9,4,1,0.5,1,2,true"]:
        (work / "row.csv").write_text((work / "header.csv").read_text() + row + "\n")
        s.run(["bench", "--from", "row.csv", "--out", "bench-out"], f"bench --from {row}")
    for missing in [["decode"], ["decode", "cap"], ["simulate", "truth.npy"], ["import"], []]:
        s.run(missing, f"slf {' '.join(missing)} (missing arguments)")

    for f in s.failures:
        print("FAIL", f)
    print(f"hostile sweep: {s.cases} cases, {s.refused} refused with one line, {s.accepted} accepted, "
          f"{len(s.failures)} failures")
    shutil.rmtree(work, ignore_errors=True)
    return 1 if s.failures else 0


if __name__ == "__main__":
    sys.exit(main())
