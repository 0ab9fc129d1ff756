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

With an output ending in ``.zarr`` every capture goes into one Zarr v3 store along a capture
axis: ``lightfield`` is float32 ``(N, U, V, H, W, 13)`` with dimension names ``capture, u, v,
h, w, band``, in chunks of one capture, so each task writes its own chunks, from any
worker, as its rows are decoded. The store is made in a temporary folder and put in place
whole once every task has ended; its attributes name the captures (``captures``) and give
each one's outcome (``decoded``, ``errors``, ``seconds``). A capture that failed, or whose
shape differs from the first capture's, leaves its slot NaN (the fill value)::

    results = slf.batch.decode_folder("captures/", "decoded.zarr", client)
    lf = xarray.open_zarr("decoded.zarr")["lightfield"]   # lazy, a chunk at a time
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterable, List, Optional, Tuple, Union


PathLike = Union[str, "os.PathLike[str]"]


@dataclass
class Result:
    """One capture's outcome: where its light field went, or why it did not."""

    name: str
    """The capture folder's name (the output is ``<name>.npy``)."""
    capture: str
    """The capture folder."""
    output: Optional[str]
    """The light field ``.npy`` written (or the store written into), or None if the capture
    failed."""
    seconds: float
    """The task's wall time (load, decode and write)."""
    error: Optional[str] = None
    """The one-line error of a capture that failed."""
    index: Optional[int] = None
    """The capture's index along the store's capture axis (a ``.zarr`` output)."""

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
    None: in this process, one after another). ``out_dir``: a folder for one
    ``<name>.npy`` per capture, or a path ending in ``.zarr`` for one store of them all
    along a capture axis (see the module's docs; ``gzip=1..9`` compresses its chunks).
    ``options`` are :func:`slf.decode`'s keywords (``preset="preview"``, ...).
    ``on_result`` is called with each result as it arrives. Returns the results in the
    captures' order; a store in which no capture decoded is not written, and raises."""
    if isinstance(folder, (str, os.PathLike)):
        captures = captures_in(folder)
    else:
        captures = [os.fspath(c) for c in folder]
    out = os.fspath(out_dir)
    for taken in ("output", "slot"):
        if taken in options:
            raise TypeError(f"{taken}: decode_folder sets each capture's output itself")
    gzip = options.pop("gzip", None)
    if out.lower().endswith(".zarr"):
        return _into_store(captures, out, client, on_result, options, gzip)
    if gzip is not None:
        raise TypeError("gzip: compresses a .zarr store's chunks; give an output ending in .zarr")
    check_outputs(captures, out)
    return _run(captures, [(decode_one, (c, out, options)) for c in captures], client, on_result)


def _run(
    captures: List[str],
    tasks: List[Any],
    client: Any,
    on_result: Optional[Callable[[Result], None]],
) -> List[Result]:
    """Runs ``tasks`` (``(function, args)``, one per capture) here or on ``client``; a
    task that fails itself (a worker died, a bug) is reported as its capture's error."""
    if client is None:
        results = []
        for f, args in tasks:
            r = f(*args)
            if on_result is not None:
                on_result(r)
            results.append(r)
        return results
    from dask.distributed import as_completed

    futures = [client.submit(f, *args, pure=False) for f, args in tasks]
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


def _shape_of(capture: str) -> Optional[Tuple[Tuple[int, int, int, int, int], List[float]]]:
    """A capture's light-field shape ``(U, V, H, W, B)`` and band centres from its
    ``capture.json``, or None if it cannot be read (its task then reports why)."""
    import json

    try:
        with open(os.path.join(capture, "capture.json"), encoding="utf-8") as f:
            d = json.load(f)
        (u, v), (h, w), bands = d["views"], d["lenslets"], [float(b) for b in d["bands_nm"]]
        return (int(u), int(v), int(h), int(w), len(bands)), bands
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _into_store(
    captures: List[str],
    out: str,
    client: Any,
    on_result: Optional[Callable[[Result], None]],
    options: dict,
    gzip: Optional[int],
) -> List[Result]:
    """Every capture into slot ``i`` of one store at ``out`` (see the module's docs)."""
    import json

    from . import _slf

    shapes = [_shape_of(c) for c in captures]
    first = next((s for s in shapes if s is not None), None)
    if first is None:
        raise ValueError(f"{out}: no capture's capture.json gives its views, lenslets and bands_nm")
    shape, bands = first
    name = lambda c: os.path.basename(os.path.normpath(c))  # noqa: E731
    reference = name(captures[shapes.index(first)])
    stack = _slf.Stack(out, len(captures), shape, bands, captures, gzip)
    try:
        tasks = []
        refused = {}
        for i, (c, s) in enumerate(zip(captures, shapes)):
            if s is not None and s != first:
                refused[i] = Result(
                    name(c), c, None, 0.0,
                    f"ValueError: {c}: light field {s[0]} at {s[1]} nm, not the store's {shape} at {bands} nm "
                    f"(of {reference}, the first capture)",
                    index=i,
                )
            tasks.append((decode_slot, (c, stack.path, i, out, options)))
        run = [t for i, t in enumerate(tasks) if i not in refused]
        ran = iter(_run([c for i, c in enumerate(captures) if i not in refused], run, client, on_result))
        results = [refused[i] if i in refused else next(ran) for i in range(len(captures))]
        for i, r in refused.items():
            if on_result is not None:
                on_result(r)
        if not any(r.ok for r in results):
            first_error = next(r for r in results if not r.ok)
            raise ValueError(
                f"{out}: no capture decoded ({len(results)} failed; {first_error.name}: {first_error.error}); "
                "nothing written"
            )
        attrs = {
            "captures": [r.name for r in results],
            "capture_folders": [os.path.abspath(r.capture) for r in results],
            "decoded": [r.ok for r in results],
            "errors": [r.error for r in results],
            "seconds": [r.seconds for r in results],
            "options": {k: v if isinstance(v, (str, int, float, bool, type(None))) else repr(v) for k, v in options.items()},
        }
        stack.finish(json.dumps(attrs))
    except BaseException:
        stack.discard()
        raise
    return results


def decode_slot(capture: str, store: str, index: int, out: str, options: dict) -> Result:
    """Decodes one capture folder into slot ``index`` of the temporary ``store`` that will
    become ``out``: the task each capture is. Never raises for a bad capture: the error is
    the result's."""
    import slf

    start = time.perf_counter()
    name = os.path.basename(os.path.normpath(capture))
    try:
        slf.decode(capture, **{"threads": 1, **options, "output": store, "slot": index})
        return Result(name, capture, out, time.perf_counter() - start, index=index)
    except (ValueError, OSError) as e:
        return Result(name, capture, None, time.perf_counter() - start, f"{type(e).__name__}: {e}", index=index)
