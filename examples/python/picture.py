# %% [markdown]
# # A region of a planet, drawn by pyvista
#
# Makes `docs/images/python-pyvista.png`: the earthlike planet around a mountain, welded into one
# mesh by `Planet.region`, handed to pyvista with the engine's vertex colours, drawn off screen.
# Needs pyvista (`pip install pyvista`) and an OpenGL it can draw with off screen (Mesa's OSMesa
# or EGL on a machine without a display).
#
#     python examples/python/picture.py [out.png]

# %%
import sys

import numpy as np
import pyvista as pv

import pmc

planet = pmc.Planet("earthlike", seed=7)
# The highest ground among a few places: a mountain, with its slopes, snow and cave mouths.
lat, lon = np.meshgrid(np.linspace(-40, 40, 41), np.linspace(-180, 175, 72), indexing="ij")
heights = planet.surface_height(lat, lon)
i = np.unravel_index(np.argmax(heights), heights.shape)
place = float(lat[i]), float(lon[i])
print(f"the highest sampled ground: {heights[i]:.0f} m at {place}")

# %%
region = planet.region(place[0], place[1], 500.0, level=0)
mesh = region.to_pyvista()
print(region, f"from {region.chunks} chunks")

# %%
pv.OFF_SCREEN = True
plotter = pv.Plotter(off_screen=True, window_size=(1280, 720))
plotter.set_background("#0b1020", top="#3a5f8f")
plotter.add_mesh(mesh, scalars="colors", rgb=True, smooth_shading=True, specular=0.1)
centre = region.positions.mean(axis=0)
up = centre / np.linalg.norm(centre)
east = np.cross([0.0, 1.0, 0.0], up)
east /= np.linalg.norm(east)
north = np.cross(up, east)
plotter.camera_position = [tuple(centre + 420 * up - 700 * north + 250 * east), tuple(centre), tuple(up)]
out = sys.argv[1] if len(sys.argv) > 1 else "python-pyvista.png"
plotter.screenshot(out)
print("wrote", out)
