"""Fixtures of the slf package's tests: the `slf` command to compare against, small
scenes and captures made once per session."""

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import slf

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def slf_bin() -> str:
    """The `slf` command: $SLF_BIN, else the repository's release build, else on PATH.
    The CLI comparisons need it; its absence is a failure, not a skip."""
    for candidate in (os.environ.get("SLF_BIN"), REPO / "target" / "release" / "slf", shutil.which("slf")):
        if candidate and Path(candidate).is_file():
            return str(candidate)
    pytest.fail("no slf command: build it (cargo build --release -p slf-host) or set SLF_BIN")


def run(cmd, **kw) -> subprocess.CompletedProcess:
    """Runs a command; its output is shown if it fails."""
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    assert p.returncode == 0, f"{cmd}: exit {p.returncode}\n{p.stdout}\n{p.stderr}"
    return p


@pytest.fixture(scope="session")
def depth() -> np.ndarray:
    """`slf scene depth --size 20`: 5 x 5 views of 20 x 20 lenslets."""
    return slf.scene("depth", size=20)


@pytest.fixture(scope="session")
def capture(depth) -> slf.Capture:
    """The depth scene at pixel k = 1, seed 1, with noise."""
    return slf.simulate(depth, k=1)
