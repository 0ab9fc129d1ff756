"""The package gives the command's results: the same scene, the same capture, the same
decode bit for bit, the same metrics; captures round-trip between the two."""

import json
import re
import subprocess
import zlib

import numpy as np
import pytest

import slf
from conftest import run


def test_scene_equals_cli(tmp_path, slf_bin):
    run([slf_bin, "scene", "outdoor", "--size", "24", "--views", "4", "--seed", "3", "-o", tmp_path / "s.npy"])
    assert np.array_equal(slf.scene("outdoor", size=24, views=4, seed=3), np.load(tmp_path / "s.npy"))


def test_simulate_equals_cli_and_round_trips(tmp_path, slf_bin, depth):
    np.save(tmp_path / "lf.npy", depth)
    run([slf_bin, "simulate", tmp_path / "lf.npy", "-o", tmp_path / "cli", "--mask", "lenslet", "-s", "3", "--seed", "7"])
    from_cli = slf.load_capture(tmp_path / "cli")
    ours = slf.simulate(depth, mask="lenslet", k=3, seed=7)
    assert ours.frames.shape == (3, 100, 100)
    assert np.array_equal(ours.frames, from_cli.frames)
    assert ours.description == from_cli.description
    # Python's folder read back by Python and by the command's decode.
    ours.save(tmp_path / "py")
    again = slf.load_capture(tmp_path / "py")
    assert np.array_equal(again.frames, ours.frames) and again.description == ours.description
    written = json.loads((tmp_path / "py" / "capture.json").read_text())
    # Beside the description, each frame's size and CRC-32 as written (issue 51), checked
    # here with zlib's CRC-32.
    records = written.pop("files")
    assert written == ours.description
    assert [r["name"] for r in records] == ours.description["frames"]
    for r in records:
        data = (tmp_path / "py" / r["name"]).read_bytes()
        assert r["bytes"] == len(data) and r["crc32"] == f"{zlib.crc32(data):08x}"


def test_a_real_sensor_equals_cli(tmp_path, slf_bin, depth):
    np.save(tmp_path / "lf.npy", depth)
    flags = ["--leakage", "0.1", "--vignetting", "0.5", "--dark-sd", "3", "--prnu", "0.01", "--hot-pixels", "0.001", "--sensor-seed", "4"]
    run([slf_bin, "simulate", tmp_path / "lf.npy", "-o", tmp_path / "cli", "--seed", "7", *flags])
    from_cli = slf.load_capture(tmp_path / "cli")
    ours = slf.simulate(depth, seed=7, leakage=0.1, vignetting=0.5, dark_sd=3, prnu=0.01, hot_pixels=0.001, sensor_seed=4)
    assert np.array_equal(ours.frames, from_cli.frames)
    assert ours.description == from_cli.description
    assert ours.description["version"] == 2 and ours.description["simulated_sensor"]["filters"]["leakage"] == pytest.approx(0.1)
    ideal = slf.simulate(depth, seed=7)
    assert "simulated_sensor" not in ideal.description and not np.array_equal(ideal.frames, ours.frames)


def test_a_turned_lenslet_grid_equals_cli(tmp_path, slf_bin, depth):
    """The grid keywords are the flags: the same capture, the grid found by calibrate, the
    same decodes through it and as if aligned."""
    np.save(tmp_path / "lf.npy", depth)
    flags = ["--rotation", "0.4", "--pitch", "5.06,5.03", "--vignetting", "0.3"]
    run([slf_bin, "simulate", tmp_path / "lf.npy", "-o", tmp_path / "cap", "--seed", "7", *flags, "--calibration-captures", tmp_path / "cc", "--exposures", "1"])
    ours = slf.simulate(depth, seed=7, rotation=0.4, pitch=(5.06, 5.03), vignetting=0.3)
    from_cli = slf.load_capture(tmp_path / "cap")
    assert np.array_equal(ours.frames, from_cli.frames) and ours.description == from_cli.description
    grid = ours.description["lenslet_grid"]
    assert grid["rotation_deg"] == 0.4 and grid["pitch"] == [5.06, 5.03]
    assert ours.frames.shape == (1, round(20 * 5.06), round(20 * 5.03)) == (1, grid["sensor"][0], grid["sensor"][1])
    lines = slf.calibrate(tmp_path / "cc", tmp_path / "cal")
    assert any(line.startswith("lenslet grid: rotation 0.4") for line in lines), lines
    for grid_choice in ["auto", "aligned"]:
        run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "cli.npy", "--calibration", tmp_path / "cal", "--grid", grid_choice])
        decoded = slf.decode(tmp_path / "cap", calibration=tmp_path / "cal", grid=grid_choice)
        assert np.array_equal(decoded, np.load(tmp_path / "cli.npy")), grid_choice
    # The baselines read the grid too (issue 66, item 3).
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "cli.npy", "--method", "demosaic"])
    assert np.array_equal(slf.decode(tmp_path / "cap", method="demosaic"), np.load(tmp_path / "cli.npy"))


