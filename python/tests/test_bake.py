"""The distributed bake: the same bytes as `pmc tiles bake`, on a LocalCluster of 2 worker
processes, through a worker's death, resumed, and failing clearly on bad input."""

import hashlib
import os
import pathlib
import signal
import subprocess
import sys

import pytest

import pmc
import pmc.bake

# A region of the Earth at true scale: 486 tiles in about 40 subtrees.
REGION = (39.0, 0.0, 20000.0)
MAX_LEVEL = 11


def tree(folder: pathlib.Path) -> dict:
    """Every file under `folder` by relative path, with its digest."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            out[p.relative_to(folder).as_posix()] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


@pytest.fixture(scope="module")
def reference(pmc_bin, tmp_path_factory) -> dict:
    """The region baked by `pmc tiles bake` in one process."""
    out = tmp_path_factory.mktemp("cli") / "tiles"
    region = ",".join(str(v) for v in REGION)
    cmd = [str(pmc_bin), "tiles", "bake", "--quiet", "--preset", "earth", "--seed", "7", "--region", region, "--max-level", str(MAX_LEVEL), "-o", str(out)]
    subprocess.run(cmd, check=True)
    files = tree(out)
    assert "tileset.json" in files and "bake.json" in files
    assert sum(1 for f in files if f.endswith(".glb")) > 100
    return files


def bake(out, client, **kw):
    return pmc.bake.tiles(pmc.Planet("earth", 7), str(out), region=REGION, max_level=MAX_LEVEL, client=client, **kw)


def test_two_workers_bake_the_same_bytes_as_the_command_line(reference, dask_client, tmp_path):
    stats = bake(tmp_path / "tiles", dask_client)
    assert tree(tmp_path / "tiles") == reference
    assert stats["tiles"] == sum(1 for f in reference if f.endswith(".glb"))
    assert stats["subtrees"] == sum(1 for f in reference if f.startswith("subtrees/"))
    assert stats["resumed"] == 0
    # Both workers took part: the work was spread by subtree.
    assert len(dask_client.scheduler_info()["workers"]) == 2


def test_an_fsspec_url_is_an_output_like_a_folder(reference, dask_client, tmp_path):
    bake(f"file://{tmp_path}/tiles", dask_client)
    assert tree(tmp_path / "tiles") == reference


def test_a_worker_killed_mid_bake_changes_no_byte(reference, dask_client, tmp_path):
    """SIGKILL of a worker process while it bakes a subtree: its task is baked again on the
    other worker (then the restarted one), and the folder is the same bytes."""
    import time

    killed = []

    def kill_a_busy_worker(stats):
        if killed:
            return
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            busy = [w for w, tasks in dask_client.processing().items() if any("pmc-subtree" in str(t) for t in tasks)]
            if busy:
                pid = dask_client.run(os.getpid, workers=busy[:1])[busy[0]]
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                return
            time.sleep(0.005)

    stats = bake(tmp_path / "tiles", dask_client, progress=kill_a_busy_worker)
    assert killed, "no worker was busy with a subtree after the first one"
    assert stats["tasks"] > 2
    assert tree(tmp_path / "tiles") == reference
    dask_client.wait_for_workers(2, timeout=60)


def test_an_interrupted_bake_resumes_to_the_same_bytes(reference, dask_client, tmp_path):
    out = tmp_path / "tiles"
    bake(out, dask_client)
    # As if killed before its end: the tileset and the deepest subtrees not written yet, a
    # temporary file left in .partial.
    (out / "tileset.json").unlink()
    deepest = sorted(out.glob("subtrees/*/*/*/*/*.json"), key=lambda p: -int(p.parts[-4]))[:5]
    for s in deepest:
        s.unlink()
    (out / ".partial").mkdir()
    (out / ".partial" / "0.tmp").write_bytes(b"half a tile")
    stats = bake(out, dask_client)
    assert stats["resumed"] > 0 and stats["subtrees"] >= len(deepest)
    assert tree(out) == reference


def test_bad_input_fails_the_bake_clearly_and_leaves_no_partial_file(dask_client, tmp_path):
    # An unknown preset: refused before anything is written.
    out = tmp_path / "a"
    with pytest.raises(pmc.PmcError, match="unknown preset"):
        pmc.bake.tiles("jupiter", str(out), client=dask_client)
    assert not out.exists()
    # An output that cannot be written (its parent is a file).
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(pmc.PmcError, match="cannot"):
        pmc.bake.tiles(pmc.Planet("moon", 3), str(blocker / "tiles"), max_level=1, client=dask_client)
    # A folder holding something else.
    other = tmp_path / "other"
    other.mkdir()
    (other / "mine.txt").write_text("keep me")
    with pytest.raises(pmc.PmcError, match="not empty"):
        pmc.bake.tiles(pmc.Planet("moon", 3), str(other), max_level=1, client=dask_client)
    assert [p.name for p in other.iterdir()] == ["mine.txt"]


def test_a_worker_without_the_elevation_file_fails_the_bake(dask_client, tmp_path):
    import numpy as np
    import pmc.dem

    lat = np.arange(89.5, -90, -1.0)
    lon = np.arange(-179.5, 180, 1.0)
    heights = (2000 * np.sin(np.radians(lon))[None, :] * np.cos(np.radians(lat))[:, None]).astype(np.float32)
    dem = tmp_path / "relief.pmcdem"
    pmc.dem.import_array(heights, dem, extent=(-180, -90, 180, 90))
    planet = pmc.Planet.from_dem(dem)
    dem.unlink()  # the client has the planet; the workers cannot open its file
    out = tmp_path / "tiles"
    with pytest.raises(pmc.PmcError, match="relief.pmcdem"):
        pmc.bake.tiles(planet, str(out), region=REGION, max_level=4, client=dask_client)
    assert not (out / ".partial").exists()
    assert not (out / "tileset.json").exists()


def test_workers_fetch_the_elevation_file_from_its_url(dask_client, tmp_path, pmc_bin):
    """The client's path is not the workers': they fetch the file from `dem_url` (any fsspec
    URL), checked by its digest, and bake the same bytes as `pmc tiles bake` on the file."""
    import shutil

    import numpy as np
    import pmc.dem

    lat = np.arange(89.5, -90, -1.0)
    lon = np.arange(-179.5, 180, 1.0)
    heights = (2000 * np.sin(np.radians(lon))[None, :] * np.cos(np.radians(lat))[:, None]).astype(np.float32)
    store = tmp_path / "store"
    store.mkdir()
    pmc.dem.import_array(heights, store / "relief.pmcdem", extent=(-180, -90, 180, 90))
    local = tmp_path / "local.pmcdem"
    shutil.copy(store / "relief.pmcdem", local)
    planet = pmc.Planet.from_dem(local)
    ref = tmp_path / "ref"
    subprocess.run([str(pmc_bin), "tiles", "bake", "--quiet", "--dem", str(local), "--region", "10,20,20000", "--max-level", "8", "-o", str(ref)], check=True)
    local.unlink()
    out = tmp_path / "tiles"
    pmc.bake.tiles(planet, str(out), region=(10.0, 20.0, 20000.0), max_level=8, client=dask_client, dem_url=f"file://{store}/relief.pmcdem")
    assert tree(out) == tree(ref)


def test_pmc_bake_console_script_on_a_scheduler(dask_client, pmc_bin, tmp_path):
    out = tmp_path / "cli"
    # The console script the package installs beside the interpreter.
    script = [os.path.join(os.path.dirname(sys.executable), "pmc-bake")]
    run = subprocess.run(
        script + ["--scheduler", dask_client.scheduler.address, "--preset", "moon", "--seed", "3", "--n-c", "8", "--n-t", "16", "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert "baked" in run.stdout
    ref = tmp_path / "ref"
    subprocess.run([str(pmc_bin), "tiles", "bake", "--quiet", "--preset", "moon", "--seed", "3", "--n-c", "8", "--n-t", "16", "-o", str(ref)], check=True)
    assert tree(out) == tree(ref)
    bad = subprocess.run(script + ["--scheduler", dask_client.scheduler.address, "--region", "1,2", "-o", str(tmp_path / "x")], capture_output=True, text=True)
    assert bad.returncode == 1 and "--region" in bad.stderr
    nobody = subprocess.run(script + ["--scheduler", "tcp://127.0.0.1:9", "--timeout", "2", "-o", str(tmp_path / "y")], capture_output=True, text=True, timeout=120)
    assert nobody.returncode == 1 and "no Dask scheduler answers" in nobody.stderr, nobody.stderr


def test_a_bakes_units_are_checked():
    from pmc import _pmc

    tiles = _pmc.TileBake(pmc.Planet("moon", 3)._native, max_level=3)
    roots = tiles.roots()
    assert len(roots) == 6 and all(r[1] == 0 for r in roots)
    files, children = tiles.subtree(roots[0])
    assert files[-1][0] == tiles.subtree_path(roots[0]) and files[-1][1] is None
    assert all(path.startswith("content/") and level is not None for path, level, _ in files[:-1])
    assert children == tiles.children(roots[0])
    with pytest.raises(pmc.PmcError, match="cube face"):
        tiles.subtree((9, 0, 0, 0, 0))
    with pytest.raises(pmc.PmcError, match="no subtree root"):
        tiles.subtree((0, 1, 0, 0, 0))
    with pytest.raises(pmc.PmcError, match="not a tile of this bake"):
        tiles.children((0, 3, 1000, 0, 0))
    with pytest.raises(pmc.PmcError, match="frame"):
        _pmc.TileBake(pmc.Planet("moon", 3)._native, frame="mercator")
    with pytest.raises(pmc.PmcError, match="max-level"):
        _pmc.TileBake(pmc.Planet("moon", 3)._native, max_level=40)
