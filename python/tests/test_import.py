"""`slf.import_views` and `slf.import_cube` give what `slf import` writes."""

import struct
import zlib

import numpy as np
import pytest

import slf
from conftest import run


def write_png(path, rgb: np.ndarray) -> None:
    """An 8-bit RGB PNG, written by hand so the tests need nothing but numpy."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[r].astype(np.uint8).tobytes() for r in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    path.write_bytes(png)


@pytest.fixture
def views(tmp_path):
    """A 5 x 5 grid of 24 x 24 RGB views, named view_R_C.png."""
    rng = np.random.default_rng(5)
    folder = tmp_path / "views"
    folder.mkdir()
    base = rng.integers(0, 256, (24, 30, 3))
    for r in range(5):
        for c in range(5):
            write_png(folder / f"view_{r}_{c}.png", base[:, c : c + 24])
    return folder


def test_views_equal_cli(tmp_path, slf_bin, views):
    flags = ["--pattern", "view_{row}_{col}.png", "--grid", "5,5", "--views", "4,4", "--start", "1,0"]
    run([slf_bin, "import", "views", views, "-o", tmp_path / "v.npy", *flags])
    ours = slf.import_views(views, pattern="view_{row}_{col}.png", grid=(5, 5), views=(4, 4), start=(1, 0))
    assert ours.shape == (4, 4, 24, 24, 13)
    assert np.array_equal(ours, np.load(tmp_path / "v.npy"))


def test_views_missing_is_an_error_naming_the_file(views):
    with pytest.raises(ValueError, match="view_9_9|missing|no file"):
        slf.import_views(views, pattern="view_{row}_{col}.png", grid=(10, 10), views=(10, 10))


def test_cube_equals_cli(tmp_path, slf_bin):
    rng = np.random.default_rng(9)
    cube = rng.uniform(0.05, 0.9, (20, 22, 31)).astype(np.float32)
    np.save(tmp_path / "c.npy", cube)
    run([slf_bin, "import", "cube", tmp_path / "c.npy", "-o", tmp_path / "lf.npy", "--wavelengths", "400:700:10", "--disparity", "0.5"])
    ours = slf.import_cube(tmp_path / "c.npy", wavelengths="400:700:10", disparity=0.5)
    assert ours.shape[-1] == 13
    assert np.array_equal(ours, np.load(tmp_path / "lf.npy"))


def test_cube_without_wavelengths_says_so(tmp_path):
    np.save(tmp_path / "c.npy", np.ones((8, 8, 31), np.float32))
    with pytest.raises(ValueError, match="wavelengths"):
        slf.import_cube(tmp_path / "c.npy")
