"""Planets, chunks, regions, densities, heights and paths through the Python package."""

import threading
import time

import numpy as np
import pytest

import pmc


@pytest.fixture(scope="module")
def sphere():
    # A small exact sphere: every chunk of it meshes in milliseconds.
    return pmc.Planet("sphere", 1, n_c=2, n_t=8, d_b=40.0, l_d=1.0, d_c=2)


@pytest.fixture(scope="module")
def earthlike():
    return pmc.Planet("earthlike", 7)


def test_info_describes_the_planet():
    info = pmc.Planet(preset="moon", seed=3).info()
    assert info["preset"] == "moon" and info["seed"] == 3
    assert info["terrain"] == "preset:moon:3"
    assert info["layout"] == {"n_c": 8, "n_t": 32, "d_b": 1744.0, "l_d": 4.0, "d_c": 2}
    assert info["radius"] == pytest.approx(1744 + 4 * 32 * 2)
    assert info["chunks"] == 6 * 8 * 8 * 2
    assert len(info["materials"]) > 3


def test_the_earth_is_at_true_scale():
    info = pmc.Planet("earth", 7).info()
    assert abs(info["datum_radius"] - 6_371_000) < 1
    assert info["layout"]["l_d"] == 1.0 and info["max_level"] == 18


def test_a_chunk_is_numpy_arrays_of_the_right_kinds(earthlike):
    m = earthlike.chunk("top", 0, 3, 4, 1)
    n = m.vertex_count
    assert n > 0 and m.triangle_count > 0
    assert m.positions.shape == (n, 3) and m.positions.dtype == np.float32
    assert m.origin.shape == (3,) and m.origin.dtype == np.float64
    assert m.normals.shape == (n, 3) and m.normals.dtype == np.float32
    assert m.colors.shape == (n, 4) and m.colors.dtype == np.uint8
    assert m.heights.shape == (n,) and m.heights.dtype == np.float32
    assert m.materials.shape == (n,) and m.materials.dtype == np.uint8
    assert m.indices.shape == (m.triangle_count, 3) and m.indices.dtype == np.uint32
    assert m.indices.max() < n
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-3)
    # The arrays are the engine's buffers handed over, not copies owned by numpy.
    assert not m.positions.flags.owndata and m.positions.base is not None


