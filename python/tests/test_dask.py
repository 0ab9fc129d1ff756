"""Many captures on a local Dask cluster of 2 worker processes (loopback only): every
output equals the single-process decode, a broken capture is reported and loses nothing
else, and the documented example script does the same."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import slf
import slf.batch

from dask import distributed

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "decode_folder.py"


@pytest.fixture(scope="module")
def folder(tmp_path_factory, depth):
    """Four captures of the depth scene (seeds 1..4) and one with a truncated frame."""
    root = tmp_path_factory.mktemp("captures")
    for seed in range(1, 5):
        slf.simulate(depth, k=1, seed=seed).save(root / f"cap{seed}")
    slf.simulate(depth, k=1, seed=9).save(root / "broken")
    (root / "broken" / "snapshot_0.pgm").write_bytes(b"P5\n100 100\n65535\n" + b"\x00" * 10)
    return root


def expected(folder, name):
    return slf.decode(folder / name, preset="preview", threads=1)


def test_local_cluster_matches_single_process(folder, tmp_path):
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        seen = []
        results = slf.batch.decode_folder(folder, tmp_path / "out", client, on_result=seen.append, preset="preview")
    assert [r.name for r in results] == ["broken", "cap1", "cap2", "cap3", "cap4"]
    assert sorted(r.name for r in seen) == sorted(r.name for r in results)
    broken, good = results[0], results[1:]
    assert not broken.ok and "snapshot_0.pgm" in broken.error and broken.output is None
    assert not (tmp_path / "out" / "broken.npy").exists()
    for r in good:
        assert r.ok, r.error
        assert np.array_equal(np.load(r.output), expected(folder, r.name)), r.name
    # Different captures, different light fields: the outputs are not one file four times.
    assert not np.array_equal(np.load(good[0].output), np.load(good[1].output))


def test_in_process_without_a_client(folder, tmp_path):
    results = slf.batch.decode_folder([folder / "cap1", folder / "broken"], tmp_path, preset="preview")
    assert [r.ok for r in results] == [True, False]
    assert np.array_equal(np.load(results[0].output), expected(folder, "cap1"))


def test_example_script(folder, tmp_path):
    p = subprocess.run(
        [sys.executable, str(EXAMPLE), str(folder), str(tmp_path), "--workers", "2", "--preset", "preview"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 1, p.stdout + p.stderr  # one capture failed, the others decoded
    assert "broken: FAILED" in p.stdout and "decoded 4 of 5 captures" in p.stdout, p.stdout
    for seed in range(1, 5):
        assert np.array_equal(np.load(tmp_path / f"cap{seed}.npy"), expected(folder, f"cap{seed}"))


def test_no_captures_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="no capture folders"):
        slf.batch.captures_in(tmp_path)


def test_an_output_is_never_a_capture_file_or_another_output(folder, tmp_path, depth):
    """Issue 41, item 6 for the package: refused before any task runs, nothing written."""
    # A capture folder named like its own frame, decoded into itself.
    cap = tmp_path / "snapshot_0"
    slf.simulate(depth, k=1, seed=1, format="npy").save(cap)
    before = (cap / "snapshot_0.npy").read_bytes()
    with pytest.raises(ValueError, match="would be a file of the capture"):
        slf.batch.decode_folder([cap], cap, preset="preview")
    assert (cap / "snapshot_0.npy").read_bytes() == before
    # Two folders of one name.
    other = tmp_path / "again" / "cap1"
    slf.simulate(depth, k=1, seed=2).save(other)
    out = tmp_path / "out"
    with pytest.raises(ValueError, match="would both write"):
        slf.batch.decode_folder([folder / "cap1", other], out, preset="preview")
    assert not out.exists()


def test_a_folder_decoded_into_one_zarr_store(folder, tmp_path):
    """Issue 65, item 4: many captures along a capture axis of one store, each written by
    its own task on its own worker; a failed capture's slot is NaN and its error kept."""
    import xarray
    import zarr

    small = tmp_path / "small"  # another shape: refused a slot, the others go on
    slf.simulate(slf.scene("depth", size=12), k=1, seed=5).save(small)
    out = tmp_path / "all.zarr"
    captures = [folder / "cap1", folder / "broken", small, folder / "cap2"]
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        seen = []
        results = slf.batch.decode_folder(captures, out, client, on_result=seen.append, preset="preview")
    assert [r.ok for r in results] == [True, False, False, True], [r.error for r in results]
    assert [r.index for r in results] == [0, 1, 2, 3] and len(seen) == 4
    assert "snapshot_0.pgm" in results[1].error
    assert "not the store's (5, 5, 20, 20, 13)" in results[2].error, results[2].error
    group = zarr.open_group(out, mode="r")
    lf = group["lightfield"]
    assert lf.shape == (4, 5, 5, 20, 20, 13) and lf.chunks[:4] == (1, 5, 5, 8), lf.chunks
    assert lf.metadata.dimension_names == ("capture", "u", "v", "h", "w", "band")
    for i, name in [(0, "cap1"), (3, "cap2")]:
        assert np.array_equal(lf[i], expected(folder, name)), name
    assert np.isnan(lf[1]).all() and np.isnan(lf[2]).all()
    attrs = dict(group.attrs)
    assert attrs["captures"] == ["cap1", "broken", "small", "cap2"]
    assert attrs["decoded"] == [True, False, False, True]
    assert attrs["errors"][0] is None and "snapshot_0.pgm" in attrs["errors"][1]
    assert attrs["options"] == {"preset": "preview"} and attrs["axes"] == "cuvhwb"
    # Lazily, by band centre, in xarray.
    data = xarray.open_zarr(out)["lightfield"]
    assert data.dims == ("capture", "u", "v", "h", "w", "band")
    nm = float(data["band"][4])
    assert np.array_equal(data.sel(band=nm).isel(capture=3).values, expected(folder, "cap2")[..., 4])
    # Nothing temporary is left beside it.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["all.zarr", "small"]


def test_a_store_in_which_nothing_decoded_is_not_written(folder, tmp_path):
    out = tmp_path / "none.zarr"
    with pytest.raises(ValueError, match="no capture decoded .*snapshot_0.pgm.*nothing written"):
        slf.batch.decode_folder([folder / "broken"], out, preset="preview")
    assert list(tmp_path.iterdir()) == []
    # A capture inside the store it would be written into is refused before any task.
    inside = tmp_path / "in.zarr" / "cap"
    (tmp_path / "in.zarr").mkdir()
    (tmp_path / "in.zarr" / "zarr.json").write_text('{"zarr_format": 3, "node_type": "group"}')
    slf.simulate(slf.scene("depth", size=12), k=1, seed=5).save(inside)
    with pytest.raises(ValueError, match="in.zarr holds a capture folder .*in.zarr.cap"):
        slf.batch.decode_folder([inside], tmp_path / "in.zarr", preset="preview")
    assert (inside / "capture.json").exists()


def test_a_decode_to_a_zarr_store_returns_it_opened(folder, tmp_path):
    import zarr

    out = tmp_path / "one.zarr"
    lf = slf.decode(folder / "cap3", preset="preview", threads=1, output=out)
    assert isinstance(lf, zarr.Array) and np.array_equal(lf[...], expected(folder, "cap3"))
    assert "description" in dict(zarr.open_group(out, mode="r").attrs)
    with pytest.raises(TypeError, match="slot"):
        slf.decode(folder / "cap3", preset="preview", output=out, slot=-1)
