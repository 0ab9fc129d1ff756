"""Type stubs of the native module `slf._slf` (PyO3). Use the functions of `slf`, which
convert arrays and keywords; these take the `slf` command's flags as strings."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

LightField = npt.NDArray[np.float32]
Frames = npt.NDArray[np.uint16]

def scene(name: str, size: int, views: int, seed: int) -> LightField: ...
def simulate(
    lf: LightField, args: List[str], calibration_captures: Optional[str], exposures: int
) -> Tuple[Frames, str, List[str]]: ...
def load_capture(path: str) -> Tuple[Frames, str]: ...
def save_capture(frames: Frames, description: str, path: str) -> None: ...
def check_capture(frames: Frames, description: str) -> str: ...
def decode(
    frames: Frames,
    description: str,
    args: List[str],
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    output: Optional[str] = None,
    source: Optional[str] = None,
    slot: Optional[int] = None,
) -> Tuple[Optional[LightField], Dict[str, Any]]: ...

class Stack:
    def __init__(
        self,
        path: str,
        captures: int,
        shape: Tuple[int, int, int, int, int],
        bands_nm: List[float],
        inputs: List[str],
        gzip: Optional[int] = None,
    ) -> None: ...
    @property
    def path(self) -> str: ...
    def finish(self, attrs: str) -> None: ...
    def discard(self) -> None: ...
def evaluate(truth: LightField, recon: LightField) -> Dict[str, float]: ...
def import_views(args: List[str]) -> Tuple[LightField, Optional[npt.NDArray[np.float32]], List[str]]: ...
def import_cube(args: List[str]) -> Tuple[LightField, Optional[npt.NDArray[np.float32]], List[str]]: ...