def test_a_calibrated_decode_equals_cli(tmp_path, slf_bin, depth):
    np.save(tmp_path / "lf.npy", depth)
    flags = ["--leakage", "0.1", "--vignetting", "0.4", "--dark-sd", "2", "--hot-pixels", "0.001"]
    run([slf_bin, "simulate", tmp_path / "lf.npy", "-o", tmp_path / "cap", *flags, "--calibration-captures", tmp_path / "cal", "--exposures", "2"])
    run([slf_bin, "calibrate", tmp_path / "cal", "-o", tmp_path / "calibration"])
    # The package's calibration captures are the command's, file for file.
    sensor = dict(leakage=0.1, vignetting=0.4, dark_sd=2, hot_pixels=0.001)
    slf.simulate(depth, calibration_captures=tmp_path / "py-cal", exposures=2, **sensor)
    cli_files = sorted(p.relative_to(tmp_path / "cal") for p in (tmp_path / "cal").rglob("*") if p.is_file())
    py_files = sorted(p.relative_to(tmp_path / "py-cal") for p in (tmp_path / "py-cal").rglob("*") if p.is_file())
    assert cli_files == py_files and len(cli_files) > 0
    for f in cli_files:
        assert (tmp_path / "cal" / f).read_bytes() == (tmp_path / "py-cal" / f).read_bytes(), f
    # The package's calibration is the command's, file for file.
    lines = slf.calibrate(tmp_path / "cal", tmp_path / "py-calibration")
    assert len(lines) == 2 and "calibration:" in lines[0]
    for name in ["calibration.json", "dark.npy", "flat.npy"]:
        assert (tmp_path / "calibration" / name).read_bytes() == (tmp_path / "py-calibration" / name).read_bytes(), name
    with pytest.raises(ValueError, match="a scene's capture"):
        slf.calibrate([tmp_path / "cap", tmp_path / "cal"], tmp_path / "bad")
    for method in ["cs", "demosaic"]:
        run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "cli.npy", "--method", method, "--calibration", tmp_path / "calibration"])
        ours = slf.decode(tmp_path / "cap", method=method, calibration=tmp_path / "calibration")
        assert np.array_equal(ours, np.load(tmp_path / "cli.npy")), method
    # The response in the solve's projection, by keyword as by flag.
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "cli.npy", "--calibration", tmp_path / "calibration", "--response-model", "projection"])
    projected = slf.decode(tmp_path / "cap", calibration=tmp_path / "calibration", response_model="projection")
    assert np.array_equal(projected, np.load(tmp_path / "cli.npy"))
    assert not np.array_equal(projected, slf.decode(tmp_path / "cap", calibration=tmp_path / "calibration"))
    plain = slf.decode(tmp_path / "cap", method="demosaic")
    assert not np.array_equal(plain, ours)


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        ([], {}),
        (["--preset", "preview"], {"preset": "preview"}),
        (["--stride", "5", "--disparities", "-1:1", "--dictionary", "dct"], {"stride": 5, "disparities": (-1, 1), "dictionary": "dct"}),
        (["--seeded", "false", "--dictionary", "dct"], {"seeded": False, "dictionary": "dct"}),
        (["--seed-sigma-f", "0.8", "--dictionary", "dct", "--schedule", "annealed"], {"seed_sigma_f": 0.8, "dictionary": "dct", "schedule": "annealed"}),
        (["--schedule", "annealed"], {"schedule": "annealed"}),
        (["--patch-views", "4"], {"patch_views": 4}),
        (["--patch-views", "5", "--preset", "preview"], {"patch_views": 5, "preset": "preview"}),
        (["--plausible", "off", "--dictionary", "dct"], {"plausible": "off", "dictionary": "dct"}),
        (["--plausible", "2:0.1"], {"plausible": (2, 0.1)}),
        (["--shear-check"], {"shear_check": True}),
        (["--model-trial", "false"], {"model_trial": False}),
        (["--shear-trial", "false"], {"shear_trial": False}),
        (["--method", "demosaic"], {"method": "demosaic"}),
        (["--method", "ppid"], {"method": "ppid"}),
    ],
)
def test_decode_equals_cli_bit_for_bit(tmp_path, slf_bin, capture, flags, kwargs):
    capture.save(tmp_path / "cap")
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "out.npy", "--quiet", *flags])
    cli = np.load(tmp_path / "out.npy")
    ours = slf.decode(capture, **kwargs)
    assert ours.dtype == np.float32 and ours.shape == cli.shape == (5, 5, 20, 20, 13)
    assert np.array_equal(ours, cli), f"max difference {np.abs(ours - cli).max()}"
    # The capture's folder decodes the same as the capture in memory.
    assert np.array_equal(slf.decode(tmp_path / "cap", **kwargs), ours)


