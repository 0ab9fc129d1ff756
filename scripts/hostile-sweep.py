#!/usr/bin/env python3
"""Bad and odd inputs through the `slf` command, as a new user or an adversary would give
them: missing, empty, random, truncated and lying files, FIFOs and devices, sparse files
claiming gigabytes, every numeric flag of `slf decode` with values out of range, outputs
over inputs. Each run gets a memory limit and a time limit; the sweep fails on any abort,
hang, panic, multi-line error or exit 0 that leaves a destroyed input or a light field slf
itself refuses, or where slf must refuse (issue 51's classes: extreme bench tables, mixed
folders, trainings larger than memory, unusable calibrations, a failed standard output, a
file-size limit, values accepted and ignored, and, with a Python that imports slf, the
package's None, string booleans and empty paths).

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
# The Python package's cases run with this interpreter when it imports slf (CI's venv);
# skipped, and said, when it does not.
PYTHON = os.environ.get("SLF_PYTHON", sys.executable)
PYTHON = os.path.abspath(PYTHON) if os.sep in PYTHON else PYTHON  # the runs' folder is another
REPO = Path(__file__).resolve().parents[1]
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

    def run(self, args, name, outputs=(), keep=(), refuse=False, stdout=None, file_limit=None, python=None):
        """Runs `slf ARGS` (or, with `python`, that Python source with the package); `outputs`
        are .npy light fields an exit 0 must leave whole (removed before the run; after an
        exit 0 each must be there and read by `slf eval`), `keep` files no run may
        change; `refuse`: the run must fail (an exit 0 is a failure of the sweep); `stdout`
        a file to write standard output to; `file_limit` bytes of RLIMIT_FSIZE."""
        self.cases += 1
        before = {p: Path(p).read_bytes() for p in keep if Path(p).is_file()}
        # An output an earlier case left would pass for this one's.
        for out in outputs:
            if out not in keep:
                at = Path(self.work, out)
                if at.is_dir():
                    shutil.rmtree(at)
                else:
                    at.unlink(missing_ok=True)

        def preexec():
            limits()
            if file_limit is not None:
                signal.signal(signal.SIGXFSZ, signal.SIG_DFL)
                resource.setrlimit(resource.RLIMIT_FSIZE, (file_limit, file_limit))

        cmd = [PYTHON, "-c", python] if python is not None else [SLF, *map(str, args)]
        try:
            out = open(stdout, "w") if stdout else subprocess.PIPE
            p = subprocess.run(
                cmd,
                cwd=self.work,
                stdout=out,
                stderr=subprocess.PIPE,
                text=True,
                timeout=SECONDS,
                preexec_fn=preexec,
            )
            if stdout:
                out.close()
        except subprocess.TimeoutExpired:
            self.failures.append(f"{name}: hang (over {SECONDS} s)")
            return
        err = p.stderr.strip()
        if python is not None:
            # The package raises one exception: its last line is the message.
            err = err.splitlines()[-1] if err else ""
            if p.returncode != 0 and err:
                err = "error: " + err
        if p.returncode == 0 and refuse:
            self.failures.append(f"{name}: exit 0, where slf must refuse")
        if p.returncode < 0:
            self.failures.append(f"{name}: killed by {signal.Signals(-p.returncode).name}: {err[-200:]}")
        elif "panicked" in err or "memory allocation" in err:
            self.failures.append(f"{name}: abort: {err[-300:]}")
        elif p.returncode != 0:
            self.refused += 1
            lines = [line for line in err.splitlines() if not line.startswith(("note:", "warning:"))]
            if len(lines) != 1 or not lines[0].startswith("error"):
                self.failures.append(f"{name}: not one error line: {err!r}")
            elif len(lines[0]) > 4200:
                self.failures.append(f"{name}: an error line of {len(lines[0])} characters")
        else:
            self.accepted += 1
            # Strict: an exit 0 leaves each output whole, a light field slf itself reads.
            for out in outputs:
                at = Path(self.work, out)
                if out.endswith(".zarr"):
                    # A store: its group and its array described (zarr-python reads it in
                    # the package's tests).
                    if not (at / "zarr.json").is_file() or not (at / "lightfield" / "zarr.json").is_file():
                        self.failures.append(f"{name}: exit 0 and no whole store {out}")
                    continue
                if out.endswith(".h5"):
                    if not at.is_file() or at.read_bytes()[:8] != b"\x89HDF\r\n\x1a\n":
                        self.failures.append(f"{name}: exit 0 and no HDF5 file {out}")
                    continue
                if not at.is_file():
                    self.failures.append(f"{name}: exit 0 and no {out}")
                    continue
                check = subprocess.run([SLF, "eval", out, out], cwd=self.work, capture_output=True, text=True)
                if check.returncode != 0:
                    self.failures.append(f"{name}: exit 0 wrote {out}, which slf eval refuses: {check.stderr.strip()}")
        for path, data in before.items():
            if not Path(path).is_file() or Path(path).read_bytes() != data:
                self.failures.append(f"{name}: {path} changed or destroyed")


def issue_51(s, work, ok):
    """The classes of issue 51 (nothing lost, nothing silently wrong, round 4): each must be
    refused with one line (or, where marked, run to a correct end)."""
    header = (work / "header.csv").read_text()
    # 1, 12: bench tables of values no decode gives; a table redrawn from its own folder.
    for row in ["pixel,3,x,1.7e308,0.9,4,1,0.5,1,2,true\npixel,3,y,-1.7e308,0.9,4,1,0.5,1,2,true",
                "pixel,3,x,30,0.9,4,1e-200,0.5,1,2,true\npixel,3,y,30,0.9,4,1e200,0.5,1,2,true"]:
        (work / "extreme.csv").write_text(header + row + "\n")
        s.run(["bench", "--from", "extreme.csv", "--out", "bench-x"], f"bench --from {row[:30]}...", refuse=True)
    (work / "own").mkdir(exist_ok=True)
    (work / "own" / "bench.csv").write_text(header + "pixel,3,x,30.123456789,0.9,4,1,0.5,1,2,true\n")
    s.run(["bench", "--from", "own/bench.csv", "--out", "own"], "bench --from DIR/bench.csv --out DIR",
          keep=[str(work / "own" / "bench.csv")])

    # The calibrated set-up of the issue.
    ok("scene", "smooth", "--size", "16", "-o", "lf16.npy")
    ok("simulate", "lf16.npy", "-o", "cap16", "--leakage", "0.1", "--calibration-captures", "cc", "--exposures", "2")
    ok("calibrate", "cc", "-o", "cal")
    ok("simulate", "lf16.npy", "-o", "cap16b", "--leakage", "0.3", "--calibration-captures", "cc-b",
       "--exposures", "1")
    ok("calibrate", "cc-b", "-o", "cal-b")
    cal_files = [str(work / "cal" / f) for f in os.listdir(work / "cal")]

    # 2: folders mixed after they were written: a flat or a frame from elsewhere.
    shutil.copytree(work / "cal", work / "cal-mixed")
    shutil.copy(work / "cal-b" / "flat.npy", work / "cal-mixed" / "flat.npy")
    s.run(["decode", "cap16", "--calibration", "cal-mixed", "-o", "m.npy", "-q"], "decode with a mixed calibration",
          refuse=True)
    shutil.copytree(work / "cap16", work / "cap-mixed")
    shutil.copy(work / "cap16b" / "snapshot_0.pgm", work / "cap-mixed" / "snapshot_0.pgm")
    s.run(["decode", "cap-mixed", "-o", "m.npy", "-q"], "decode a capture with another's frame", refuse=True)
    # A folder holding a user's file is not an output to replace.
    (work / "mine").mkdir(exist_ok=True)
    (work / "mine" / "notes.txt").write_text("mine")
    for args in [["simulate", "lf16.npy", "-o", "mine"], ["calibrate", "cc", "-o", "mine"]]:
        s.run(args, f"{args[0]} -o a folder with a user's file", refuse=True, keep=[str(work / "mine" / "notes.txt")])

    # 4: a training larger than memory, refused before it renders.
    blob = REPO / "firmware" / "dictionaries" / "fullview8.slfd"
    for scenes, size in [("3", "1024"), ("1000", "1024")]:
        s.run(["train-schedule", blob, "-o", "t.slfd", "--scenes", scenes, "--size", size, "--patches", "4",
               "--iterations", "1"], f"train-schedule --scenes {scenes} --size {size}", refuse=True)
    s.run(["train", "-o", "t.slfd", "--scenes", "1000", "--size", "1024"], "train --scenes 1000 --size 1024",
          refuse=True)

    # 6, 9: response curves no decode can use, refused when calibrating.
    eye = [[1.0 if i == j else 0.0 for j in range(13)] for i in range(13)]
    for label, rows in [("ones", [[1.0] * 13] * 13), ("0.3 x I", [[0.3 * x for x in r] for r in eye]),
                        ("a zero row", eye[:12] + [[0.0] * 12 + [1e-9]])]:
        body = b"".join(struct.pack("<f", x) for r in rows for x in r)
        (work / "curves.npy").write_bytes(npy("<f4", (13, 13), body))
        s.run(["calibrate", "cc", "-o", "c1", "--response", "curves.npy"], f"calibrate --response {label}",
              refuse=True)
    # 7: captures of two sensors.
    s.run(["calibrate", "cc", "cc-b/flat-00", "-o", "c1"], "calibrate two sensors' captures", refuse=True)
    # A calibration capture decoded as a scene.
    s.run(["decode", "cc/flat-00", "-o", "m.npy", "-q"], "decode a calibration capture", refuse=True)

    # 8: baselines with a calibration: accepted, and their values in the sensor's range
    # (checked by reading the .npy's float32 body).
    for method in ["ppid", "demosaic"]:
        out = work / f"b-{method}.npy"
        s.run(["decode", "cap16", "--calibration", "cal", "--method", method, "-o", out.name, "-q"],
              f"decode --method {method} --calibration", outputs=[out.name], keep=cal_files)
        if out.exists():
            data = out.read_bytes()
            start = 10 + struct.unpack("<H", data[8:10])[0]
            least = min(struct.unpack(f"<{(len(data) - start) // 4}f", data[start:]))
            if least < 0:
                s.failures.append(f"decode --method {method} --calibration: a value of {least} below 0")

    # 10, 11: a standard output that cannot be written; a file-size limit.
    s.run(["scene", "smooth", "--size", "11", "-o", "s11.npy"], "scene > /dev/full", stdout="/dev/full", refuse=True)
    (work / "uf").mkdir(exist_ok=True)
    s.run(["scene", "smooth", "--size", "40", "-o", "uf/s.npy"], "scene under ulimit -f", file_limit=40 << 10,
          refuse=True)
    left = [f for f in os.listdir(work / "uf")]
    if left:
        s.failures.append(f"scene under ulimit -f: left {left}")

    # 15: values accepted and ignored.
    for args in [["simulate", "lf16.npy", "-o", "x-cap", "--filter-width", "200", "--secondary", "1"],
                 ["import", "views", "cap16", "--index-base", "7", "-o", "v.npy"],
                 ["decode", "cap16", "--calibration", "cal", "--response-model", "projection",
                  "--disparities=-1:1:0.5", "-o", "m.npy", "-q"],
                 ["decode", "cap16", "--response-model", "projection", "-o", "m.npy", "-q"]]:
        s.run(args, " ".join(args[:1] + args[2:]), refuse=True)

    issue_65(s, work, ok)
    python_cases(s)


def psnr(work, truth, decoded):
    """`slf eval --border 2`'s PSNR, dB (None when eval refuses)."""
    p = subprocess.run([SLF, "eval", truth, decoded, "--border", "2"], cwd=work, capture_output=True, text=True)
    line = next((x for x in p.stdout.splitlines() if x.startswith("PSNR")), None)
    return float(line.split()[1]) if p.returncode == 0 and line else None


