"""Bad input raises a clear, one-line exception: ValueError for values and shapes (the axis
named), OSError for files; odd but valid input (float64, Fortran order, views) is converted."""

import json
import warnings

import numpy as np
import pytest

import slf


def test_wrong_axes_are_named(depth):
    with pytest.raises(ValueError, match=r"want 5 axes \(U, V, H, W, B\), got 4"):
        slf.simulate(depth[0])
    with pytest.raises(ValueError, match=r"frames: want 3 axes \(snapshots, rows, cols\)"):
        slf.Capture(np.zeros((100, 100), np.uint16), {})


def test_band_count_needs_wavelengths(depth):
    with pytest.raises(ValueError, match="12 bands; the camera has 13.*wavelengths"):
        slf.simulate(depth[..., :12])


def test_nan_is_refused_with_its_place(depth):
    bad = depth.copy()
    bad[1, 2, 3, 4, 5] = np.nan
    bad[4, 4, 4, 4, 4] = np.inf
    with pytest.raises(ValueError, match=r"2 values are NaN or infinite, the first at \(u, v, h, w, b\) = \(1, 2, 3, 4, 5\)"):
        slf.simulate(bad)
    with pytest.raises(ValueError, match="recon: 2 values are NaN"):
        slf.evaluate(depth, bad)


def test_wrong_dtypes(depth, capture):
    with pytest.raises(ValueError, match="dtype <U1 is not a real number type"):
        slf.simulate(np.full(depth.shape, "a"))
    with pytest.raises(ValueError, match="frames: dtype float32, want uint16"):
        slf.Capture(capture.frames.astype(np.float32), capture.description)


def test_float64_fortran_and_views_are_converted_once(depth):
    ref = slf.simulate(depth)
    for odd in (depth.astype(np.float64), np.asfortranarray(depth), depth[:, :, ::1, :, :]):
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            got = slf.simulate(odd)
        assert np.array_equal(got.frames, ref.frames)
        assert len(w) == int(odd.dtype != np.float32 or not odd.flags.c_contiguous)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        slf.simulate(np.asfortranarray(depth.astype(np.float64)))
    assert len(w) == 1 and "float64 to float32, to C order" in str(w[0].message)


def test_missing_files_are_oserrors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such capture folder"):
        slf.load_capture(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(OSError):
        slf.load_capture(tmp_path / "empty")
    with pytest.raises(OSError):
        slf.import_cube(tmp_path / "nothing.npy", wavelengths="400:700:10")


def test_a_broken_capture_is_named(tmp_path, capture):
    capture.save(tmp_path / "c")
    (tmp_path / "c" / "snapshot_0.pgm").write_bytes(b"P5\n3 3\n65535\n")
    with pytest.raises(ValueError, match="snapshot_0.pgm"):
        slf.load_capture(tmp_path / "c")
    d = dict(capture.description, lenslets=[21, 20])
    with pytest.raises(ValueError, match="frame 0"):
        slf.Capture(capture.frames, d)
    with pytest.raises(ValueError, match="invalid capture description"):
        slf.Capture(capture.frames, {"format": "slf-capture"})


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"stride": 7}, "--stride"),
        ({"preset": "fast"}, "invalid value 'fast' for '--preset"),
        ({"method": "magic"}, "--method"),
        ({"disparities": "5:1"}, "MIN:MAX"),
        ({"gains": [1.0, 2.0]}, "--gains: 13 values, got 2"),
        ({"mu": -1.0}, "mu"),
        ({"threads": 0}, "threads: at least 1"),
        ({"threads": 10**9}, "threads: 1000000000 is more than the"),
        ({"window": "round"}, "--window"),
        ({"min_bands": 14}, "--min-bands 14: at most 13"),
        ({"adaptive": 2.0, "stride": 5}, "--adaptive needs a stride below 5"),
        ({"blob": "e.slfd", "dictionary": "dct"}, "--blob names an ensemble"),
        ({"sigma_f": 1.5}, r"--sigma-f 1.5: must be in \(0, 1\)"),
        ({"mu": 5.0}, r"--mu 5: must be in \(0, 2\]"),
        ({"sigma_min": 1e30}, r"--sigma-min 1e30: must be in \(0, 1\]"),
        ({"noise": 1e30}, r"--noise 1e30: must be in \[0, 1\]"),
        ({"gains": [1.0] * 12 + [1e30]}, r"--gains: gain 13 is 1e30"),
        ({"method": "demosaic", "mu": 0.5}, r"--mu given with --method demosaic"),
    ],
)
def test_bad_decode_settings(capture, kwargs, message):
    with pytest.raises(ValueError, match=message):
        slf.decode(capture, **kwargs)


