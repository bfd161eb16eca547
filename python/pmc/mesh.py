"""Meshes as numpy arrays, and their conversions to trimesh and pyvista."""

from __future__ import annotations

from typing import Any, Dict, Optional

import numpy as np

__all__ = ["Mesh", "to_pyvista", "to_trimesh"]


class Mesh:
    """A triangle mesh of the planet's surface, as numpy arrays (no copies of the engine's).

    - ``positions``: ``(n, 3)``: f32 relative to ``origin`` for a chunk, f64 planet-centred
      metres for a welded region (``origin`` is then zero);
    - ``origin``: ``(3,)`` f64, planet-centred metres;
    - ``normals``: ``(n, 3)`` f32 unit outward normals (from the density's gradient);
    - ``colors``: ``(n, 4)`` u8 linear RGBA;
    - ``heights``: ``(n,)`` f32 metres above the datum;
    - ``water_depths``: ``(n,)`` f32 metres of sea above the vertex;
    - ``materials``: ``(n,)`` u8 ids into ``Planet.info()["materials"]``;
    - ``indices``: ``(m, 3)`` u32 triangles, counter-clockwise seen from outside;
    - ``edge_keys`` (a chunk's only): ``(n, 4)`` u64, the grid edge each vertex lies on.

    A vertex on a chunk's border lies on the same grid edge as its neighbours' copies, with the
    same ``edge_keys`` ("same edge, same bits"): welding chunks by their edge keys is exact,
    and chunks put side by side form one closed surface.
    """

    __slots__ = (
        "positions",
        "positions_low",
        "origin",
        "normals",
        "colors",
        "heights",
        "water_depths",
        "materials",
        "indices",
        "edge_keys",
        "chunks",
    )

    def __init__(
        self,
        positions: np.ndarray,
        indices: np.ndarray,
        *,
        origin: Optional[np.ndarray] = None,
        positions_low: Optional[np.ndarray] = None,
        normals: Optional[np.ndarray] = None,
        colors: Optional[np.ndarray] = None,
        heights: Optional[np.ndarray] = None,
        water_depths: Optional[np.ndarray] = None,
        materials: Optional[np.ndarray] = None,
        edge_keys: Optional[np.ndarray] = None,
        chunks: int = 1,
    ) -> None:
        n = len(positions)
        self.positions = positions
        self.indices = indices
        self.origin = np.zeros(3) if origin is None else origin
        self.positions_low = positions_low
        self.normals = np.zeros((n, 3), np.float32) if normals is None else normals
        self.colors = np.zeros((n, 4), np.uint8) if colors is None else colors
        self.heights = np.zeros(n, np.float32) if heights is None else heights
        self.water_depths = np.zeros(n, np.float32) if water_depths is None else water_depths
        self.materials = np.zeros(n, np.uint8) if materials is None else materials
        self.edge_keys = edge_keys
        self.chunks = chunks

    @classmethod
    def _from_native(cls, d: Dict[str, Any], welded: bool = False) -> "Mesh":
        return cls(
            d["positions"],
            d["indices"],
            origin=None if welded else d["origin"],
            positions_low=None if welded else d["positions_low"],
            normals=d["normals"],
            colors=d["colors"],
            heights=d["heights"],
            water_depths=d["water_depths"],
            materials=d["materials"],
            edge_keys=d.get("edge_keys"),
            chunks=d.get("chunks", 1),
        )

    @property
    def vertex_count(self) -> int:
        """Number of vertices."""
        return len(self.positions)

    @property
    def triangle_count(self) -> int:
        """Number of triangles."""
        return len(self.indices)

    def world_positions(self) -> np.ndarray:
        """Positions in f64 planet-centred metres: ``origin + positions`` (plus the low part f32
        could not hold, so copies of a vertex in neighbouring chunks agree far below a
        millimetre)."""
        p = self.positions.astype(np.float64) + self.origin
        if self.positions_low is not None:
            p += self.positions_low
        return p

    def to_trimesh(self, **kwargs: Any) -> Any:
        """This mesh as a ``trimesh.Trimesh`` (see :func:`to_trimesh`)."""
        return to_trimesh(self, **kwargs)

    def to_pyvista(self) -> Any:
        """This mesh as a ``pyvista.PolyData`` (see :func:`to_pyvista`)."""
        return to_pyvista(self)

    def __repr__(self) -> str:
        return f"Mesh({self.vertex_count} vertices, {self.triangle_count} triangles)"


def _colors_srgb(linear: np.ndarray) -> np.ndarray:
    """Linear RGBA bytes to sRGB bytes (what trimesh and pyvista display)."""
    c = linear[:, :3].astype(np.float64) / 255.0
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    out = np.empty_like(linear)
    out[:, :3] = np.clip(np.round(s * 255.0), 0, 255).astype(np.uint8)
    out[:, 3] = linear[:, 3]
    return out


def to_trimesh(mesh: Mesh, *, process: bool = False) -> Any:
    """``mesh`` as a ``trimesh.Trimesh`` in f64 planet-centred metres, with its normals and
    sRGB vertex colours, and the heights, water depths and materials in
    ``vertex_attributes``. Needs trimesh (``pip install pmc[trimesh]``)."""
    try:
        import trimesh
    except ImportError as e:
        raise ImportError("to_trimesh needs trimesh: pip install trimesh (or pmc[trimesh])") from e
    t = trimesh.Trimesh(
        vertices=mesh.world_positions(),
        faces=np.asarray(mesh.indices, dtype=np.int64),
        vertex_normals=mesh.normals.astype(np.float64),
        vertex_colors=_colors_srgb(mesh.colors),
        process=process,
    )
    t.vertex_attributes["height"] = mesh.heights
    t.vertex_attributes["water_depth"] = mesh.water_depths
    t.vertex_attributes["material"] = mesh.materials
    return t


def to_pyvista(mesh: Mesh) -> Any:
    """``mesh`` as a ``pyvista.PolyData`` in f64 planet-centred metres, with point data
    ``normals``, ``colors`` (sRGB bytes, for ``rgb=True``), ``height``, ``water_depth`` and
    ``material``. Needs pyvista (``pip install pmc[pyvista]``)."""
    try:
        import pyvista
    except ImportError as e:
        raise ImportError("to_pyvista needs pyvista: pip install pyvista (or pmc[pyvista])") from e
    tris = np.asarray(mesh.indices, dtype=np.int64)
    faces = np.hstack([np.full((len(tris), 1), 3, dtype=np.int64), tris]).ravel()
    poly = pyvista.PolyData(mesh.world_positions(), faces)
    poly.point_data["normals"] = mesh.normals
    poly.point_data["colors"] = _colors_srgb(mesh.colors)[:, :3]
    poly.point_data["height"] = mesh.heights
    poly.point_data["water_depth"] = mesh.water_depths
    poly.point_data["material"] = mesh.materials
    return poly
