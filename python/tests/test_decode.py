"""The decode from Python: threads, progress, reports, the GIL released."""

import json
import os
import stat
import threading
import time

import numpy as np
import pytest

import slf


def test_threads_do_not_change_the_result(capture):
    one = slf.decode(capture, preset="preview", threads=1)
    two = slf.decode(capture, preset="preview", threads=2)
    assert np.array_equal(one, two)


def test_report(capture, depth):
    lf, report = slf.decode(capture, preset="preview", report=True)
    assert report["method"] == "cs" and report["preset"] == "preview"
    assert report["decoded"] > 0 and report["failed"] == 0 and report["stride"] == 5
    assert report["seeded"] is False  # the disjoint grid has no shifted patch to seed
    assert report["solved"] + report["interpolated"] + report["flat"] == report["decoded"]
    assert report["interpolated"] == 0  # the pixel mask measures every band in a patch
    assert len(report["gains"]) == 13 and report["seconds"] > 0
    assert report["disparity"].shape == (20, 20)
    _, off = slf.decode(capture, preset="preview", disparities="0:0", report=True)
    assert off["disparity"] is None
    assert slf.evaluate(depth, lf)["psnr"] > 20


def test_patch_views_keyword_and_report(capture):
    # The full-view patch by default on 5 x 5 views (one window a block), the paper's on
    # request (four); a patch larger than the lenslet is a ValueError naming the flag.
    _, five = slf.decode(capture, preset="preview", report=True)
    _, four = slf.decode(capture, preset="preview", patch_views=4, report=True)
    assert five["patch_views"] == 5 and four["patch_views"] == 4
    assert four["decoded"] > five["decoded"]
    small = slf.simulate(slf.scene("depth", size=11, views=4), k=1)
    assert slf.decode(small, preset="preview", report=True)[1]["patch_views"] == 4
    with pytest.raises(ValueError, match="--patch-views 5: the capture's lenslets have 4 x 4 views"):
        slf.decode(small, patch_views=5)
    with pytest.raises(ValueError, match="patch-views"):
        slf.decode(capture, patch_views=6)


def test_progress_callback(capture):
    calls = []
    slf.decode(capture, preset="preview", progress=lambda done, total: calls.append((done, total)))
    assert calls, "the callback was never called"
    total = calls[0][1]
    assert sorted(d for d, _ in calls) == list(range(1, total + 1))
    assert all(t == total for _, t in calls)