def test_shapes_differ_in_evaluate(depth):
    with pytest.raises(ValueError, match="shapes differ"):
        slf.evaluate(depth, depth[:, :, :10])


def test_scene_arguments():
    with pytest.raises(ValueError, match="unknown scene \"nope\""):
        slf.scene("nope")
    with pytest.raises(ValueError, match="size 0"):
        slf.scene("depth", size=0)


def test_impossible_noise_and_no_light(capture):
    d = dict(capture.description, noise={"full_well_electrons": 20000.0, "read_noise_dn": 1e30})
    with pytest.raises(ValueError, match="noise.read_noise_dn"):
        slf.Capture(capture.frames, d)
    dark = slf.Capture(np.full_like(capture.frames, int(capture.description["black_level"])), capture.description)
    with pytest.raises(ValueError, match="no light was recorded"):
        slf.decode(dark)


def test_each_cause_is_said_once(tmp_path):
    (tmp_path / "views").mkdir()
    (tmp_path / "views" / "input_Cam020.png").write_bytes(b"not a png")
    with pytest.raises(ValueError) as e:
        slf.import_views(tmp_path / "views")
    assert "not an image slf reads" in str(e.value)
    assert str(e.value).count("Invalid PNG signature") == 1, str(e.value)


def test_frames_outside_the_capture_folder_are_refused(capture, tmp_path):
    """Issue 41, item 13: a capture never writes a frame outside its folder."""
    for name in ("../x.pgm", str(tmp_path / "abs.pgm")):
        d = dict(capture.description, frames=[name])
        with pytest.raises(ValueError, match="not a path inside the capture folder"):
            slf.Capture(capture.frames, d)
        c = slf.Capture(capture.frames, capture.description)
        c.description = d  # changed after construction, as a user may
        with pytest.raises(ValueError, match="not a path inside the capture folder"):
            c.save(tmp_path / "cap")
    assert not (tmp_path / "x.pgm").exists() and not (tmp_path / "abs.pgm").exists()


def test_arrays_as_flags_and_float_frames(capture):
    """Issue 41, item 15: gains as a numpy array are numbers, not their repr; float frames
    set after construction are one ValueError line, not a two-line TypeError."""
    assert np.array_equal(
        slf.decode(capture, preset="preview", gains=np.ones(13)), slf.decode(capture, preset="preview", gains=[1.0] * 13)
    )
    c = slf.Capture(capture.frames, capture.description)
    c.frames = capture.frames.astype(np.float32)
    with pytest.raises(ValueError, match="frames: dtype float32, want uint16") as e:
        slf.decode(c)
    assert "\n" not in str(e.value)


def test_none_is_the_default_and_strings_are_no_booleans(depth, capture):
    """Issue 51, item 13: ``noise=None`` is the command's default (noise on), not
    noiseless; ``"false"`` for a boolean keyword is refused, not taken as True."""
    noisy = slf.simulate(depth, seed=3, noise=None)
    assert np.array_equal(noisy.frames, slf.simulate(depth, seed=3).frames)
    assert not np.array_equal(noisy.frames, slf.simulate(depth, seed=3, noise=False).frames)
    for key in ("edge_fallback", "seeded", "sheared_fallback", "model_trial", "shear_trial", "exact", "report"):
        with pytest.raises(TypeError, match=f"{key}: want True, False or None, got 'false'"):
            slf.decode(capture, **{key: "false"})
    with pytest.raises(TypeError, match="noise: want True, False or None"):
        slf.simulate(depth, noise="no")
    # np.bool_ is a boolean.
    a = slf.decode(capture, preset="preview", seeded=np.bool_(False))
    b = slf.decode(capture, preset="preview", seeded=False)
    assert np.array_equal(a, b)


def test_an_empty_path_is_refused(depth, capture, tmp_path, monkeypatch):
    """Issue 51, item 14: an empty path wrote into the working folder."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="path: an empty path"):
        capture.save("")
    with pytest.raises(ValueError, match="calibration_captures: an empty path"):
        slf.simulate(depth, leakage=0.1, calibration_captures="")
    with pytest.raises(ValueError, match="output: an empty path"):
        slf.calibrate(str(tmp_path), "")
    with pytest.raises(ValueError, match="output: an empty path"):
        slf.decode(capture, output="")
    assert list(tmp_path.iterdir()) == []
