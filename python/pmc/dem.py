"""Real planets from elevation data held in memory: anything rasterio or xarray reads (any GDAL
format, netCDF4, Zarr) becomes a cube-face elevation file (``.pmcdem``) for
:meth:`pmc.Planet.from_dem`, as ``pmc dem import`` makes one from a file."""

from __future__ import annotations

import os
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from . import _pmc
from ._pmc import PmcError

__all__ = ["import_array"]

_LAT_NAMES = ("lat", "latitude", "y", "rlat")
_LON_NAMES = ("lon", "longitude", "x", "rlon")


def _axis(coords: Any, names: Sequence[str], what: str) -> Tuple[str, np.ndarray]:
    for n in names:
        if n in coords:
            return n, np.asarray(coords[n].values, dtype=np.float64)
    raise PmcError(f"the array has no {what} coordinate (looked for {', '.join(names)}); give extent= instead")


def _from_xarray(da: Any) -> Tuple[np.ndarray, Tuple[float, float, float, float], bool, Optional[float]]:
    """Heights, extent (cell edges), north-first flag and nodata of an xarray DataArray."""
    lat_name, lat = _axis(da.coords, _LAT_NAMES, "latitude")
    lon_name, lon = _axis(da.coords, _LON_NAMES, "longitude")
    if len(lat) < 2 or len(lon) < 2:
        raise PmcError("the array needs at least 2 latitudes and 2 longitudes to know its spacing")
    da = da.transpose(lat_name, lon_name)
    dlat, dlon = abs(lat[1] - lat[0]), abs(lon[1] - lon[0])
    west, east = min(lon[0], lon[-1]) - dlon / 2, max(lon[0], lon[-1]) + dlon / 2
    south, north = min(lat[0], lat[-1]) - dlat / 2, max(lat[0], lat[-1]) + dlat / 2
    values = np.asarray(da.values)
    if lon[0] > lon[-1]:
        values = values[:, ::-1]
    nodata = da.attrs.get("_FillValue", da.attrs.get("nodata", da.encoding.get("_FillValue")))
    return values, (west, south, east, north), bool(lat[0] > lat[-1]), None if nodata is None else float(nodata)


def import_array(
    array: Any,
    output: Union[str, "os.PathLike[str]"],
    *,
    extent: Optional[Sequence[float]] = None,
    nodata: Optional[float] = None,
    north_up: Optional[bool] = None,
    cell_centres: bool = True,
    level: Optional[int] = None,
    bits: str = "auto",
    radius: Optional[float] = None,
    name: Optional[str] = None,
) -> Dict[str, Any]:
    """Imports a grid of heights (metres) into the cube-face elevation file ``output``.

    ``array`` is a 2-D numpy array (rows of longitudes; a masked array's masked cells are
    missing) with ``extent = (west, south, east, north)`` in degrees — rasterio's
    ``src.bounds`` is in that order — or an ``xarray.DataArray`` with latitude and longitude
    coordinates (its extent and orientation are read from them).

    - ``north_up``: whether the first row is the northernmost (images, GeoTIFFs); default True
      for a plain array.
    - ``cell_centres``: whether ``extent`` bounds the cells (True: each height at its cell's
      centre) or gives the outer rows' and columns' positions (False, a grid of nodes).
    - ``nodata``: the value that marks a missing height (NaN always does).
    - ``level``, ``bits`` (``auto``, ``i16`` or ``f32``) and ``radius`` (the body's, metres):
      as ``pmc dem import``'s ``--level``, ``--bits`` and ``--radius``.

    Returns the import's report: level, format, digest, bytes, samples filled. Errors (a bad
    extent, an array of the wrong shape, no valid height) raise :class:`pmc.PmcError`, and no
    file is left at ``output``.
    """
    if hasattr(array, "dims") and hasattr(array, "coords") and extent is None:
        values, extent, north_first, found_nodata = _from_xarray(array)
        if nodata is None:
            nodata = found_nodata
        if north_up is not None:
            north_first = north_up
        name = name or str(getattr(array, "name", None) or "xarray")
    else:
        if extent is None:
            raise PmcError("give extent=(west, south, east, north) in degrees for a plain array")
        values = array
        north_first = True if north_up is None else bool(north_up)
        name = name or "array"
    if np.ma.isMaskedArray(values):
        values = np.ma.filled(values.astype(np.float32), np.nan)
    values = np.asarray(values)
    if values.ndim != 2:
        raise PmcError(f"heights must be a 2-D array of rows, got {values.ndim} dimensions (shape {values.shape})")
    ext = [float(v) for v in extent]
    if len(ext) != 4:
        raise PmcError(f"extent is (west, south, east, north), got {len(ext)} numbers")
    west, south, east, north = ext
    heights = np.ascontiguousarray(values, dtype=np.float32)
    return _pmc.import_dem_array(
        heights,
        west,
        south,
        east,
        north,
        os.fspath(output),
        north_first=north_first,
        cell_centres=cell_centres,
        nodata=None if nodata is None else float(nodata),
        name=name,
        level=level,
        bits=bits,
        radius=radius,
    )