def issue_65(s, work, ok):
    """The surfaces of issue 65 (round 5): the lenslet grid's index, folders that are not
    ours, readers of files longer than their header, long names and values, flags the
    baselines ignore, FIFOs as outputs, large tables and `.npy` files past the memory."""
    # 2: a calibration's grid names the lenslets as the capture does (the issue's case).
    ok("scene", "texture", "--size", "24", "-o", "tex.npy")
    ok("simulate", "tex.npy", "-o", "capg", "--rotation", "0.3", "--vignetting", "0.5", "--grid-offset", "0,0",
       "-s", "1", "--calibration-captures", "ccg", "--exposures", "1")
    ok("calibrate", "ccg", "-o", "calg")
    s.run(["decode", "capg", "--calibration", "calg", "-o", "g.npy", "-q"], "decode a grid at the sensor's corner",
          outputs=["g.npy"])
    s.run(["decode", "capg", "--calibration", "calg", "--grid", "capture", "-o", "gc.npy", "-q"],
          "decode a grid at the sensor's corner, --grid capture", outputs=["gc.npy"])
    a, b = psnr(work, "tex.npy", "g.npy"), psnr(work, "tex.npy", "gc.npy")
    if a is None or b is None or a < b - 1.0:
        s.failures.append(f"grid index: the calibration's grid decodes at {a} dB, the capture's at {b} dB")
    # 10: a grid beside the sensor; a stray description naming a user's file; the
    # calibration captures' folder overlapping the capture's.
    s.run(["simulate", "truth.npy", "-o", "g-off", "--grid-offset", "200,200"], "simulate --grid-offset 200,200",
          refuse=True)
    (work / "stray").mkdir(exist_ok=True)
    (work / "stray" / "thesis.tex").write_text("mine")
    (work / "stray" / "capture.json").write_text('{"frames": ["thesis.tex"]}')
    s.run(["simulate", "truth.npy", "-o", "stray"], "simulate -o a folder whose capture.json names a user's file",
          refuse=True, keep=[str(work / "stray" / "thesis.tex")])
    for cc in ["capx", "capx/cc"]:
        s.run(["simulate", "truth.npy", "-o", "capx", "--calibration-captures", cc, "--exposures", "1"],
              f"simulate -o capx --calibration-captures {cc}", refuse=True)
        if (work / "capx").exists():
            s.failures.append(f"simulate -o capx --calibration-captures {cc}: refused, and wrote capx")
    # 11: files longer than their header, a frame that is a folder, a long format, an
    # upper-case CRC, a long output name, the border, a negative error map.
    (work / "trailing.npy").write_bytes((work / "truth.npy").read_bytes() + b"\0" * 8)
    s.run(["eval", "truth.npy", "trailing.npy"], "eval a .npy longer than its header", refuse=True)
    shutil.copytree(work / "cap", work / "cap-dir")
    os.remove(work / "cap-dir" / "snapshot_0.npy")
    (work / "cap-dir" / "snapshot_0.npy").mkdir()
    s.run(["decode", "cap-dir", "-o", "x.npy", "-q"], "decode a capture whose frame is a folder", refuse=True)
    shutil.copytree(work / "cap", work / "cap-long")
    desc = (work / "cap-long" / "capture.json").read_text()
    (work / "cap-long" / "capture.json").write_text(desc.replace('"format": "', '"format": "' + "x" * 10_000_000, 1))
    s.run(["decode", "cap-long", "-o", "x.npy", "-q"], "decode a capture of a 10 MB format", refuse=True)
    shutil.copytree(work / "cap", work / "cap-upper")
    import re
    path = work / "cap-upper" / "capture.json"
    path.write_text(re.sub(r'"crc32": "([0-9a-f]+)"', lambda m: f'"crc32": "{m.group(1).upper()}"', path.read_text()))
    long_name = "a" * 246 + ".npy"
    s.run(["decode", "cap-upper", "-o", long_name, "-q"], "decode an upper-case CRC to a 250-byte name",
          outputs=[long_name])
    s.run(["eval", "truth.npy", "truth.npy", "--border", "7"], "eval --border 7 on 12 lenslets", refuse=True)
    (work / "neg.npy").write_bytes(npy("<f4", (12, 12), struct.pack("<f", -1.0) * 144))
    s.run(["eval", "truth.npy", "truth.npy", "--error-map", "neg.npy"], "eval a negative error map", refuse=True)
    # 9: flags the baselines would ignore; 8, 12: a FIFO as the output.
    for extra in [["--shear-trial", "true"], ["--shear-check"], ["--model-trial", "true"]]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", "--method", "demosaic", *extra],
              f"decode --method demosaic {' '.join(extra)}", refuse=True)
    s.run(["decode", "cap", "-o", "fifo.npy", "-q"], "decode -o a FIFO", refuse=True)
    # 4: the chunked outputs, HDF5 and a Zarr store: written, replaced, and refused over
    # what is not theirs (a file, a user's folder, the capture, a map inside the store).
    capture_files = [str(p) for p in (work / "cap").iterdir()]
    for out, extra in [("o.h5", []), ("o.h5", ["--deflate", "9"]), ("o.zarr", []), ("o.zarr", ["--deflate", "1"]),
                       ("o.zarr", ["--method", "ppid"])]:
        s.run(["decode", "cap", "-o", out, "-q", *extra], f"decode -o {out} {' '.join(extra)}", outputs=[out],
              keep=capture_files)
    (work / "file.zarr").write_text("mine")
    (work / "mine.zarr").mkdir(exist_ok=True)
    (work / "mine.zarr" / "notes.txt").write_text("mine")
    for out, extra in [("file.zarr", []), ("mine.zarr", []), ("cap", ["--format", "zarr"]),
                       ("o.zarr", ["--error-map", "o.zarr/em.npy"]), ("o.zarr", ["--dtype", "u16"]),
                       ("o.zarr", ["--deflate", "0"]), ("o.zarr", ["--deflate", "10"]), ("", ["--format", "zarr"]),
                       ("missing/o.zarr", [])]:
        s.run(["decode", "cap", "-o", out, "-q", *extra], f"decode -o {out!r} {' '.join(extra)}", refuse=True,
              keep=capture_files + [str(work / "file.zarr"), str(work / "mine.zarr" / "notes.txt")])
    # 7: a long table in alternating order (quadratic once: past 120 s at 100,000 rows).
    header = (work / "header.csv").read_text()
    rows = "".join(f"{m},3,x{i},30,0.9,4,1,0.5,1,2,true\n" for i, m in
                   zip(range(100_000), ["pixel", "lenslet"] * 50_000))
    (work / "long.csv").write_text(header + rows)
    s.run(["bench", "--from", "long.csv", "--out", "bench-long"], "bench --from 100,000 alternating rows")
    # 3: a .npy of 2^30 values, inside the documented cap, past the run's memory.
    sparse(work / "g30.npy", npy("<f4", (8, 8, 1024, 1024, 16)), 128 + 4 * (1 << 30))
    for args in [["eval", "g30.npy", "g30.npy"], ["simulate", "g30.npy", "-o", "g30-cap"],
                 ["import", "bands", "g30.npy", "--wavelengths", "400:775:25", "-o", "imp.npy"]]:
        s.run(args, f"{args[0]} a .npy of 2^30 values", refuse=True)