def test_a_chunk_is_the_same_bytes_every_time():
    a = pmc.Planet("moon", 3).chunk(2, 0, 1, 2, 1)
    b = pmc.Planet("moon", 3).chunk(pmc.FACES[2], 0, 1, 2, 1)
    for name in ("positions", "normals", "colors", "indices", "materials"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name


def test_the_chunks_of_a_planet_close_into_one_surface(sphere):
    """Same edge, same bits: the chunks' border vertices carry the same edge keys as their
    neighbours' copies (and the same place, far below a millimetre), so welding by edge key
    gives a closed 2-manifold of Euler characteristic 2."""
    info = sphere.info()
    n_c, d_c = info["layout"]["n_c"], info["layout"]["d_c"]
    keys, positions, triangles, base = [], [], [], 0
    for f in range(6):
        for i in range(n_c):
            for j in range(n_c):
                for k in range(d_c):
                    m = sphere.chunk(f, 0, i, j, k)
                    keys.append(m.edge_keys)
                    positions.append(m.world_positions())
                    triangles.append(m.indices.astype(np.int64) + base)
                    base += m.vertex_count
    key = np.concatenate(keys)
    p = np.concatenate(positions)
    t = np.concatenate(triangles)
    unique, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    assert np.abs(p - p[first][inverse]).max() < 1e-6
    t = inverse[t]
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    directed = {tuple(e) for e in edges.tolist()}
    assert len(directed) == len(edges), "an edge is used twice in one direction"
    assert all((b, a) in directed for a, b in directed), "an edge has no twin: a hole"
    undirected = len(directed) // 2
    assert len(unique) - undirected + len(t) == 2


def test_seams_give_transition_cells_only_on_real_seams(earthlike):
    plain = earthlike.chunk("top", 0, 3, 4, 1)
    seamed = earthlike.chunk("top", 0, 3, 4, 1, seams=0b1111)
    assert seamed.triangle_count != plain.triangle_count


def test_a_region_is_welded_around_the_place(earthlike):
    r = earthlike.region(10.0, 20.0, 300.0, level=0)
    assert r.chunks >= 1 and r.vertex_count > 0
    assert r.positions.dtype == np.float64 and not r.origin.any()
    # Welded: no two vertices at the same place.
    assert len(np.unique(r.positions, axis=0)) == r.vertex_count
    h = earthlike.surface_height(10.0, 20.0)
    lat, lon = np.radians(10.0), np.radians(20.0)
    # The planet frame: Y to the north pole, longitude 0 on +Z.
    place = (earthlike.info()["datum_radius"] + h) * np.array(
        [np.cos(lat) * np.sin(lon), np.sin(lat), np.cos(lat) * np.cos(lon)]
    )
    d = np.linalg.norm(r.positions - place, axis=1)
    assert d.min() < 50.0


def test_density_is_positive_inside_and_negative_above(earthlike):
    info = earthlike.info()
    lat, lon = np.radians(5.0), np.radians(40.0)
    up = np.array([np.cos(lat) * np.sin(lon), np.sin(lat), np.cos(lat) * np.cos(lon)])
    h = earthlike.surface_height(5.0, 40.0)
    r = info["datum_radius"] + h
    d = earthlike.density(np.stack([up * (r - 30.0), up * (r + 30.0)]))
    assert d.shape == (2,) and d[0] > 0 > d[1]
    assert np.ndim(earthlike.density(up * info["radius"] * 1.5)) == 0


def test_surface_height_broadcasts(earthlike):
    lat = np.linspace(-60, 60, 7)
    h = earthlike.surface_height(lat[:, None], np.array([0.0, 90.0, 180.0]))
    assert h.shape == (7, 3)
    assert isinstance(earthlike.surface_height(1.0, 2.0), float)
    assert h[3, 1] == earthlike.surface_height(0.0, 90.0)


def test_bad_input_raises_pmc_errors_with_the_engines_message(earthlike):
    with pytest.raises(pmc.PmcError, match="unknown preset"):
        pmc.Planet("jupiter")
    with pytest.raises(pmc.PmcError, match="not part of this planet"):
        earthlike.chunk("top", 0, 99, 0, 0)
    with pytest.raises(pmc.PmcError, match="not part of this planet"):
        earthlike.chunk("top", 40, 0, 0, 0)
    with pytest.raises(pmc.PmcError, match="cube face"):
        earthlike.chunk(6, 0, 0, 0, 0)
    with pytest.raises(pmc.PmcError):
        earthlike.chunk("sideways", 0, 0, 0, 0)
    with pytest.raises(pmc.PmcError, match="seams"):
        earthlike.chunk("top", 0, 0, 0, 0, seams=64)
    with pytest.raises(pmc.PmcError, match="not finite"):
        earthlike.density([[0.0, float("nan"), 0.0]])
    with pytest.raises(pmc.PmcError, match="n x 3"):
        earthlike.density(np.zeros((4, 2)))
    with pytest.raises(pmc.PmcError):
        earthlike.surface_height(91.0, 0.0)
    with pytest.raises(pmc.PmcError):
        earthlike.surface_height(float("nan"), 0.0)
    with pytest.raises(pmc.PmcError, match="radius"):
        pmc.Planet("moon", radius=-5.0)
    with pytest.raises(pmc.PmcError, match="not both"):
        pmc.Planet("moon", radius=5000.0, n_c=4)
    with pytest.raises(pmc.PmcError):
        pmc.Planet("moon", n_t=0)
    with pytest.raises(pmc.PmcError, match="seed"):
        pmc.Planet("moon", seed=-1)
    with pytest.raises(pmc.PmcError):
        pmc.Planet.from_dem("/nonexistent/earth.pmcdem")
    with pytest.raises(pmc.PmcError):
        earthlike.region(0.0, 0.0, -1.0)


def test_a_spec_rebuilds_the_same_planet(earthlike):
    again = pmc.Planet.from_spec(earthlike.spec)
    assert again.info() == earthlike.info()
    a, b = earthlike.chunk(0, 0, 1, 1, 1), again.chunk(0, 0, 1, 1, 1)
    assert a.positions.tobytes() == b.positions.tobytes()
    with pytest.raises(pmc.PmcError):
        pmc.Planet.from_spec({"terrain": "preset:nowhere:1", "layout": [8, 32, 1744, 4, 2]})
    with pytest.raises(pmc.PmcError):
        pmc.Planet.from_spec({"layout": [8, 32, 1744, 4, 2]})


def test_a_path_walks_over_the_ground(earthlike):
    p = earthlike.path((10.0, 20.0), (11.0, 21.0))
    assert p.found and p.reason is None
    assert p.points.shape[1] == 3 and len(p.points) >= 2
    straight = np.linalg.norm(p.points[-1] - p.points[0])
    assert p.length >= straight * 0.999
    # Every point lies on the ground: air above it, rock below.
    up = p.points / np.linalg.norm(p.points, axis=1)[:, None]
    assert (earthlike.density(p.points + up * 1.5) < 0).all()


def test_no_path_is_an_answer_not_an_error():
    # An agent that cannot step more than a millimetre finds no way over rough ground.
    moon = pmc.Planet("moon", 3)
    p = moon.path((0.0, 0.0), (1.0, 1.0), step_up=0.001, step_down=0.001, max_slope=1.0)
    assert not p.found and p.reason and p.length is None


def test_meshing_releases_the_gil(earthlike):
    """While another thread meshes a region, this thread keeps running: its longest wait is a
    small part of the meshing's time (a held GIL would block it for all of it)."""
    done = threading.Event()
    spans = {}

    def work():
        t0 = time.perf_counter()
        earthlike.region(-20.0, 60.0, 900.0)
        spans["work"] = time.perf_counter() - t0
        done.set()

    t = threading.Thread(target=work)
    last = time.perf_counter()
    longest = 0.0
    t.start()
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    t.join()
    assert spans["work"] > 0.05
    assert longest < 0.5 * spans["work"], (longest, spans["work"])


def test_help_reads_well():
    doc = pmc.Planet.__doc__
    assert "preset" in doc and "seed" in doc and "from_dem" in doc
    for method in ("chunk", "region", "density", "surface_height", "path", "info"):
        assert getattr(pmc.Planet, method).__doc__.strip(), method


def test_meshes_convert_to_trimesh(earthlike):
    import trimesh

    m = earthlike.region(10.0, 20.0, 300.0)
    t = m.to_trimesh()
    assert isinstance(t, trimesh.Trimesh)
    assert len(t.vertices) == m.vertex_count and len(t.faces) == m.triangle_count
    np.testing.assert_array_equal(t.vertices, m.positions)
    assert t.vertex_attributes["material"].shape == (m.vertex_count,)
    # A closed planet is a watertight trimesh with the sphere's volume.
    sphere = pmc.Planet("sphere", 1, n_c=2, n_t=8, d_b=40.0, l_d=1.0, d_c=2)
    chunks = [sphere.chunk(f, 0, i, j, k) for f in range(6) for i in range(2) for j in range(2) for k in range(2)]
    whole = trimesh.util.concatenate([c.to_trimesh() for c in chunks if c.triangle_count])
    whole.merge_vertices(digits_vertex=9)
    assert whole.is_watertight
    # The sphere preset's radius: d_b + T/2 + 0.37 l_d with T = l_d n_t d_c.
    assert whole.volume == pytest.approx(4 / 3 * np.pi * (40 + 8 * 2 / 2 + 0.37) ** 3, rel=0.02)


def test_meshes_convert_to_pyvista_or_say_how_to_install_it(earthlike):
    m = earthlike.chunk("top", 0, 3, 4, 1)
    try:
        import pyvista  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pip install"):
            m.to_pyvista()
        return
    poly = m.to_pyvista()
    assert poly.n_points == m.vertex_count and poly.n_cells == m.triangle_count
