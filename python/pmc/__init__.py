"""PMC, Planetary Marching Cubes, from Python.

Whole planets with caves and overhangs, meshed by marching cubes in spherical space, as numpy
arrays: a procedural preset or a real planet from an elevation model, chunk by chunk or a region
at a time, with densities, surface heights, walking paths and durable edits. Meshes convert to
``trimesh.Trimesh`` and ``pyvista.PolyData``; ``pmc.dem.import_array`` turns any raster that
rasterio or xarray reads into a planet; ``pmc.bake.tiles`` bakes 3D Tiles on a Dask cluster.

>>> import pmc
>>> moon = pmc.Planet(preset="moon", seed=3)
>>> mesh = moon.chunk("top", 0, 3, 4, 1)
>>> mesh.positions.shape[1], mesh.indices.shape[1]
(3, 3)

Every error of the engine is raised as :class:`PmcError` with the engine's message.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _pmc
from ._pmc import FACES, PRESETS, PmcError, __version__
from .mesh import Mesh

__all__ = [
    "FACES",
    "PRESETS",
    "Mesh",
    "Path",
    "Planet",
    "PmcError",
    "World",
    "__version__",
]

FaceLike = Union[int, str]


class Planet:
    """A planet: a terrain on a layout of chunks (six cube faces mapped onto a sphere, each a grid
    of chunks with an outward depth axis).

    ``Planet(preset="earthlike", seed=7)`` makes a procedural planet: ``sphere``,
    ``earthlike``, ``moon``, ``mars`` or ``earth`` (the Earth at true scale, 6 371 km with
    1 m voxels). The same preset, seed and layout give byte-identical meshes everywhere.

    The layout is the preset's own unless given: ``radius`` picks the preset's layout for that
    radius (metres), or each of ``n_c`` (chunks along a face side), ``n_t`` (tiles along a chunk
    side), ``d_b`` (radius of the innermost voxel layer, m), ``l_d`` (depth of a voxel, m) and
    ``d_c`` (chunks along depth) replaces that parameter.

    Other planets: :meth:`Planet.from_dem` (a ``.pmcdem`` file from ``pmc dem import`` or
    :func:`pmc.dem.import_array`) and :meth:`Planet.open_world` (a world file with its edits).

    Bad arguments raise :class:`PmcError` with the engine's message. Meshing releases the GIL,
    so threads can mesh chunks side by side.
    """

    __slots__ = ("_native",)

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
    ) -> None:
        self._native = _pmc.Planet(
            preset, _seed(seed), radius=radius, n_c=n_c, n_t=n_t, d_b=d_b, l_d=l_d, d_c=d_c
        )

    @classmethod
    def _wrap(cls, native: Any) -> "Planet":
        p = cls.__new__(cls)
        p._native = native
        return p

    @classmethod
    def from_dem(
        cls,
        path: Union[str, "os.PathLike[str]"],
        seed: int = 7,
        *,
        interpolation: str = "bicubic",
        n_c: Optional[int] = None,
        n_t: Optional[int] = None,
        d_b: Optional[float] = None,
        l_d: Optional[float] = None,
        d_c: Optional[int] = None,
    ) -> "Planet":
        """A real planet from a cube-face elevation file (``.pmcdem``).

        Heights come from the file, interpolated ``bicubic`` or ``bilinear`` (both exact at the
        samples); detail noise below the data's resolution and caves under the land come from
        ``seed``. The layout is the one for the body's radius unless parameters are given.
        """
        return cls._wrap(
            _pmc.Planet(
                "earthlike",
                _seed(seed),
                n_c=n_c,
                n_t=n_t,
                d_b=d_b,
                l_d=l_d,
                d_c=d_c,
                dem=os.fspath(path),
                interpolation=interpolation,
            )
        )

    @staticmethod
    def open_world(path: Union[str, "os.PathLike[str]"]) -> "World":
        """Opens a world file (made by ``pmc edit``, ``pmc serve --world`` or
        :meth:`World.create`): its planet with its edits, editable."""
        return World.open(path)

    @classmethod
    def from_spec(cls, spec: Dict[str, Any]) -> "Planet":
        """The planet a :attr:`spec` describes (what a bake's workers receive)."""
        try:
            terrain, layout, world = spec["terrain"], spec["layout"], spec.get("world")
        except (KeyError, TypeError) as e:
            raise PmcError(f"a planet spec is a dict with 'terrain' and 'layout' (and 'world'), got {spec!r}") from e
        return cls._wrap(_pmc.Planet.from_spec(str(terrain), [float(x) for x in layout], world))

    @property
    def spec(self) -> Dict[str, Any]:
        """What another process needs to build this planet again: the terrain's canonical text
        (``preset:NAME:SEED``, or ``dem:INTERPOLATION:SEED:DIGEST:PATH``), the five layout
        parameters, and the world file if the planet is a world's."""
        terrain, layout, world = self._native.spec()
        return {"terrain": terrain, "layout": list(layout), "world": None if world is None else os.fspath(world)}

    def info(self) -> Dict[str, Any]:
        """The planet's description: terrain, preset, seed, layout, radius, datum radius, sea
        radius, finest-to-coarsest levels, chunk count, materials (and the world's edits)."""
        return self._native.info()

    def chunk(self, face: FaceLike, level: int, i: int, j: int, k: int, seams: int = 0) -> Mesh:
        """The mesh of one chunk: ``face`` (0 to 5, or a name of :data:`FACES`), ``level`` of
        detail (0 the finest), indices ``i``, ``j`` along the face and ``k`` along depth.

        ``seams`` is the mask of sides whose neighbour is one level coarser (bits: u min, u max,
        v min, v max, inner, outer): those sides get the transition cells that keep a mixed-level
        selection closed. Positions are f32 relative to ``mesh.origin`` (f64, planet-centred
        metres); :meth:`Mesh.world_positions` gives them in f64.
        """
        return Mesh._from_native(self._native.chunk(face, int(level), int(i), int(j), int(k), int(seams)))

    def region(self, lat: float, lon: float, radius_m: float, level: int = 0) -> Mesh:
        """The surface within ``radius_m`` metres of the ground at ``lat``, ``lon`` (degrees),
        from the chunks of one level of detail welded into one mesh (f64 planet-centred
        positions, vertices shared between chunks merged by their grid edge, exactly)."""
        return Mesh._from_native(self._native.region(float(lat), float(lon), float(radius_m), int(level)), welded=True)

    def density(self, points: Any) -> np.ndarray:
        """The density at planet-centred points (metres; an ``(n, 3)`` array, or one point):
        positive inside the ground, negative in air and water; the surface is its zero."""
        p = np.asarray(points, dtype=np.float64)
        one = p.ndim == 1
        p = np.ascontiguousarray(p.reshape(1, -1) if one else p)
        out = self._native.density(p)
        return out[0] if one else out

    def surface_height(self, lat: Any, lon: Any) -> Union[float, np.ndarray]:
        """The height of the ground above the datum (sea level, or the middle of the shell on
        planets without a sea) at ``lat``, ``lon`` in degrees: numbers or arrays, broadcast
        together. The ground is the first surface met going down from the top of the shell."""
        la, lo = np.broadcast_arrays(np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64))
        out = self._native.surface_height(np.ascontiguousarray(la.ravel()), np.ascontiguousarray(lo.ravel()))
        out = out.reshape(la.shape)
        return float(out) if out.ndim == 0 else out

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
    ) -> "Path":
        """A walk over the ground (through caves and under overhangs) from ``start`` to
        ``goal``, each ``(lat, lon)`` or ``(lat, lon, alt)``: an altitude picks the floor nearest
        it. The agent needs ``clearance`` metres of air, climbs at most ``step_up`` and drops at
        most ``step_down`` metres between neighbouring columns, and walks slopes up to
        ``max_slope`` degrees (defaults: a person on the default planet). Small planets use the
        whole-planet grid, large ones the lazy grid built around the search (``lazy`` forces
        either). No path is an answer, not an error: see :attr:`Path.found`."""
        doc, points = self._native.path(
            [float(x) for x in start],
            [float(x) for x in goal],
            clearance=clearance,
            step_up=step_up,
            step_down=step_down,
            max_slope=max_slope,
            lazy=lazy,
        )
        return Path(json.loads(doc), points)

    def __repr__(self) -> str:
        return repr(self._native)