def test_disparity_map_equals_cli(tmp_path, slf_bin, capture):
    capture.save(tmp_path / "cap")
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "o.npy", "-q", "--preset", "preview", "--disparity-map", tmp_path / "d.npy"])
    _, report = slf.decode(capture, preset="preview", report=True)
    assert np.array_equal(report["disparity"], np.load(tmp_path / "d.npy"))


def test_model_trial_report_equals_cli(tmp_path, slf_bin, capture):
    capture.save(tmp_path / "cap")
    out = run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "o.npy", "-q"]).stdout
    lf, report = slf.decode(capture, report=True)
    t = report["trial"]
    assert t["model"] in ("dct", "ensemble") and t["pilots"] > 0
    # The model with the smaller held-out error decodes, unless the two are within their
    # spread: then the model the pixel mask at k = 1 favours, the ensemble.
    if t["tied"]:
        assert t["model"] == "ensemble", t
    else:
        assert (t["model"] == "dct") == (t["dct_error"] < t["ensemble_error"]), t
    name = "DCT" if t["model"] == "dct" else "ensemble"
    assert f"model trial: decoded by the {name} (held-out error over {t['pilots']} pilot patches" in out
    # The frame is the picked model's decode without the trial.
    alone = slf.decode(capture, model_trial=False, dictionary=t["model"])
    assert np.array_equal(lf, alone), np.abs(lf - alone).max()
    _, off = slf.decode(capture, model_trial=False, report=True)
    assert "trial" not in off
    # The shear trial (one snapshot: half-pixel disparities searched) reports as the command.
    s = report["shear_trial"]
    if s["pilots"] == 0:
        assert s["halves"] and "shear trial: no pilot patch at a half-pixel disparity" in out, out
    else:
        kept = "half-pixel disparities kept" if s["halves"] else "whole disparities only"
        assert f"shear trial: {kept}" in out and f"over {s['pilots']} pilot patches at half-pixel" in out, out


def test_error_map_equals_cli(tmp_path, slf_bin, depth, capture):
    capture.save(tmp_path / "cap")
    out = run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "o.npy", "-q", "--error-map", tmp_path / "e.npy"]).stdout
    lf, report = slf.decode(capture, error_map=True)
    # The same decode with or without the estimate; the same map as the command's.
    assert np.array_equal(lf, np.load(tmp_path / "o.npy")) and np.array_equal(lf, slf.decode(capture))
    emap = report["error_map"]
    assert emap.shape == (20, 20) and emap.dtype == np.float32
    assert np.array_equal(emap, np.load(tmp_path / "e.npy"), equal_nan=True)
    assert f"estimated PSNR {report['estimated_psnr']:.2f} dB" in out
    # In the output's units: within a factor of 10 of the true RMS error of the frame.
    true_rms = float(np.sqrt(np.mean((lf - depth) ** 2)))
    est_rms = float(np.sqrt(np.nanmean(emap**2)))
    assert true_rms / 10 < est_rms < 10 * true_rms, (est_rms, true_rms)
    np.save(tmp_path / "t.npy", depth)
    printed = run([slf_bin, "eval", tmp_path / "t.npy", tmp_path / "o.npy", "--error-map", tmp_path / "e.npy"]).stdout
    assert re.search(r"estimate PSNR [0-9.]+ dB \(true [0-9.]+\); blocks of 5 x 5 lenslets: rank correlation", printed)
    # The estimate by the held-out decode (the default) costs that decode; by the patches, a solve each.
    assert report["estimate_seconds"] > 0.0
    _, by_patches = slf.decode(capture, error_map=True, estimate_by="patches")
    assert "estimate_seconds" not in by_patches or by_patches["estimate_seconds"] == 0.0
    assert not np.array_equal(by_patches["error_map"], emap, equal_nan=True)


