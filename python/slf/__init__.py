"""slf: the decoder of a compressive multispectral light-field camera, from numpy.

A scene to a decoded light field and its quality::

    import slf
    lf = slf.scene("depth", size=60)          # (U, V, H, W, 13) float32
    out = slf.decode(slf.simulate(lf, k=1))   # the same shape
    slf.evaluate(lf, out)                     # {'psnr': ..., 'ssim': ..., 'sa': ...}

Every function runs the same code as a command of the ``slf`` CLI, with the same defaults:
a keyword is the command's flag with ``_`` for ``-`` (``sigma_min=`` is ``--sigma-min``),
left at ``None`` for the command's default, and the errors are the command's, one line,
raised as ``ValueError`` (a value out of range, a wrong shape) or ``OSError`` (a file).

Light fields are ``(U, V, H, W, B)`` float32 arrays: U x V views, H x W lenslets (pixels
per view), B = 13 bands from 400 to 700 nm by 25. Other float dtypes and memory orders are
accepted and converted (a warning says so); a capture holds its raw frames as a
``(k, rows, cols)`` uint16 array and its description as a dict (``capture.json``).

Many captures on a Dask cluster: :func:`slf.batch.decode_folder`.
"""

from __future__ import annotations

import json
import os
import sys
import warnings
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from . import _slf

__version__ = _slf.__version__

__all__ = [
    "Capture",
    "decode",
    "evaluate",
    "import_cube",
    "import_views",
    "load_capture",
    "scene",
    "simulate",
]

PathLike = Union[str, "os.PathLike[str]"]


def _flag(name: str, value: Any) -> Optional[str]:
    """One ``--name=value`` flag of the CLI, or None for a keyword left at its default."""
    if value is None or value is False:
        return None
    flag = "--" + name.replace("_", "-")
    if value is True:
        return flag
    if isinstance(value, np.ndarray):
        value = value.tolist()  # gains=np.ones(13), as a list of numbers
    if isinstance(value, (list, tuple)):
        value = ",".join(str(v) for v in value)
    return f"{flag}={value}"


def _bool(name: str, value: Any, default: Optional[bool] = None) -> Optional[bool]:
    """A boolean keyword: True, False, or None for ``default`` (the command's). Anything
    else is refused: ``"false"`` is a true string in Python and once acted as True."""
    if value is None:
        return default
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{name}: want True, False or None, got {value!r} ({type(value).__name__})")


def _switch(name: str, value: Any) -> Optional[str]:
    """A boolean keyword as a ``--name true|false`` flag's value, None left to the preset."""
    b = _bool(name, value)
    return None if b is None else ("true" if b else "false")


def _path(name: str, value: Any) -> str:
    """A path keyword as a string; an empty one (which would write into the working
    folder) is refused."""
    p = os.fspath(value)
    if not p:
        raise ValueError(f"{name}: an empty path names no file or folder")
    return p


def _raw_frames(frames: Any) -> np.ndarray:
    """A capture's frames as the extension takes them (uint16), or one line saying why not:
    ``capture.frames`` may have been replaced after the capture was made."""
    arr = np.asarray(frames)
    if arr.dtype != np.uint16:
        raise ValueError(f"frames: dtype {arr.dtype}, want uint16 (raw sensor values)")
    return arr


def _flags(**kwargs: Any) -> list:
    return [f for f in (_flag(k, v) for k, v in kwargs.items()) if f is not None]


