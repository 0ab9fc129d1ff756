"""Many captures at once: a folder of capture folders (a sequence, a dataset) decoded on a
Dask cluster, each capture a task.

::

    from dask.distributed import Client, LocalCluster
    import slf.batch

    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        results = slf.batch.decode_folder("captures/", "decoded/", client, preset="default")
    for r in results:
        print(r.name, r.ok, r.seconds if r.ok else r.error)

Each task loads one capture, decodes it with one thread (``threads=1``: Dask's worker
threads are the parallelism) and writes ``OUT/<name>.npy`` itself, on the worker, as its
rows are decoded (``slf.decode(..., output=)``: a worker holds a band of rows, not the frame;
the file goes to a temporary name and is renamed when done, so a file that exists is whole). A
capture that fails is reported in its result with the one-line error; the others go on.
On a real cluster the same call runs with a ``Client`` of Dask's own deployments
(``dask-scheduler`` / ``dask-worker``, dask-jobqueue for SLURM and PBS, dask-kubernetes):
the folders must then be on storage every worker sees.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterable, List, Optional, Union


PathLike = Union[str, "os.PathLike[str]"]


@dataclass
class Result:
    """One capture's outcome: where its light field went, or why it did not."""

    name: str
    """The capture folder's name (the output is ``<name>.npy``)."""
    capture: str
    """The capture folder."""
    output: Optional[str]
    """The light field ``.npy`` written, or None if the capture failed."""
    seconds: float
    """The task's wall time (load, decode and write)."""
    error: Optional[str] = None
    """The one-line error of a capture that failed."""

    @property
    def ok(self) -> bool:
        return self.error is None


def captures_in(folder: PathLike) -> List[str]:
    """The capture folders in ``folder`` (each holding a ``capture.json``), sorted by name;
    ``folder`` itself if it is one."""
    folder = os.fspath(folder)
    if os.path.isfile(os.path.join(folder, "capture.json")):
        return [folder]
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"{folder}: no such folder")
    found = sorted(
        os.path.join(folder, n) for n in os.listdir(folder) if os.path.isfile(os.path.join(folder, n, "capture.json"))
    )
    if not found:
        raise ValueError(f"{folder}: no capture folders (folders holding a capture.json)")
    return found


def check_outputs(captures: List[str], out_dir: str) -> None:
    """Refuses, before any task runs, a run whose output ``out_dir/<name>.npy`` would be a
    file of a capture (its ``capture.json`` or a frame) or another capture's output (two
    folders of one name): the same rule ``slf`` keeps for its commands. Paths are compared
    resolved."""
    import json

    inputs = {}
    for c in captures:
        files = ["capture.json"]
        try:
            with open(os.path.join(c, "capture.json"), encoding="utf-8") as f:
                frames = json.load(f).get("frames", [])
            files += [n for n in frames if isinstance(n, str)]
        except (OSError, ValueError, AttributeError):
            pass  # the task reports a capture it cannot read
        for n in files:
            inputs[os.path.realpath(os.path.join(c, n))] = c
    seen = {}
    for c in captures:
        path = os.path.realpath(os.path.join(out_dir, os.path.basename(os.path.normpath(c)) + ".npy"))
        if path in inputs:
            raise ValueError(f"{path}: the output of {c} would be a file of the capture {inputs[path]}")
        if path in seen:
            raise ValueError(f"{c} and {seen[path]} would both write {path}: give folders of distinct names")
        seen[path] = c


def decode_one(capture: str, out_dir: str, options: dict) -> Result:
    """Decodes one capture folder into ``out_dir/<name>.npy``: the task each capture is.
    Never raises for a bad capture: the error is the result's."""
    import slf

    start = time.perf_counter()
    name = os.path.basename(os.path.normpath(capture))
    try:
        os.makedirs(out_dir, exist_ok=True)
        path = os.path.join(out_dir, name + ".npy")
        # Written as it is decoded: the worker holds a band of rows, not the frame, and the
        # file is in place only once the decode is done.
        slf.decode(capture, **{"threads": 1, **options, "output": path})
        return Result(name, capture, path, time.perf_counter() - start)
    except (ValueError, OSError) as e:
        return Result(name, capture, None, time.perf_counter() - start, f"{type(e).__name__}: {e}")


def decode_folder(
    folder: Union[PathLike, Iterable[PathLike]],
    out_dir: PathLike,
    client: Any = None,
    on_result: Optional[Callable[[Result], None]] = None,
    **options: Any,
) -> List[Result]:
    """Decodes every capture of ``folder`` (or of a list of capture folders) into
    ``out_dir``, one Dask task per capture, on ``client`` (a ``dask.distributed.Client``;
    None: in this process, one after another). ``options`` are :func:`slf.decode`'s
    keywords (``preset="preview"``, ...). ``on_result`` is called with each result as it
    arrives. Returns the results in the captures' order."""
    if isinstance(folder, (str, os.PathLike)):
        captures = captures_in(folder)
    else:
        captures = [os.fspath(c) for c in folder]
    out = os.fspath(out_dir)
    check_outputs(captures, out)
    if client is None:
        results = []
        for c in captures:
            r = decode_one(c, out, options)
            if on_result is not None:
                on_result(r)
            results.append(r)
        return results
    from dask.distributed import as_completed

    futures = [client.submit(decode_one, c, out, options, pure=False) for c in captures]
    index = {f.key: i for i, f in enumerate(futures)}
    done: List[Optional[Result]] = [None] * len(captures)
    for future in as_completed(futures):
        i = index[future.key]
        if future.status == "error":
            # The task itself failed (a worker died, a bug): the capture is reported, the
            # others go on.
            exc = future.exception()
            name = os.path.basename(os.path.normpath(captures[i]))
            r = Result(name, captures[i], None, 0.0, f"{type(exc).__name__}: {exc}")
        else:
            r = future.result()
        done[i] = r
        if on_result is not None:
            on_result(r)
    return [r for r in done if r is not None]
