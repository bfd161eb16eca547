"""Real planets from arrays: numpy grids and xarray DataArrays become `.pmcdem` files."""

import numpy as np
import pytest
import xarray as xr

import pmc
import pmc.dem


def relief(lat, lon):
    """A smooth test relief, metres: ocean basins and continents."""
    return 3000.0 * np.sin(np.radians(2 * lon)) * np.cos(np.radians(lat)) + 500.0 * np.cos(np.radians(3 * lat))


def global_grid(step=1.0):
    lat = np.arange(90 - step / 2, -90, -step)  # north first, cell centres
    lon = np.arange(-180 + step / 2, 180, step)
    return lat, lon, relief(lat[:, None], lon[None, :]).astype(np.float32)


def test_a_numpy_grid_becomes_a_planet_with_its_heights(tmp_path):
    lat, lon, h = global_grid()
    out = tmp_path / "relief.pmcdem"
    report = pmc.dem.import_array(h, out, extent=(-180, -90, 180, 90))
    assert out.exists() and report["bytes"] == out.stat().st_size and len(report["digest"]) > 8
    planet = pmc.Planet.from_dem(out, seed=1)
    info = planet.info()
    assert info["preset"] == "dem" and info["dem_digest"] == report["digest"]
    # At sample points far from steep ground, the planet's surface is the data's height, up to
    # the detail noise added below the data's resolution and the shell's voxels.
    pick_lat, pick_lon = lat[30:150:20], lon[10:350:45]
    la, lo = np.meshgrid(pick_lat, pick_lon, indexing="ij")
    got = planet.surface_height(la, lo)
    want = relief(la, lo)
    assert np.median(np.abs(got - want)) < 60.0, np.abs(got - want).max()


def test_south_first_rows_and_nodata_are_understood(tmp_path):
    lat, lon, h = global_grid()
    holes = h.copy()
    holes[100:110, 100:110] = -32768.0
    a = pmc.dem.import_array(holes[::-1], tmp_path / "a.pmcdem", extent=(-180, -90, 180, 90), north_up=False, nodata=-32768)
    b = pmc.dem.import_array(np.ma.masked_equal(holes, -32768.0), tmp_path / "b.pmcdem", extent=(-180, -90, 180, 90))
    assert a["digest"] == b["digest"]
    assert a["source_filled"] > 0


def test_an_xarray_dataarray_carries_its_own_extent(tmp_path):
    lat, lon, h = global_grid()
    da = xr.DataArray(h, coords={"lat": lat, "lon": lon}, dims=("lat", "lon"), name="elevation")
    a = pmc.dem.import_array(da, tmp_path / "x.pmcdem")
    b = pmc.dem.import_array(h, tmp_path / "n.pmcdem", extent=(-180, -90, 180, 90))
    assert a["digest"] == b["digest"]
    # Transposed and south-first: the same planet.
    c = pmc.dem.import_array(da.isel(lat=slice(None, None, -1)).transpose("lon", "lat"), tmp_path / "t.pmcdem")
    assert c["digest"] == a["digest"]


def test_bad_grids_are_refused_and_leave_no_file(tmp_path):
    _, _, h = global_grid()
    out = tmp_path / "bad.pmcdem"
    cases = [
        (lambda: pmc.dem.import_array(h, out), "extent"),
        (lambda: pmc.dem.import_array(h, out, extent=(10, -90, -10, 90)), "west"),
        (lambda: pmc.dem.import_array(h, out, extent=(-180, -90, 180)), "extent"),
        (lambda: pmc.dem.import_array(h[0], out, extent=(-180, -90, 180, 90)), "2-D"),
        (lambda: pmc.dem.import_array(np.full((4, 4), np.nan, np.float32), out, extent=(0, 0, 4, 4)), "valid"),
        (lambda: pmc.dem.import_array(h, out, extent=(-180, -90, 180, float("nan"))), "finite"),
        (lambda: pmc.dem.import_array(h, out, extent=(-180, -90, 180, 90), bits="i8"), "bits"),
    ]
    for call, pattern in cases:
        with pytest.raises(pmc.PmcError, match=pattern):
            call()
        assert not out.exists()