def _as_float32(a: Any, what: str, axes: str) -> np.ndarray:
    """``a`` as a C-ordered float32 array of 5 axes; converted (and said) if it is not."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"{what}: dtype {arr.dtype} is not a real number type (want float32)")
    if arr.ndim != 5:
        raise ValueError(f"{what}: want 5 axes {axes}, got {arr.ndim} of shape {arr.shape}")
    if arr.dtype != np.float32 or not arr.flags.c_contiguous:
        how = []
        if arr.dtype != np.float32:
            how.append(f"{arr.dtype} to float32")
        if not arr.flags.c_contiguous:
            how.append("to C order")
        warnings.warn(f"slf: {what} converted ({', '.join(how)}): a copy", stacklevel=3)
        arr = np.ascontiguousarray(arr, dtype=np.float32)
    return arr


class Capture:
    """A capture: the raw frames of k snapshots and their description.

    ``frames`` is a ``(k, rows, cols)`` uint16 array (the sensor's values, black level
    included); ``description`` the dict of ``capture.json`` (lenslets, views, bands, mask,
    levels, noise, defective pixels). Made by :func:`simulate`, read by
    :func:`load_capture`, written by :meth:`save` as the folder ``slf simulate`` writes and
    ``slf decode`` reads. Constructing one checks the frames against the description.
    ``source`` is the folder :func:`load_capture` read it from (None for one made in memory):
    a decode's ``output`` may not be one of its files.
    """

    def __init__(self, frames: np.ndarray, description: Dict[str, Any]):
        frames = np.ascontiguousarray(_raw_frames(frames))
        text = _slf.check_capture(frames, json.dumps(description))
        self.frames: np.ndarray = frames
        self.description: Dict[str, Any] = json.loads(text)
        self.source: Optional[str] = None

    @property
    def snapshots(self) -> int:
        """k, the number of frames."""
        return int(self.frames.shape[0])

    @property
    def lenslets(self) -> Tuple[int, int]:
        """Lenslet rows and columns (H, W of the decoded light field)."""
        r, c = self.description["lenslets"]
        return int(r), int(c)

    @property
    def views(self) -> Tuple[int, int]:
        """Views per lenslet, rows and columns (U, V)."""
        u, v = self.description["views"]
        return int(u), int(v)

    def save(self, path: PathLike) -> None:
        """Writes the capture folder ``path`` (``capture.json`` and one frame file per
        snapshot, in the format its names say), as ``slf simulate -o path`` does."""
        _slf.save_capture(_raw_frames(self.frames), json.dumps(self.description), _path("path", path))

    def __repr__(self) -> str:
        mask = self.description.get("mask", {}).get("family", "?")
        return (
            f"Capture(k={self.snapshots}, lenslets={self.lenslets}, views={self.views}, "
            f"mask={mask!r}, frames={self.frames.shape[1]}x{self.frames.shape[2]} uint16)"
        )


def _from_parts(parts: Tuple[np.ndarray, str], source: Optional[str] = None) -> Capture:
    frames, text = parts
    c = Capture.__new__(Capture)
    c.frames = frames
    c.description = json.loads(text)
    c.source = source
    return c


def scene(name: str, size: int = 100, views: int = 5, seed: int = 0) -> np.ndarray:
    """A test scene as ``slf scene`` renders it: ``(views, views, size, size, 13)`` float32.

    ``name``: a test scene (smooth, texture, depth, saturated, dark), a realistic one
    (outdoor, tungsten, office, led), ``random`` (a training scene of the shipped ensemble)
    or ``realistic`` (slanted and curved surfaces, 1/f textures, measured spectra), the last
    two drawn from ``seed``.
    """
    for n, v in (("size", size), ("views", views), ("seed", seed)):
        if not isinstance(v, (int, np.integer)) or v < 0:
            raise ValueError(f"{n}: want a whole number at or above 0, got {v!r}")
    if not 11 <= size <= 4096:
        raise ValueError(
            f"size {size}: want 11..=4096 (as `slf scene --size`: the smallest light field slf.evaluate scores)"
        )
    if not 4 <= views <= 16:
        raise ValueError(f"views {views}: want 4..=16 (as `slf scene --views`: the decoder's patch takes 4 x 4)")
    return _slf.scene(name, int(size), int(views), int(seed))


def simulate(
    lf: np.ndarray,
    mask: str = "pixel",
    k: int = 1,
    seed: int = 1,
    noise: Optional[bool] = True,
    *,
    read_noise: Optional[float] = None,
    full_well: Optional[float] = None,
    defects: Optional[float] = None,
    wavelengths: Optional[str] = None,
    format: Optional[str] = None,
    leakage: Optional[float] = None,
    filter_width: Optional[float] = None,
    secondary: Optional[float] = None,
    secondary_nm: Optional[float] = None,
    leak_floor: Optional[float] = None,
    dark_sd: Optional[float] = None,
    hot_pixels: Optional[float] = None,
    prnu: Optional[float] = None,
    vignetting: Optional[float] = None,
    sensor_seed: Optional[int] = None,
    rotation: Optional[float] = None,
    pitch: Optional[Union[float, Sequence[float]]] = None,
    grid_offset: Optional[Sequence[float]] = None,
    calibration_captures: Optional[PathLike] = None,
    exposures: int = 8,
) -> Capture:
    """Records the light field ``lf`` ``(U, V, H, W, B)`` with the camera, as ``slf simulate``.

    ``mask``: pixel, lenslet or kronecker; ``k``: snapshots (1..=13); ``seed``: the mask's,
    the noise's and the defects'; ``noise=False`` is ``--no-noise`` (None: the command's default, noise on). ``read_noise`` (DN,
    default 2), ``full_well`` (electrons at white, default 20000), ``defects`` (fraction of
    defective pixels, default 0), ``wavelengths`` (of ``lf``'s bands when it does not have
    the camera's 13: ``"START:STOP:STEP"`` or a comma list, nm) and ``format`` (of the frame
    files :meth:`Capture.save` writes: pgm, png, npy) as the command's flags.

    A real sensor, all off by default (the command's flags of the same names): ``leakage``
    (the share of a pixel's response from bands other than its filter's, in [0, 0.9]) with
    its shape ``filter_width`` (nm), ``secondary`` (peaks relative to the main one),
    ``secondary_nm`` and ``leak_floor``; ``dark_sd`` (DN) and ``hot_pixels`` (fraction),
    ``prnu`` (gain spread), ``vignetting`` (light the corner view loses) and ``sensor_seed``
    (one sensor for every capture made with it). Such a capture records its sensor in its
    description's ``simulated_sensor`` (format version 2).

    A real lenslet array, off by default (``--rotation``, ``--pitch``, ``--grid-offset``):
    ``rotation`` (degrees, positive turns the lenslet rows down to the right), ``pitch``
    (pixels per lenslet, one number or ``(rows, cols)``), ``grid_offset`` (lenslet (0, 0)'s
    micro-image centre, ``(row, col)`` pixels; default the array centred). The frames are
    then the grid's sensor's size and the description records ``lenslet_grid``.

    ``calibration_captures``: a
    folder to write the sensor's dark, flat and band-sweep captures into, ``exposures``
    (1..=256) of each, as ``--calibration-captures DIR --exposures N`` does, for
    :func:`calibrate`.
    """
    arr = _as_float32(lf, "lf", "(U, V, H, W, B)")
    args = _flags(
        mask=mask,
        snapshots=k,
        seed=seed,
        no_noise=not _bool("noise", noise, True),
        read_noise=read_noise,
        full_well=full_well,
        defects=defects,
        wavelengths=wavelengths,
        format=format,
        leakage=leakage,
        filter_width=filter_width,
        secondary=secondary,
        secondary_nm=secondary_nm,
        leak_floor=leak_floor,
        dark_sd=dark_sd,
        hot_pixels=hot_pixels,
        prnu=prnu,
        vignetting=vignetting,
        sensor_seed=sensor_seed,
        rotation=rotation,
        pitch=pitch,
        grid_offset=grid_offset,
    )
    cal = None if calibration_captures is None else _path("calibration_captures", calibration_captures)
    # Checked here: a negative count reached the native call as an OverflowError.
    if isinstance(exposures, (bool, np.bool_)) or not isinstance(exposures, (int, np.integer)):
        raise TypeError(f"exposures: want an integer in 1..=256, got {exposures!r} ({type(exposures).__name__})")
    if not 1 <= int(exposures) <= 256:
        raise ValueError(f"exposures: {int(exposures)} is not in 1..=256")
    frames, text, notes = _slf.simulate(arr, args, cal, int(exposures))
    for n in notes:
        warnings.warn(f"slf: {n}", stacklevel=2)
    return _from_parts((frames, text))


def load_capture(path: PathLike) -> Capture:
    """Reads a capture folder (``capture.json`` and its frames) as ``slf decode`` does."""
    p = os.fspath(path)
    if not os.path.isdir(p):
        raise FileNotFoundError(f"{p}: no such capture folder")
    return _from_parts(_slf.load_capture(p), source=p)


def calibrate(captures: Union[PathLike, Sequence[PathLike]], output: PathLike) -> list:
    """A sensor's calibration from its calibration captures, as ``slf calibrate``: each of
    ``captures`` a capture folder (its ``light`` dark, flat or a band) or a folder of them
    (as ``slf simulate --calibration-captures`` writes); writes the calibration folder
    ``output`` that ``decode(..., calibration=output)`` reads. Returns the command's report
    lines (captures used, hot pixels found, the darkest view's vignetting)."""
    given = [captures] if isinstance(captures, (str, os.PathLike)) else list(captures)
    return list(_slf.calibrate([_path("captures", c) for c in given], _path("output", output)))


def _progress_callback(progress: Any) -> Optional[Callable[[int, int], None]]:
    """``progress`` as a ``(done, total)`` callback: a callable as is, True a tqdm bar
    (a line on stderr without tqdm), None or False nothing."""
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress
    if progress is not True:
        raise TypeError(
            f"progress: want True, False, None or a callable f(done, total), got {progress!r} "
            f"({type(progress).__name__})"
        )
    try:
        from tqdm.auto import tqdm  # type: ignore
    except ImportError:
        tqdm = None
    state: Dict[str, Any] = {}

    def update(done: int, total: int) -> None:
        if tqdm is not None:
            bar = state.get("bar")
            if bar is None or bar.total != total:
                if bar is not None:
                    bar.close()
                bar = state["bar"] = tqdm(total=total, unit="tile", desc="decoding")
            bar.update(done - bar.n)
            if done == total:
                bar.close()
        else:
            sys.stderr.write(f"\rdecoding {done}/{total} tiles")
            if done == total:
                sys.stderr.write("\n")
            sys.stderr.flush()

    return update


def decode(
    capture: Union[Capture, PathLike],
    method: str = "cs",
    preset: str = "default",
    *,
    stride: Optional[int] = None,
    window: Optional[str] = None,
    disparities: Union[None, str, Sequence[float]] = None,
    edge_fallback: Optional[bool] = None,
    sheared_fallback: Optional[bool] = None,
    seeded: Optional[bool] = None,
    schedule: Optional[str] = None,
    patch_views: Optional[int] = None,
    dictionary: Optional[str] = None,
    choice: Optional[str] = None,
    blob: Optional[PathLike] = None,
    calibration: Optional[PathLike] = None,
    response_model: Optional[str] = None,
    grid: Optional[str] = None,
    balance: Optional[str] = None,
    gains: Optional[Sequence[float]] = None,
    adaptive: Optional[float] = None,
    sigma_f: Optional[float] = None,
    steps: Optional[int] = None,
    mu: Optional[float] = None,
    sigma_min: Optional[float] = None,
    max_iterations: Optional[int] = None,
    noise: Optional[float] = None,
    shot: Optional[float] = None,
    exact: bool = False,
    tolerance: Optional[float] = None,
    warm_start: Optional[float] = None,
    warm_sigma_f: Optional[float] = None,
    warm_steps: Optional[int] = None,
    seed_sigma_f: Optional[float] = None,
    cold_start: Optional[float] = None,
    flat: Optional[float] = None,
    min_bands: Optional[int] = None,
    plausible: Union[None, str, Tuple[float, float]] = None,
    shear_check: bool = False,
    model_trial: Optional[bool] = None,
    trial_by: Optional[str] = None,
    baseline_blend: Optional[bool] = None,
    shear_trial: Optional[bool] = None,
    error_map: bool = False,
    estimate_by: Optional[str] = None,
    threads: Optional[int] = None,
    progress: Any = None,
    report: bool = False,
    output: Optional[PathLike] = None,
    slot: Optional[int] = None,
) -> Union[np.ndarray, Tuple[np.ndarray, Dict[str, Any]]]:
    """Decodes a capture (or a capture folder's path) as ``slf decode`` does, bit for bit.

    Returns the light field ``(U, V, H, W, 13)`` float32, or with ``report=True`` the pair
    ``(light field, report)``: a dict of patches decoded / flagged / failed, of the decoded
    those solved / interpolated (fewer than ``min_bands`` bands measured) / flat, tiles, solves,
    steps, band gains, seconds, the per-lenslet disparity map (``report["disparity"]``, an
    array, or None when no disparity was searched), ``stride``, ``seeded`` (whether the shifted
    patches started from the disjoint grid's decode), ``patch_views`` (4 or 5: the views per
    axis of the patch it decoded with), ``off_sensor_lenslets`` and ``off_sensor_views`` (what
    the lenslet grid puts past the sensor's edges: views never measured, guessed from their
    neighbours; ``evaluate(..., border=2)`` scores without the edge lenslets), ``coverage``
    (each lenslet's share of views on the sensor, an ``(H, W)`` array: 1 but at those
    lenslets, which ``estimated_psnr`` leaves out) and a
    ``warning`` when over 1 % of the patches failed or were flagged.

    ``method``: cs (compressed sensing), interpolate, demosaic or ppid (baselines).
    ``preset``: preview (fast), default or best; any keyword below overrides the preset's
    value. The keywords are ``slf decode``'s flags (see ``slf decode --help``):
    ``stride`` 1..=5, ``window`` uniform or tapered, ``disparities`` ``"MIN:MAX[:STEP]"``
    or ``(min, max[, step])``, ``edge_fallback``, ``sheared_fallback`` (every sheared block decoded unsheared as
    well, for the values no sheared patch reached; True in the preview), ``seeded`` (shifted patches started from
    the disjoint grid's decode), ``schedule`` trained (the blob's trained schedules, the
    default) or annealed (the hand-set one the solver keywords set), ``patch_views`` 4 or 5 (the paper's 4 x 4-view patch or the
    full-view patch; default 5 for lenslets of 5 x 5 views), ``dictionary`` dct or ensemble,
    ``choice``, ``blob`` (an ensemble file), ``calibration`` (a folder ``slf calibrate``
    wrote: dark levels, flats, hot pixels and the filters' response corrected, baselines
    too), ``response_model`` unmix (the default: each decoded spectrum unmixed by the
    response's inverse) or projection (the response in every projection of the solve),
    ``grid`` auto (the calibration's lenslet grid if it found one, else the capture's),
    capture (the capture's ``lenslet_grid``) or aligned (the frames read as an aligned
    array's, slf before grids), ``balance`` grey or off, ``gains`` (13),
    ``adaptive`` and the solver's ``sigma_f`` ... ``min_bands``, ``plausible``,
    ``shear_check``, ``model_trial`` (the ensemble or the DCT for the frame by their
    held-out errors on pilot patches; default True in every preset, leaning to the DCT in
    the preview, False where ``dictionary`` is named: ``report["trial"]`` says which, the
    errors and ``tied`` (the two within their spread, so the mask's favoured model decoded);
    ``trial_by="decode"`` tells them apart by the frame decoded again by each from
    seven in eight samples, two more decodes: ``report["trial"]["decode_dct_error"]`` and
    ``["decode_ensemble_error"]``), ``baseline_blend`` (on a kronecker mask, each block mixed
    from the decode and PPID by their held-out errors; default True: ``report["baseline_blend"]``
    gives PPID's mean weight, its weight per lenslet (``"weights"``), the lenslets mostly PPID's
    and its seconds), ``shear_trial`` (whole disparities only for the frame where pilot patches
    estimate them clearly better than the half-pixel ones; default True:
    ``report["shear_trial"]``, or ``report["shear_trial_skipped"]`` saying why it did not
    run: no half-pixel disparity to try), ``error_map`` (the decode's error per lenslet in
    ``report["error_map"]`` and its estimated PSNR), ``estimate_by`` decode (the frame
    decoded again from seven in eight samples by the same plan, the default: a second
    decode's time) or patches (each patch solved once more, a solve a patch).

    ``threads``: threads of this decode (None: one per core; 1 inside a Dask task).
    ``progress``: True for a bar (tqdm if installed), or a callable ``f(done, total)``
    called after each tile, from the decode's threads. The GIL is released while decoding.

    ``output``: a ``.npy`` path the light field is written to as its rows are decoded, as
    ``slf decode -o`` writes it: the decode then holds a band of rows, not the frame (a
    frame of any size fits), the file is in place only once the decode is done (a failed
    decode leaves none), and the light field returned is a read-only memory map of it
    (``np.load(output, mmap_mode="r")``). ``report["rows_held"]``: the most lenslet rows
    of sums the decode held at once. A path ending in ``.zarr`` writes a Zarr v3 store as
    ``slf decode -o OUT.zarr`` does (the array ``lightfield``, the ``band`` coordinate, the
    capture's description and the settings in the group's attributes), and the light field
    returned is the store's array opened read-only by zarr-python (None without it).
    ``slot``: with ``output`` the temporary store ``slf.batch.decode_folder`` made for many
    captures, the capture's index in it (None is returned).
    """
    cap = capture if isinstance(capture, Capture) else load_capture(capture)
    if isinstance(disparities, (list, tuple)):
        disparities = ":".join(f"{d:g}" for d in disparities)
    edge_fallback = _switch("edge_fallback", edge_fallback)  # type: ignore[assignment]
    sheared_fallback = _switch("sheared_fallback", sheared_fallback)  # type: ignore[assignment]
    seeded = _switch("seeded", seeded)  # type: ignore[assignment]
    model_trial = _switch("model_trial", model_trial)  # type: ignore[assignment]
    baseline_blend = _switch("baseline_blend", baseline_blend)  # type: ignore[assignment]
    shear_trial = _switch("shear_trial", shear_trial)  # type: ignore[assignment]
    exact = bool(_bool("exact", exact, False))
    shear_check = bool(_bool("shear_check", shear_check, False))
    error_map = bool(_bool("error_map", error_map, False))
    report = bool(_bool("report", report, False))
    if isinstance(plausible, (list, tuple)):
        plausible = ":".join(f"{p:g}" for p in plausible)
    if blob is not None:
        blob = _path("blob", blob)
    if calibration is not None:
        calibration = _path("calibration", calibration)
    if output is not None:
        output = _path("output", output)
    args = _flags(
        method=method,
        preset=preset,
        stride=stride,
        window=window,
        disparities=disparities,
        edge_fallback=edge_fallback,
        sheared_fallback=sheared_fallback,
        seeded=seeded,
        schedule=schedule,
        patch_views=patch_views,
        dictionary=dictionary,
        choice=choice,
        blob=blob,
        calibration=calibration,
        response_model=response_model,
        grid=grid,
        balance=balance,
        gains=gains,
        adaptive=adaptive,
        sigma_f=sigma_f,
        steps=steps,
        mu=mu,
        sigma_min=sigma_min,
        max_iterations=max_iterations,
        noise=noise,
        shot=shot,
        exact=exact,
        tolerance=tolerance,
        warm_start=warm_start,
        warm_sigma_f=warm_sigma_f,
        warm_steps=warm_steps,
        seed_sigma_f=seed_sigma_f,
        cold_start=cold_start,
        flat=flat,
        min_bands=min_bands,
        plausible=plausible,
        shear_check=shear_check,
        model_trial=model_trial,
        trial_by=trial_by,
        baseline_blend=baseline_blend,
        shear_trial=shear_trial,
        estimate=True if error_map else None,
        estimate_by=estimate_by,
    )
    frames = _raw_frames(cap.frames)
    path = None if output is None else os.fspath(output)
    # The native decode refuses an output that is a file of the capture's folder, the
    # calibration or the blob, or not a .npy or .zarr path, before it decodes (as `slf decode` does).
    source = getattr(cap, "source", None)
    if slot is not None and (isinstance(slot, (bool, np.bool_)) or not isinstance(slot, (int, np.integer)) or slot < 0):
        raise TypeError(f"slot: want a capture's index at or above 0, got {slot!r}")
    lf, rep = _slf.decode(
        frames,
        json.dumps(cap.description),
        args,
        threads,
        _progress_callback(progress),
        path,
        source,
        None if slot is None else int(slot),
    )
    if path is not None and slot is None:
        if path.lower().endswith(".zarr"):
            try:
                import zarr
            except ImportError:
                lf = None
            else:
                lf = zarr.open_array(path, path="lightfield", mode="r")
        else:
            lf = np.load(path, mmap_mode="r")
    if "warning" in rep:
        warnings.warn(f"slf: {rep['warning']}", stacklevel=2)
    return (lf, rep) if report or error_map else lf


def evaluate(truth: np.ndarray, recon: np.ndarray, *, border: int = 0) -> Dict[str, float]:
    """PSNR (dB, data range = max of ``truth``), SSIM and spectral angle (degrees) of
    ``recon`` against ``truth``, both ``(U, V, H, W, B)``, as ``slf eval``:
    ``{"psnr", "ssim", "sa", "data_range"}``. ``border``: score only the lenslets that many
    in from every edge (``slf eval --border``: a turned lenslet array's corners reach past
    the sensor)."""
    t = _as_float32(truth, "truth", "(U, V, H, W, B)")
    r = _as_float32(recon, "recon", "(U, V, H, W, B)")
    if t.shape != r.shape:
        raise ValueError(f"shapes differ: truth {t.shape}, recon {r.shape}")
    if isinstance(border, (bool, np.bool_)) or not isinstance(border, (int, np.integer)) or border < 0:
        raise TypeError(f"border: want a whole number of lenslets at or above 0, got {border!r}")
    b = int(border)
    if b > 0:
        if 2 * b >= min(t.shape[2], t.shape[3]):
            raise ValueError(f"border {b}: the light field has {t.shape[2]} x {t.shape[3]} lenslets, nothing is {b} in from every edge")
        t, r = (np.ascontiguousarray(a[:, :, b:-b, b:-b]) for a in (t, r))
    return dict(_slf.evaluate(t, r))


def _imported(out: Tuple[np.ndarray, Optional[np.ndarray], list], source: str, with_disparity: bool) -> Any:
    lf, disparity, notes = out
    for n in notes:
        warnings.warn(f"slf: {source}: {n}", stacklevel=3)
    return (lf, disparity) if with_disparity else lf


def import_views(
    folder: PathLike,
    *,
    pattern: Optional[str] = None,
    index_base: Optional[int] = None,
    grid: Optional[Tuple[int, int]] = None,
    views: Optional[Tuple[int, int]] = None,
    start: Optional[Tuple[int, int]] = None,
    crop: Optional[Tuple[int, int, int, int]] = None,
    resize: Optional[Tuple[int, int]] = None,
    fill: Optional[str] = None,
    linear: bool = False,
    disparity: Optional[PathLike] = None,
    max_disparity: Optional[float] = None,
    with_disparity: bool = False,
) -> Any:
    """A folder of RGB views as the camera's 13 bands, as ``slf import views``:
    ``(U, V, H, W, 13)`` float32, or ``(light field, disparity)`` with
    ``with_disparity=True`` (the centre view's disparity map, or None).

    HCI benchmark naming unless ``pattern`` (``"view_{row:02}_{col:02}.png"``);
    ``grid`` the full view grid (default 9, 9), ``views`` the window read (default 5, 5),
    ``start`` its first view (default centred), ``crop`` (row, col, rows, cols) and
    ``resize`` (rows, cols) in pixels, ``fill="warp"`` to make missing views.
    """
    args = [os.fspath(folder)] + _flags(
        pattern=pattern,
        index_base=index_base,
        grid=grid,
        views=views,
        start=start,
        crop=crop,
        resize=resize,
        fill=fill,
        linear=linear,
        disparity=None if disparity is None else os.fspath(disparity),
        max_disparity=max_disparity,
    )
    return _imported(_slf.import_views(args), os.fspath(folder), with_disparity)


def import_cube(
    input: PathLike,
    *,
    wavelengths: Optional[str] = None,
    white: Optional[float] = None,
    light: Optional[str] = None,
    views: Optional[Tuple[int, int]] = None,
    disparity: Optional[float] = None,
    disparity_map: Optional[PathLike] = None,
    crop: Optional[Tuple[int, int, int, int]] = None,
    resize: Optional[Tuple[int, int]] = None,
    with_disparity: bool = False,
) -> Any:
    """A hyperspectral cube (an ``(H, W, B)`` .npy, or a folder of band images) as a light
    field of the camera's 13 bands, its views made by a disparity, as ``slf import cube``.

    ``wavelengths`` of the cube's bands (``"START:STOP:STEP"`` or a comma list, nm),
    ``white`` the value of a perfect white, ``light`` reflectance (lit by D65) or radiance,
    ``views`` (U, V), ``disparity`` a plane's (pixels per view step) or ``disparity_map``
    a .pfm of the cube's size.
    """
    args = [os.fspath(input)] + _flags(
        wavelengths=wavelengths,
        white=white,
        light=light,
        views=views,
        disparity=disparity,
        disparity_map=None if disparity_map is None else os.fspath(disparity_map),
        crop=crop,
        resize=resize,
    )
    return _imported(_slf.import_cube(args), os.fspath(input), with_disparity)
