"""Decode a folder of captures on Dask, each capture a task, and say how fast.

    python examples/decode_folder.py CAPTURES OUT [--workers 2] [--preset default]
    python examples/decode_folder.py CAPTURES OUT --scheduler tcp://host:8786

CAPTURES holds capture folders (as `slf simulate -o` writes them); each decoded light field
is written to OUT/<name>.npy as soon as its task ends. Without --scheduler a LocalCluster of
--workers processes (one thread each) runs on this machine, on loopback; with it, the tasks
go to a running cluster (started with Dask's own tools: `dask scheduler` and `dask worker`,
dask-jobqueue on SLURM or PBS, dask-kubernetes), whose workers must see both folders.
A capture that fails is reported with its error and the others go on; the exit status is 1
if any failed, 2 if none decoded.
"""

import argparse
import sys
import time

from dask.distributed import Client, LocalCluster

import slf.batch


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("captures", help="folder of capture folders")
    p.add_argument("out", help="output folder (one .npy per capture)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler instead of a LocalCluster")
    p.add_argument("--preset", default="default", choices=["preview", "default", "best"])
    a = p.parse_args(argv)

    if a.scheduler:
        client, cluster = Client(a.scheduler), None
    else:
        cluster = LocalCluster(
            n_workers=a.workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
        )
        client = Client(cluster)
    try:
        start = time.perf_counter()

        def said(r: slf.batch.Result) -> None:
            print(f"{r.name}: wrote {r.output} in {r.seconds:.2f} s" if r.ok else f"{r.name}: FAILED: {r.error}", flush=True)

        results = slf.batch.decode_folder(a.captures, a.out, client, on_result=said, preset=a.preset)
        wall = time.perf_counter() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    ok = sum(r.ok for r in results)
    workers = a.scheduler or f"{a.workers} workers"
    print(f"decoded {ok} of {len(results)} captures in {wall:.2f} s on {workers}: {ok / wall:.3f} captures/s")
    return 2 if ok == 0 else (1 if ok < len(results) else 0)


if __name__ == "__main__":
    sys.exit(main())