def python_cases(s):
    """Issue 51, 13 and 14: the Python package's None, string booleans and empty paths, when
    PYTHON imports slf (SLF_SWEEP_ONLY=python runs these alone)."""
    probe = subprocess.run([PYTHON, "-c", "import slf"], capture_output=True)
    if probe.returncode != 0:
        print(f"note: {PYTHON} does not import slf: the package's cases are skipped (set SLF_PYTHON)")
        return
    pre = "import slf, numpy as np; lf = slf.scene('smooth', size=12); cap = slf.simulate(lf)\n"
    for label, code in [("noise='no'", "slf.simulate(lf, noise='no')"),
                        ("edge_fallback='false'", "slf.decode(cap, edge_fallback='false')"),
                        ("seeded='false'", "slf.decode(cap, seeded='false')"),
                        ("Capture.save('')", "cap.save('')"),
                        ("calibrate('cc', '')", "slf.calibrate('cc', '')"),
                        ("simulate(calibration_captures='')", "slf.simulate(lf, leakage=0.1, calibration_captures='')"),
                        ("decode(output='')", "slf.decode(cap, output='')")]:
        s.run([], f"python: {label}", python=pre + code, refuse=True)
    # Issue 65: outputs over the decode's own inputs; keywords of the wrong kind.
    for label, code in [("decode(output=its own frame)",
                         "cap.save('pcap'); c = slf.load_capture('pcap'); slf.decode(c, output='pcap/' + "
                         "[f for f in __import__('os').listdir('pcap') if f.startswith('snapshot')][0])"),
                        ("decode(progress=5)", "slf.decode(cap, progress=5)"),
                        ("simulate(exposures=-1)", "slf.simulate(lf, leakage=0.1, calibration_captures='pcc', "
                                                   "exposures=-1)"),
                        ("decode(error_map=True, method='demosaic')",
                         "slf.decode(cap, error_map=True, method='demosaic')")]:
        s.run([], f"python: {label}", python=pre + code, refuse=True)
    s.run([], "python: noise=None is noise on", python=pre + (
        "a = slf.simulate(lf, seed=3, noise=None).frames; b = slf.simulate(lf, seed=3).frames\n"
        "assert np.array_equal(a, b), 'noise=None is not the default'"))


