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
# The place of the viewer's close-up (README): a ridge with snowfields and cave mouths above a
# bay with a beach.
place = (3.0, 9.0)
ground = planet.surface_height(*place)
print(f"the ground at {place}: {ground:.0f} m above the sea")

# %%
region = planet.region(place[0], place[1], 450.0, level=0)
mesh = region.to_pyvista()
print(region, f"from {region.chunks} chunks")
# The mesh is the ground, the sea floor included: tint the floor by the depth of water above it
# (the vertices' `water_depth`), as the viewer's translucent sea does.
depth = mesh.point_data["water_depth"][:, None]
sea = np.array([28.0, 92.0, 128.0])
clear = np.exp(-depth / 6.0)
mesh.point_data["colors"] = (mesh.point_data["colors"] * clear + sea * (1 - clear)).astype(np.uint8)

# %%
pv.OFF_SCREEN = True
plotter = pv.Plotter(off_screen=True, window_size=(1280, 720))
plotter.set_background("#0b1020", top="#3a5f8f")
plotter.add_mesh(mesh, scalars="colors", rgb=True, smooth_shading=True, specular=0.1)
# Looking at the place from the south-east and above it.
lat0, lon0 = np.radians(place[0]), np.radians(place[1])
up = np.array([np.cos(lat0) * np.sin(lon0), np.sin(lat0), np.cos(lat0) * np.cos(lon0)])
centre = up * (planet.info()["datum_radius"] + ground)
east = np.cross([0.0, 1.0, 0.0], up)
east /= np.linalg.norm(east)
north = np.cross(up, east)
plotter.camera_position = [tuple(centre + 330 * up - 480 * north + 260 * east), tuple(centre - 40 * up + 60 * north), tuple(up)]
out = sys.argv[1] if len(sys.argv) > 1 else "python-pyvista.png"
plotter.screenshot(out)
print("wrote", out)