def test_evaluate_equals_cli(tmp_path, slf_bin, depth, capture):
    recon = slf.decode(capture, preset="preview")
    np.save(tmp_path / "t.npy", depth)
    np.save(tmp_path / "r.npy", recon)
    out = run([slf_bin, "eval", tmp_path / "t.npy", tmp_path / "r.npy"]).stdout
    m = slf.evaluate(depth, recon)
    assert f"PSNR {m['psnr']:.3f} dB" in out
    assert f"SSIM {m['ssim']:.4f}" in out
    assert re.search(rf"SA +{m['sa']:.3f} deg", out)
    assert 15 < m["psnr"] < 60 and 0 < m["ssim"] <= 1 and m["sa"] >= 0
    # Without the edge lenslets: the CLI's --border, and the same as scoring the slices.
    out = run([slf_bin, "eval", tmp_path / "t.npy", tmp_path / "r.npy", "--border", "2"]).stdout
    inner = slf.evaluate(depth, recon, border=2)
    assert f"PSNR {inner['psnr']:.3f} dB" in out
    assert inner == slf.evaluate(depth[:, :, 2:-2, 2:-2], recon[:, :, 2:-2, 2:-2])
    with pytest.raises(ValueError, match="border 99"):
        slf.evaluate(depth, recon, border=99)
    with pytest.raises(TypeError, match="border"):
        slf.evaluate(depth, recon, border=-1)


def test_an_hdf5_decode_reads_in_h5py(tmp_path, slf_bin, capture):
    # `slf decode -o OUT.h5`: h5py reads the light field (the package's decode, bit for
    # bit), its axes, its 13 band centres and the capture's description; the file is
    # chunked by bands of 8 lenslet rows (it is written a band at a time, issue 65), so a
    # few rows read without the rest.
    import h5py

    capture.save(tmp_path / "cap")
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "lf.h5", "--deflate", "4", "-q"])
    want = slf.decode(capture)
    with h5py.File(tmp_path / "lf.h5", "r") as f:
        d = f["lightfield"]
        assert d.shape == want.shape and d.dtype == np.float32
        assert np.array_equal(d[()], want)
        assert np.array_equal(d[:, :, 9:11], want[:, :, 9:11])
        assert [str(a) for a in d.attrs["axes"]] == list("uvhwb")
        assert np.array_equal(d.attrs["bands_nm"], np.asarray(capture.description["bands_nm"], dtype=np.float32))
        assert json.loads(d.attrs["description"]) == capture.description
        assert "--deflate 4" in d.attrs["command"] and d.attrs["settings"]
        u, v, h, w, b = want.shape
        assert d.compression == "gzip" and d.chunks == (u, v, min(h, 8), min(w, 128), b)


def test_a_zarr_decode_opens_lazily_in_zarr_xarray_and_dask(tmp_path, slf_bin, capture):
    # `slf decode -o OUT.zarr` (issue 65, item 4): a Zarr v3 store that zarr-python, xarray
    # and Dask open without reading it, holding the package's decode bit for bit, with the
    # axes' names, the band centres as the band axis's coordinate and the description.
    import dask.array as da
    import xarray as xr
    import zarr

    capture.save(tmp_path / "cap")
    run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "lf.zarr", "--deflate", "4", "-q"])
    want = slf.decode(capture)
    u, v, h, w, b = want.shape
    group = zarr.open_group(tmp_path / "lf.zarr", mode="r")
    a = group["lightfield"]
    assert a.metadata.zarr_format == 3 and a.shape == want.shape and a.dtype == np.float32
    assert a.chunks == (u, v, min(h, 8), min(w, 128), b)
    assert np.array_equal(a[:, :, 9:11], want[:, :, 9:11])
    assert group.attrs["description"] == capture.description
    nm = np.asarray(capture.description["bands_nm"], dtype=np.float32)
    ds = xr.open_zarr(tmp_path / "lf.zarr", consolidated=False)
    lf = ds["lightfield"]
    assert lf.dims == ("u", "v", "h", "w", "band")
    assert np.array_equal(lf["band"].values, nm)
    assert np.array_equal(lf.sel(band=nm[3]).values, want[..., 3])
    lazy = da.from_zarr(str(tmp_path / "lf.zarr"), component="lightfield")
    assert lazy.chunksize == a.chunks
    assert np.array_equal(lazy.compute(), want)