def main():
    work = Path(tempfile.mkdtemp(prefix="slf-sweep-"))
    s = Sweep(work)
    if os.environ.get("SLF_SWEEP_ONLY") == "python":
        (work / "cc").mkdir()
        python_cases(s)
        return report(s, work)
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
                 "--hot-pixels", "--prnu", "--vignetting", "--sensor-seed", "--exposures", "--rotation", "--pitch",
                 "--grid-offset"]:
        for v in ["nan", "inf", "-1", "1e39", "", "x", "0.99"]:
            s.run(["simulate", "truth.npy", "-o", "sim-out", "--calibration-captures", "cal-caps", flag, v],
                  f"simulate {flag} {v!r}")

    # A lenslet grid a decode is asked to read through, named wrongly or on an aligned capture.
    for v in ["", "x", "nan", "Aligned", "capture,aligned"]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", "--grid", v], f"decode --grid {v!r}")
    for v in ["auto", "capture", "aligned"]:
        s.run(["decode", "cap", "-o", "x.npy", "-q", "--grid", v, "--method", "demosaic"], f"decode --grid {v} (aligned)")

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
                  ["--coverage-map", "cap/snapshot_0.npy"], ["--coverage-map", "x.npy"],
                  ["--method", "demosaic", "--coverage-map", "c.npy"],
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

    issue_51(s, work, ok)

    return report(s, work)


def report(s, work):
    for f in s.failures:
        print("FAIL", f)
    print(f"hostile sweep: {s.cases} cases, {s.refused} refused with one line, {s.accepted} accepted, "
          f"{len(s.failures)} failures")
    shutil.rmtree(work, ignore_errors=True)
    return 1 if s.failures else 0


if __name__ == "__main__":
    sys.exit(main())
