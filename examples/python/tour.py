# %% [markdown]
# # A tour of PMC from Python
#
# A planet with caves and overhangs as numpy arrays, a real planet from an elevation grid, an
# edit that lasts, a walk over the ground and a region handed to trimesh. Run it as a script
# (`python examples/python/tour.py`), or open it as a notebook: each `# %%` is a cell (Jupyter
# with jupytext, VS Code, Spyder). The tests run it (python/tests/test_examples.py).

# %%
import os
import tempfile

import numpy as np

import pmc
import pmc.dem

work = tempfile.mkdtemp(prefix="pmc-tour-")

# %% [markdown]
# ## A procedural planet
# `earthlike`: continents, seas, mountains, caves and overhangs, 2 km in radius with 4 m voxels.

# %%
planet = pmc.Planet(preset="earthlike", seed=7)
info = planet.info()
print(planet)
print(f"{info['chunks']} chunks, levels 0 to {info['max_level']}, materials: {', '.join(info['materials'])}")

# %% [markdown]
# ## One chunk, as numpy arrays
# Positions are f32 relative to the chunk's f64 origin; `world_positions()` gives f64 metres.

# %%
chunk = planet.chunk("top", 0, 3, 4, 1)
print(chunk, chunk.positions.dtype, chunk.indices.shape)
world = chunk.world_positions()
print("the chunk spans", np.ptp(world, axis=0).round(1), "metres")

# %% [markdown]
# ## Heights and densities, vectorised
# The density is positive in rock and negative in air: a cave is air below the ground.

# %%
lat = np.linspace(-60, 60, 5)
lon = np.linspace(-180, 180, 9)
heights = planet.surface_height(lat[:, None], lon[None, :])
print("ground heights (m):\n", heights.round(0))

# A column straight down from the sky at one place: where the density changes sign, there is a
# surface; more than one crossing is a cave or an overhang no heightmap can hold.
up = np.array([0.0, 0.0, 1.0])
radii = np.linspace(info["datum_radius"] - 200, info["datum_radius"] + 200, 801)
column = planet.density(up[None, :] * radii[:, None])
surfaces = np.count_nonzero(np.diff(np.sign(column)))
print(f"{surfaces} surfaces along the column at lat 0, lon 0")

# %% [markdown]
# ## A walk over the ground

# %%
walk = planet.path((10.0, 20.0), (11.0, 21.0))
print(walk)

# %% [markdown]
# ## An edit that lasts
# A world file keeps the edits (SQLite); each is saved before `edit` returns.

# %%
with pmc.World.create(os.path.join(work, "tour.pmcw"), planet) as w:
    before = w.planet.surface_height(10.0, 20.0)
    w.edit("remove", 10.0, 20.0, radius=25.0)
    after = w.planet.surface_height(10.0, 20.0)
print(f"the ground at 10, 20: {before:.1f} m before the dig, {after:.1f} m after")

# %% [markdown]
# ## A real planet from an elevation grid
# Any 2-D array with its extent (what rasterio's `src.read(1)` and `src.bounds` give), or an
# xarray DataArray with latitude and longitude: here a made-up relief on a 1-degree grid.

# %%
lat_c = np.arange(89.5, -90, -1.0)
lon_c = np.arange(-179.5, 180, 1.0)
relief = (3000 * np.sin(np.radians(2 * lon_c))[None, :] * np.cos(np.radians(lat_c))[:, None]).astype(np.float32)
report = pmc.dem.import_array(relief, os.path.join(work, "relief.pmcdem"), extent=(-180, -90, 180, 90))
real = pmc.Planet.from_dem(os.path.join(work, "relief.pmcdem"), seed=1)
print("imported:", report["format"], f"level {report['level']}", f"{report['bytes'] / 1e6:.1f} MB")
print("the data's height at 0, 45:", relief[89, 224], "m; the planet's:", round(real.surface_height(0.5, 44.5), 1), "m")

# %% [markdown]
# ## A region to trimesh
# Chunks of one level of detail around a place, welded by their grid edges (exactly).

# %%
region = planet.region(10.0, 20.0, 400.0, level=0)
mesh = region.to_trimesh()
print(f"{region.chunks} chunks welded: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles")
mesh.export(os.path.join(work, "region.ply"))
print("wrote", os.path.join(work, "region.ply"))