@pytest.mark.parametrize("libver", ["earliest", "latest"])
@pytest.mark.parametrize("compression", [None, "gzip"])
def test_h5py_files_import_whatever_their_format_version(tmp_path, slf_bin, libver, compression):
    # Issue 65, item 4: a chunked, compressed dataset h5py writes with libver="latest" (its
    # layout message version 5) was refused ("invalid data layout version: 5").
    import h5py

    lf = np.random.default_rng(5).random((2, 3, 10, 12, 13), dtype=np.float32)
    with h5py.File(tmp_path / "lf.h5", "w", libver=libver) as f:
        f.create_dataset("g/lf", data=lf, chunks=(1, 3, 4, 12, 13), compression=compression)
    run([slf_bin, "import", "hdf5", tmp_path / "lf.h5", "--dataset", "g/lf", "--axes", "uvhwb", "-o", tmp_path / "x.npy"])
    assert np.array_equal(np.load(tmp_path / "x.npy"), lf)


def test_an_hdf5_soft_link_imports_as_its_dataset(tmp_path, slf_bin):
    # Issue 51, item 16: a soft link said "need 18446744073709551615 bytes". The reader
    # follows it now; a link to nothing is refused with one line naming it.
    import h5py

    with h5py.File(tmp_path / "soft.h5", "w") as f:
        f["real"] = np.arange(2 * 2 * 3 * 3 * 13, dtype="f4").reshape(2, 2, 3, 3, 13) / 500
        f["lf"] = h5py.SoftLink("/real")
        f["dangling"] = h5py.SoftLink("/nothing")
    base = [slf_bin, "import", "hdf5", tmp_path / "soft.h5", "--axes", "uvhwb", "-o"]
    run(base + [tmp_path / "a.npy", "--dataset", "lf"])
    run(base + [tmp_path / "b.npy", "--dataset", "real"])
    assert np.array_equal(np.load(tmp_path / "a.npy"), np.load(tmp_path / "b.npy"))
    p = subprocess.run([str(c) for c in base + [tmp_path / "c.npy", "--dataset", "dangling"]], capture_output=True, text=True)
    assert p.returncode == 1 and p.stderr.count("\n") == 1, p.stderr
    assert "dangling" in p.stderr and "18446744073709551615" not in p.stderr
    assert not (tmp_path / "c.npy").exists()


def test_baseline_blend_equals_cli(tmp_path, slf_bin, depth):
    """On a kronecker mask the default blends each block with PPID's (issue 63): the same
    output and weights as the command's; off, the decode alone; on a pixel mask, nothing."""
    cap = slf.simulate(depth, mask="kronecker", k=3, seed=1)
    cap.save(tmp_path / "cap")
    out = run([slf_bin, "decode", tmp_path / "cap", "-o", tmp_path / "o.npy", "-q"]).stdout
    lf, report = slf.decode(cap, report=True)
    assert np.array_equal(lf, np.load(tmp_path / "o.npy"))
    b = report["baseline_blend"]
    w = b["weights"]
    assert w.shape == (20, 20) and w.dtype == np.float32 and ((w >= 0) & (w <= 1)).all()
    assert b["mean_weight"] == pytest.approx(float(w.mean()), abs=1e-6)
    assert b["mostly_baseline"] == int((w > 0.5).sum()) and b["lenslets"] == 400
    assert f"baseline blend: PPID's weight {b['mean_weight']:.2f} on average, above one half at {b['mostly_baseline']} of 400" in out
    # Each value between the decode's alone and PPID's, at the lenslet's weight.
    alone, off = slf.decode(cap, baseline_blend=False, report=True)
    assert "baseline_blend" not in off
    baseline = slf.decode(cap, method="ppid")
    want = alone + w[None, None, :, :, None] * (baseline - alone)
    assert np.abs(lf - want).max() < 1e-5
    _, pixel = slf.decode(slf.simulate(depth, k=3, seed=1), report=True)
    assert "baseline_blend" not in pixel