class Path:
    """A path's answer: :attr:`found`, its :attr:`length` in metres, its :attr:`points`
    (``(n, 3)`` planet-centred metres), and :attr:`document`, the answer as ``pmc path`` prints
    it (with the reason when there is no path)."""

    __slots__ = ("document", "points")

    def __init__(self, document: Dict[str, Any], points: np.ndarray) -> None:
        self.document = document
        self.points = points

    @property
    def found(self) -> bool:
        """Whether a path was found."""
        return bool(self.document.get("found"))

    @property
    def length(self) -> Optional[float]:
        """Metres walked, or None without a path."""
        return self.document.get("length") if self.found else None

    @property
    def reason(self) -> Optional[str]:
        """Why there is no path (None when there is one)."""
        return None if self.found else self.document.get("reason")

    def __repr__(self) -> str:
        if self.found:
            return f"Path({len(self.points)} points, {self.length} m)"
        return f"Path(not found: {self.reason})"


class World:
    """A planet with its edits, kept in a world file (SQLite, format pmc-world v2).

    Every edit is saved before :meth:`edit` returns, and survives a crash; :meth:`undo` and
    :meth:`redo` move through the edits. :attr:`planet` is the planet as edited. Use it as a
    context manager, or call :meth:`close`.
    """

    __slots__ = ("_native",)

    def __init__(self, native: Any) -> None:
        self._native = native

    @classmethod
    def open(cls, path: Union[str, "os.PathLike[str]"]) -> "World":
        """Opens an existing world file (a damaged or foreign file raises :class:`PmcError`
        naming it)."""
        return cls(_pmc.World.open(os.fspath(path)))

    @classmethod
    def create(cls, path: Union[str, "os.PathLike[str]"], planet: Planet) -> "World":
        """Creates a world file for ``planet`` at ``path``, which must not exist."""
        return cls(_pmc.World.create(os.fspath(path), planet._native))

    @property
    def planet(self) -> Planet:
        """The planet with the world's active edits."""
        return Planet._wrap(self._native.planet)

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
    ) -> int:
        """Applies a brush: ``add``, ``remove``, ``smooth``, ``flatten`` or ``paint`` (with a
        ``material``, by name or index of ``info()["materials"]``), a ball of ``radius`` metres
        centred at ``lat``, ``lon`` and ``alt`` metres above the datum, or on the ground there
        without ``alt``. The edit is saved before this returns; returns its id."""
        return self._native.edit(
            brush, float(lat), float(lon), float(radius), alt=alt, strength=float(strength), material=material
        )

    def undo(self) -> Optional[int]:
        """Undoes the last active edit (kept for :meth:`redo` until the next edit); returns its
        id, or None when there is nothing to undo."""
        return self._native.undo()

    def redo(self) -> Optional[int]:
        """Redoes the earliest undone edit; returns its id, or None."""
        return self._native.redo()

    def edits(self) -> list:
        """The active edits, oldest first: dicts of brush, center (planet-centred metres),
        radius, strength (and material)."""
        return self._native.edits()

    def close(self) -> None:
        """Closes the file; the world cannot be edited after."""
        self._native.close()

    def __enter__(self) -> "World":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"World({self.planet!r})"


def _seed(seed: int) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise PmcError(f"the seed is a whole number from 0 to 2^64 - 1, got {seed!r}")
    return int(seed)



