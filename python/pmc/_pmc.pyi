"""Type stubs of the native module `pmc._pmc` (the engine's crates behind numpy arrays). Use the
package's wrappers (`pmc.Planet`, `pmc.World`, `pmc.dem`, `pmc.bake`), which document each call."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
PRESETS: List[str]
FACES: List[str]

Root = Tuple[int, int, int, int, int]
_Path = Union[str, PathLike[str]]

class PmcError(Exception):
    """An error of the PMC engine: the message says what is wrong and how to fix it."""

class Planet:
    def __init__(
        self,
        preset: str = "earthlike",
        seed: int = 7,
        *,
        radius: Optional[float] = None,
        n_c: Optional[int] = None,
        n_t: Optional[int] = None,
        d_b: Optional[float] = None,
        l_d: Optional[float] = None,
        d_c: Optional[int] = None,
        dem: Optional[_Path] = None,
        interpolation: str = "bicubic",
    ) -> None: ...
    @staticmethod
    def from_spec(terrain: str, layout: Sequence[float], world: Optional[_Path]) -> Planet: ...
    def spec(self) -> Tuple[str, Tuple[float, float, float, float, float], Optional[str]]: ...
    def info(self) -> Dict[str, Any]: ...
    def chunk(self, face: Union[int, str], level: int, i: int, j: int, k: int, seams: int = 0) -> Dict[str, np.ndarray]: ...
    def region(self, lat: float, lon: float, radius_m: float, level: int = 0) -> Dict[str, Any]: ...
    def density(self, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def surface_height(self, lat: npt.NDArray[np.float64], lon: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def path(
        self,
        start: Sequence[float],
        goal: Sequence[float],
        *,
        clearance: Optional[float] = None,
        step_up: Optional[float] = None,
        step_down: Optional[float] = None,
        max_slope: Optional[float] = None,
        lazy: Optional[bool] = None,
    ) -> Tuple[str, npt.NDArray[np.float64]]: ...

class World:
    @staticmethod
    def open(path: _Path) -> World: ...
    @staticmethod
    def create(path: _Path, planet: Planet) -> World: ...
    @property
    def planet(self) -> Planet: ...
    def edit(
        self,
        brush: str,
        lat: float,
        lon: float,
        radius: float,
        *,
        alt: Optional[float] = None,
        strength: float = 1.0,
        material: Union[str, int, None] = None,
    ) -> int: ...
    def undo(self) -> Optional[int]: ...
    def redo(self) -> Optional[int]: ...
    def edits(self) -> List[Dict[str, Any]]: ...
    def close(self) -> None: ...

class TileBake:
    def __init__(
        self,
        planet: Planet,
        *,
        max_level: Optional[int] = None,
        min_level: int = 0,
        region: Optional[Tuple[float, float, float]] = None,
        frame: str = "auto",
    ) -> None: ...
    def roots(self) -> List[Root]: ...
    def manifest(self) -> bytes: ...
    def tileset(self) -> bytes: ...
    def subtree_path(self, root: Root) -> str: ...
    def children(self, root: Root) -> List[Root]: ...
    def subtree(self, root: Root) -> Tuple[List[Tuple[str, Optional[int], bytes]], List[Root]]: ...
    def subtrees(self, roots: Sequence[Root]) -> List[Tuple[List[Tuple[str, Optional[int], bytes]], List[Root]]]: ...
    @property
    def levels(self) -> int: ...

def import_dem_array(
    heights: npt.NDArray[np.float32],
    west: float,
    south: float,
    east: float,
    north: float,
    output: _Path,
    *,
    north_first: bool = True,
    cell_centres: bool = True,
    nodata: Optional[float] = None,
    name: str = "array",
    level: Optional[int] = None,
    bits: str = "auto",
    radius: Optional[float] = None,
) -> Dict[str, Any]: ...
def bake_batch() -> int: ...