def test_progress_errors_are_raised(capture):
    def boom(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        slf.decode(capture, preset="preview", progress=boom)


def test_gil_is_released(capture):
    """Another Python thread runs while a decode is under way."""
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    slf.decode(capture, threads=1)
    end = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 5, f"{len(during)} ticks in a {end - start:.2f} s decode"


def test_baseline_report(capture):
    lf, report = slf.decode(capture, method="demosaic", report=True)
    assert report["method"] == "demosaic" and report["measured"] > 0
    assert lf.shape == (5, 5, 20, 20, 13)


def test_frames_in_any_memory_order_decode_as_c_ordered_ones(capture, tmp_path):
    """Issue 41, item 8: Fortran-ordered or transposed frames are read by their values, not
    their memory (before: read as if C-ordered, decoded at 11 dB without an error)."""
    want = slf.decode(capture, preset="preview", disparities="0:0")
    c_order = capture.frames.copy()
    for frames in (
        np.asfortranarray(c_order),
        np.ascontiguousarray(c_order.transpose(0, 2, 1)).transpose(0, 2, 1),
        np.repeat(c_order, 2, axis=2)[:, :, ::2],
    ):
        assert np.array_equal(frames, c_order) and not frames.flags["C_CONTIGUOUS"]
        other = slf.Capture(c_order, capture.description)
        other.frames = frames  # set after construction, as a user may
        assert np.array_equal(slf.decode(other, preset="preview", disparities="0:0"), want)
        other.save(tmp_path / "cap")
        assert np.array_equal(slf.load_capture(tmp_path / "cap").frames, c_order)


def test_light_fields_in_any_memory_order_are_read_by_value(depth):
    """Issue 41, item 8, for light fields: the Python layer copies them to C order with a
    warning; the extension itself reads any order by value too."""
    from slf import _slf

    recon = depth + np.float32(0.01)
    want = dict(_slf.evaluate(depth, recon))
    assert dict(_slf.evaluate(np.asfortranarray(depth), np.asfortranarray(recon))) == want


def test_random_array_layouts_are_read_by_value(capture, depth):
    """Issue 41's fuzz target for the package's array layouts: frames and light fields in
    random memory orders, strides and axis permutations (undone to the same values) decode
    and score exactly as their C-ordered copies. A fixed seed; 40 layouts each."""
    from slf import _slf

    rng = np.random.default_rng(41)
    frames = np.ascontiguousarray(capture.frames)
    text = json.dumps(capture.description)
    want = _slf.decode(frames, text, ["--preset=preview", "--disparities=0:0"], 1, None)[0]
    recon = depth + np.float32(0.01)
    score = dict(_slf.evaluate(depth, recon))

    def relaid(a):
        """`a`'s values in a random layout: a permuted copy permuted back, a strided view
        of a larger buffer, or Fortran order."""
        how = rng.integers(3)
        if how == 0:
            order = rng.permutation(a.ndim)
            return np.ascontiguousarray(a.transpose(order)).transpose(np.argsort(order))
        if how == 1:
            axis = int(rng.integers(a.ndim))
            step = int(rng.integers(2, 4))
            return np.repeat(a, step, axis=axis)[(slice(None),) * axis + (slice(None, None, step),)]
        return np.asfortranarray(a)

    for _ in range(40):
        f = relaid(frames)
        assert np.array_equal(f, frames)
        got = _slf.decode(f, text, ["--preset=preview", "--disparities=0:0"], 1, None)[0]
        assert np.array_equal(got, want)
        t, r = relaid(depth), relaid(recon)
        assert dict(_slf.evaluate(t, r)) == score


def test_output_streams_to_a_file_and_returns_its_memory_map(capture, tmp_path):
    # The file is the decode in memory, value for value, written as the rows are decoded;
    # what comes back is a read-only memory map of it.
    out = tmp_path / "lf.npy"
    mapped, report = slf.decode(capture, output=out, report=True)
    assert isinstance(mapped, np.memmap) and not mapped.flags.writeable
    assert np.array_equal(mapped, slf.decode(capture))
    assert np.array_equal(np.load(out), mapped)
    assert 0 < report["rows_held"] <= 20
    # An aligned sensor puts no view past its edges.
    assert (report["off_sensor_lenslets"], report["off_sensor_views"]) == (0, 0)
    assert report["coverage"].shape == mapped.shape[2:4] and np.all(report["coverage"] == 1)
    # A baseline too (decoded whole, then written by rows).
    base = slf.decode(capture, method="demosaic", output=tmp_path / "d.npy")
    assert np.array_equal(base, slf.decode(capture, method="demosaic"))


def test_a_failed_decode_to_a_file_leaves_none(capture, tmp_path):
    out = tmp_path / "lf.npy"
    dark = slf.Capture(np.zeros_like(np.asarray(capture.frames)), capture.description)
    with pytest.raises(ValueError, match="no light"):
        slf.decode(dark, output=out)
    assert list(tmp_path.iterdir()) == []


def test_an_output_is_never_a_file_of_the_capture(capture, tmp_path):
    folder = tmp_path / "cap"
    capture.save(folder)
    frames = json.loads((folder / "capture.json").read_text())["frames"]
    for name in ["capture.json", *frames]:
        before = (folder / name).read_bytes()
        with pytest.raises(ValueError, match="a file of the capture"):
            slf.decode(folder, output=folder / name)
        assert (folder / name).read_bytes() == before
    with pytest.raises(ValueError, match=r"lf.h5: a .npy file or a .zarr store"):
        slf.decode(capture, output=tmp_path / "lf.h5")


def test_an_output_is_never_an_input_of_a_loaded_capture_or_its_calibration(depth, tmp_path):
    """Issue 65, item 1: a capture that load_capture read keeps its folder, and the decode
    refuses an output that is one of its files, or a file of the calibration it reads,
    before it decodes: nothing is replaced (the call returned normally and overwrote the
    raw frame, and the dark frame, before)."""
    folder = tmp_path / "cap"
    slf.simulate(depth, k=1, seed=1, leakage=0.1, calibration_captures=tmp_path / "cc", exposures=1).save(folder)
    slf.calibrate(tmp_path / "cc", tmp_path / "cal")
    loaded = slf.load_capture(folder)
    assert loaded.source == str(folder)
    frame = json.loads((folder / "capture.json").read_text())["frames"][0]
    before = (folder / frame).read_bytes()
    with pytest.raises(ValueError, match="a file of the capture"):
        slf.decode(loaded, preset="preview", output=folder / frame)
    assert (folder / frame).read_bytes() == before
    for name in ["dark.npy", "calibration.json"]:
        target = tmp_path / "cal" / name
        assert target.exists(), name
        before = target.read_bytes()
        with pytest.raises(ValueError, match="a file of calibration"):
            slf.decode(loaded, preset="preview", calibration=tmp_path / "cal", output=target)
        assert target.read_bytes() == before
    # A capture made in memory has no folder: any output is the caller's to choose.
    assert slf.Capture(loaded.frames, loaded.description).source is None


def test_a_baseline_refuses_the_estimate_and_the_trials(capture):
    """Issue 65, item 9: a baseline decodes nothing to hold out of and runs no trial, so
    these keywords are refused, as the command's flags are (before: accepted, ignored)."""
    for kwargs in [{"error_map": True}, {"model_trial": True}, {"shear_trial": True}, {"shear_check": True}]:
        with pytest.raises(ValueError, match="given with --method demosaic"):
            slf.decode(capture, method="demosaic", **kwargs)



def test_a_raising_callback_stops_the_decode(capture, tmp_path):
    """Issue 65, item 8: an exception in the progress callback stops the decode at its next
    finished row; the callback is not called again and a file output is left unwritten
    (before: the decode ran to its end, wrote the whole file, then raised)."""
    calls = []

    def boom(done, total):
        calls.append(done)
        raise RuntimeError("stop here")

    out = tmp_path / "lf.npy"
    with pytest.raises(RuntimeError, match="stop here"):
        slf.decode(capture, preset="preview", threads=1, progress=boom, output=out)
    assert calls == [1]
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(KeyboardInterrupt):
        slf.decode(capture, preset="preview", threads=1, progress=lambda d, t: (_ for _ in ()).throw(KeyboardInterrupt))


def test_ctrl_c_stops_a_decode_without_a_callback(tmp_path):
    """Issue 65, item 8: Python's signals are checked as the decode goes, so Ctrl-C
    (SIGINT) stops it with KeyboardInterrupt and leaves no file (before: only after the
    whole decode)."""
    import signal

    big = slf.simulate(slf.scene("texture", size=60), k=3, seed=1)
    out = tmp_path / "lf.npy"
    main = threading.main_thread().ident
    start = time.perf_counter()
    timer = threading.Timer(0.3, lambda: signal.pthread_kill(main, signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        slf.decode(big, threads=1, output=out)
    stopped = time.perf_counter() - start
    timer.join()
    assert list(tmp_path.iterdir()) == []
    # The whole decode takes longer than the wait: the interrupt ended it early.
    start = time.perf_counter()
    slf.decode(big, threads=1)
    assert stopped < time.perf_counter() - start


def test_keywords_of_the_wrong_kind_are_refused(capture, tmp_path, depth):
    """Issue 65, item 8: progress=5 is refused (before: accepted, no bar), exposures=-1 is a
    ValueError naming the range (before: OverflowError), and an output that is a FIFO is
    refused, not replaced by a file."""
    with pytest.raises(TypeError, match="progress: want True, False, None or a callable"):
        slf.decode(capture, preset="preview", progress=5)
    with pytest.raises(ValueError, match=r"exposures: -1 is not in 1..=256"):
        slf.simulate(depth, k=1, calibration_captures=tmp_path / "cc", exposures=-1)
    fifo = tmp_path / "out.npy"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        slf.decode(capture, preset="preview", output=fifo)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_an_error_map_asked_for_is_in_the_report(depth, tmp_path):
    """Issue 65, item 4: error_map=True where no patch can be estimated (the response in
    the projection) gives a NaN map and a note why (before: no error_map key)."""
    cap = slf.simulate(depth, k=1, seed=1, vignetting=0.3, calibration_captures=tmp_path / "cc", exposures=1)
    slf.calibrate(tmp_path / "cc", tmp_path / "cal")
    _, report = slf.decode(
        cap, preset="preview", calibration=tmp_path / "cal", response_model="projection", error_map=True
    )
    assert report["error_map"].shape == (20, 20) and np.isnan(report["error_map"]).all()
    assert "no patch could be estimated" in report["estimate_note"]


def test_a_shear_trial_with_nothing_to_try_says_so(depth):
    """Issue 65, item 9: shear_trial=True at three snapshots (whole disparities only) says
    why it did not run (before: no word); where it runs, no such key."""
    cap = slf.simulate(depth, k=3, seed=1)
    _, report = slf.decode(cap, shear_trial=True, report=True)
    assert "shear_trial" not in report
    assert "no half-pixel step to try" in report["shear_trial_skipped"]
    _, report = slf.decode(cap, shear_trial=True, disparities="0:0", report=True)
    assert report["shear_trial_skipped"] == "the decode searches no disparity"


def test_behind_a_turned_array_the_report_marks_the_lenslets_past_the_sensor(depth):
    # Issue 66, item 4: the lenslets whose views reach past the sensor's edges have their
    # share of views on it in report["coverage"], the rest 1.
    cap = slf.simulate(depth, k=1, seed=1, rotation=1.0, pitch=5.1)
    _, report = slf.decode(cap, report=True, preset="preview")
    coverage = report["coverage"]
    assert coverage.shape == depth.shape[2:4]
    assert 0 < report["off_sensor_lenslets"] == np.count_nonzero(coverage < 1)
    assert np.all((coverage >= 0) & (coverage <= 1))
    assert round(float(np.sum(1 - coverage)) * 25) == report["off_sensor_views"]
