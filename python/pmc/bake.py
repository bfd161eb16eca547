"""Planets bigger than one machine: 3D Tiles baked on a Dask cluster.

:func:`tiles` writes the same OGC 3D Tiles 1.1 tileset as ``pmc tiles bake``, byte for byte,
with the work split into tasks by subtree (three tile levels, up to 73 tiles; a task also bakes
the small subtrees at the bottom of the tree below its own) and run on a ``dask.distributed``
cluster: a ``LocalCluster`` on a laptop, or a cluster's scheduler. Workers
receive only the planet's spec (a preset and seed; an elevation file's path or URL and digest; a
world file) and build the planet themselves, never meshes from the client. Every file is written
whole or not at all, the bake resumes where a killed one stopped, and a worker lost mid-bake has
its subtrees baked again elsewhere.

The console script ``pmc-bake`` is the same from a shell (``pmc-bake --help``).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
import uuid
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

from . import _pmc
from . import Planet, PmcError

__all__ = ["tiles", "main"]

Root = Tuple[int, int, int, int, int]

#: How many times a subtree's task is submitted again after its worker was lost or restarted.
RETRIES = 5

#: Tile levels in a subtree file (`pmc_tiles::SUBTREE_LEVELS`).
SUBTREE_LEVELS = 3

# Per process (a worker's, or the client's): the tile sets built, by spec and options.
_TILE_SETS: Dict[str, Any] = {}


def _key(spec: Dict[str, Any], options: Dict[str, Any]) -> str:
    return json.dumps([spec, options], sort_keys=True)


def _fs(out: str) -> Tuple[Any, str]:
    """The fsspec filesystem of ``out`` and the path on it."""
    try:
        import fsspec
    except ImportError as e:
        raise ImportError("the distributed bake needs fsspec and dask: pip install pmc[bake]") from e
    fs, path = fsspec.core.url_to_fs(out)
    return fs, path.rstrip("/")


def _is_local(fs: Any) -> bool:
    protocol = fs.protocol if isinstance(fs.protocol, str) else fs.protocol[0]
    return protocol in ("file", "local")


def _fetch_dem(url: str, digest: str) -> str:
    """A local copy of the elevation file at ``url`` (any fsspec URL), kept by its digest."""
    cache = os.path.join(tempfile.gettempdir(), "pmc-dem-cache")
    os.makedirs(cache, exist_ok=True)
    local = os.path.join(cache, f"{digest}.pmcdem")
    if not os.path.exists(local):
        fs, path = _fs(url)
        tmp = f"{local}.{uuid.uuid4().hex}.tmp"
        try:
            with fs.open(path, "rb") as src, open(tmp, "wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
            os.replace(tmp, local)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
    return local


def _planet(spec: Dict[str, Any]) -> Planet:
    """The planet of ``spec``, with an elevation file given by URL fetched first."""
    url = spec.get("dem_url")
    if url:
        kind, interpolation, seed, digest, _path = spec["terrain"].split(":", 4)
        spec = dict(spec, terrain=":".join([kind, interpolation, seed, digest, _fetch_dem(url, digest)]))
    return Planet.from_spec(spec)


def _tile_set(spec: Dict[str, Any], options: Dict[str, Any], planet: Optional[Planet] = None) -> Any:
    key = _key(spec, options)
    found = _TILE_SETS.get(key)
    if found is None:
        planet = planet if planet is not None else _planet(spec)
        found = _pmc.TileBake(planet._native, **options)
        _TILE_SETS[key] = found
    return found


def _write(fs: Any, root: str, rel: str, data: bytes) -> None:
    """Writes ``data`` to ``root/rel`` whole or not at all: on a local disk through
    ``.partial/`` and a rename; object stores write an object at once."""
    final = f"{root}/{rel}"
    if _is_local(fs):
        tmp = os.path.join(root, ".partial", f"{uuid.uuid4().hex}.tmp")
        with open(tmp, "wb") as f:
            f.write(data)
        try:
            os.replace(tmp, final)
        except FileNotFoundError:
            # Its folder is new (made only now: most files go to a folder made before).
            os.makedirs(os.path.dirname(final), exist_ok=True)
            os.replace(tmp, final)
    else:
        fs.pipe_file(final, data)


def _bake_subtree(spec: Dict[str, Any], options: Dict[str, Any], root: Root, out: str) -> Dict[str, Any]:
    """One task: bakes the subtree at ``root`` into ``out``, and with it the subtrees below it
    that have none below them (the bottom of the tree: many small subtrees, baked here side by
    side on every core rather than as tasks of their own). Subtrees whose file is there are
    skipped (a resumed bake). Says what it wrote and which subtrees below are left to bake."""
    tiles = _tile_set(spec, options)
    fs, path = _fs(out)
    result: Dict[str, Any] = {"root": root, "children": [], "subtrees": 0, "resumed": 0, "levels": [], "subtree_bytes": 0}

    def written(files: List[Tuple[str, Optional[int], bytes]]) -> None:
        for rel, level, data in files:
            _write(fs, path, rel, data)
            if level is None:
                result["subtree_bytes"] += len(data)
            else:
                result["levels"].append((level, len(data)))
        result["subtrees"] += 1

    def baked(r: Root) -> bool:
        return fs.exists(f"{path}/{tiles.subtree_path(r)}")

    leaves: List[Root] = []

    def below(children: List[Root]) -> None:
        for c in children:
            if c[1] + SUBTREE_LEVELS >= tiles.levels:
                leaves.append(c)
            else:
                result["children"].append(c)

    if baked(root):
        result["resumed"] += 1
        below(tiles.children(root))
    else:
        files, children = tiles.subtree(root)
        written(files)
        below(children)
    todo = []
    for leaf in leaves:
        if baked(leaf):
            result["resumed"] += 1
        else:
            todo.append(leaf)
    # A few at a time, as `pmc tiles bake` does: every core busy, memory bounded.
    batch = _pmc.bake_batch()
    for i in range(0, len(todo), batch):
        for files, _ in tiles.subtrees(todo[i : i + batch]):
            written(files)
    return result


def _prepare(fs: Any, path: str, out: str, manifest: bytes) -> None:
    """Checks the folder (empty, or a bake of the same tileset to resume), empties
    ``.partial/`` and writes ``bake.json``: as ``pmc tiles bake`` does."""
    try:
        fs.makedirs(path, exist_ok=True)
    except OSError as e:
        raise PmcError(f"{out}: the output folder cannot be created: {e}") from e
    if not fs.isdir(path):
        raise PmcError(f"{out}: the output is not a folder")
    bake_json = f"{path}/bake.json"
    if fs.exists(bake_json):
        try:
            found = json.loads(fs.cat_file(bake_json))
        except ValueError:
            found = None
        if found != json.loads(manifest):
            raise PmcError(
                f"{out} holds a bake of another tileset ({bake_json}); bake into an empty folder, or remove it first"
            )
    else:
        names = [n.rstrip("/").rsplit("/", 1)[-1] for n in fs.ls(path, detail=False)]
        if any(n != ".partial" for n in names):
            raise PmcError(f"{out} is not empty and holds no bake.json; bake into an empty folder")
    if _is_local(fs):
        partial = os.path.join(path, ".partial")
        shutil.rmtree(partial, ignore_errors=True)
        try:
            os.makedirs(partial)
        except OSError as e:
            raise PmcError(f"{out}: the output folder cannot be written: {e}") from e
    try:
        _write(fs, path, "bake.json", manifest)
    except OSError as e:
        raise PmcError(f"{out}: the output folder cannot be written: {e}") from e


def _finish(fs: Any, path: str) -> None:
    if _is_local(fs):
        shutil.rmtree(os.path.join(path, ".partial"), ignore_errors=True)


def _spec_of(planet: Union[Planet, Dict[str, Any], str], dem_url: Optional[str]) -> Tuple[Dict[str, Any], Planet]:
    if isinstance(planet, Planet):
        spec, local = planet.spec, planet
    elif isinstance(planet, dict):
        spec = dict(planet)
        local = _planet(spec)
    elif isinstance(planet, str):
        local = Planet(preset=planet)
        spec = local.spec
    else:
        raise PmcError(f"planet is a pmc.Planet, a spec dict or a preset's name, got {type(planet).__name__}")
    if dem_url is not None:
        if not spec["terrain"].startswith("dem:"):
            raise PmcError("dem_url applies to a planet made from an elevation file")
        spec["dem_url"] = dem_url
    return spec, local


def tiles(
    planet: Union[Planet, Dict[str, Any], str],
    out: str = "tiles",
    *,
    max_level: Optional[int] = None,
    min_level: int = 0,
    region: Optional[Sequence[float]] = None,
    frame: str = "auto",
    client: Any = None,
    workers: int = 2,
    dem_url: Optional[str] = None,
    progress: Optional[Callable[[Dict[str, Any]], None]] = None,
) -> Dict[str, Any]:
    """Bakes ``planet`` into the 3D Tiles folder ``out`` on a Dask cluster.

    - ``planet``: a :class:`pmc.Planet` (its spec goes to the workers), a spec dict
      (``Planet.spec``), or a preset's name.
    - ``out``: a local folder or any fsspec URL (``s3://bucket/tiles``, ``gs://...``); created if
      missing; a bake of the same tileset found there is resumed, anything else refused.
    - ``max_level``, ``min_level``, ``region=(lat, lon, radius_m)`` and ``frame`` (``auto``,
      ``wgs84``, ``sphere``): as ``pmc tiles bake``'s options.
    - ``client``: a ``dask.distributed.Client``; without one, a ``LocalCluster`` of ``workers``
      processes is started for the bake and closed after it.
    - ``dem_url``: where workers fetch the planet's elevation file (checked by its digest), when
      its path on the client is not theirs.
    - ``progress``: called after each subtree with the running figures.

    A task bakes one subtree and, with it, the subtrees at the bottom of the tree below it (which
    have none below them). Returns the bake's figures: tiles, bytes, subtrees written and
    resumed, tasks, tiles per level, seconds, tiles per second. A task that fails (a worker without the elevation file, an
    unwritable output) fails the bake with the worker's message as :class:`pmc.PmcError`;
    files are only ever written whole.
    """
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as e:
        raise ImportError("the distributed bake needs dask.distributed: pip install pmc[bake]") from e
    start = time.perf_counter()
    spec, local = _spec_of(planet, dem_url)
    options = {
        "max_level": max_level,
        "min_level": int(min_level),
        "region": None if region is None else tuple(float(v) for v in region),
        "frame": frame,
    }
    tileset = _tile_set(spec, options, local)
    fs, path = _fs(out)
    _prepare(fs, path, out, tileset.manifest())

    own = client is None
    if own:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = Client(cluster)
    stats: Dict[str, Any] = {"tiles": 0, "bytes": 0, "subtrees": 0, "resumed": 0, "tasks": 0, "levels": {}, "subtree_bytes": 0}
    try:
        tries: Dict[Root, int] = {}
        root_of: Dict[str, Root] = {}

        def submit(root: Root) -> Any:
            tries[root] = tries.get(root, 0) + 1
            key = f"pmc-subtree-{root[0]}-{root[1]}-{root[2]}-{root[3]}-{root[4]}-{uuid.uuid4().hex[:8]}"
            root_of[key] = root
            return client.submit(_bake_subtree, spec, options, root, out, key=key, pure=False)

        done = as_completed([submit(tuple(r)) for r in tileset.roots()])
        for future in done:
            try:
                result = future.result()
            except Exception as e:  # the task's error, or the worker lost
                cancelled = type(e).__name__ in ("CancelledError", "KilledWorker", "FutureCancelledError")
                root = root_of[future.key]
                if cancelled and tries[root] <= RETRIES:
                    done.add(submit(root))
                    continue
                for f in list(done.futures):
                    f.cancel()
                raise PmcError(f"the bake failed on a worker: {e}") from e
            future.release()
            stats["tasks"] += 1
            for c in result["children"]:
                done.add(submit(tuple(c)))
            stats["resumed"] += result["resumed"]
            stats["subtrees"] += result["subtrees"]
            stats["subtree_bytes"] += result["subtree_bytes"]
            for level, n in result["levels"]:
                lv = stats["levels"].setdefault(level, [0, 0])
                lv[0] += 1
                lv[1] += n
                stats["tiles"] += 1
                stats["bytes"] += n
            if progress is not None:
                progress(dict(stats))
        _write(fs, path, "tileset.json", tileset.tileset())
    finally:
        _finish(fs, path)
        if own:
            client.close()
            cluster.close()
    stats["bytes"] += stats["subtree_bytes"]
    stats["seconds"] = time.perf_counter() - start
    stats["tiles_per_second"] = stats["tiles"] / max(stats["seconds"], 1e-9)
    stats["levels"] = {k: {"tiles": v[0], "bytes": v[1]} for k, v in sorted(stats["levels"].items())}
    return stats


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``pmc-bake``: a planet's 3D Tiles baked on a Dask cluster."""
    p = argparse.ArgumentParser(
        prog="pmc-bake",
        description="Bake a planet into a folder of 3D Tiles 1.1 (the same bytes as `pmc tiles bake`) on a Dask "
        "cluster: a local one, or the scheduler given. Resumable: run it again after an interrupt.",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler, e.g. tcp://HOST:8786 (default: a local cluster)")
    p.add_argument("--timeout", type=float, default=30, metavar="SECONDS", help="how long to wait for --scheduler (default 30)")
    p.add_argument("--workers", type=int, default=2, metavar="N", help="worker processes of the local cluster (default 2)")
    p.add_argument("--preset", default="earthlike", help="sphere, earthlike, moon, mars or earth (default earthlike)")
    p.add_argument("--seed", type=int, default=7, help="terrain seed (default 7)")
    p.add_argument("--dem", metavar="FILE.pmcdem", help="a real planet from an elevation file instead of a preset")
    p.add_argument("--dem-url", metavar="URL", help="where workers fetch --dem (any fsspec URL)")
    p.add_argument("--world", metavar="FILE", help="the planet of a world file, with its edits")
    for name, kind in (("n-c", int), ("n-t", int), ("d-b", float), ("l-d", float), ("d-c", int)):
        p.add_argument(f"--{name}", type=kind, metavar="V", help=f"layout parameter {name.replace('-', '_')}")
    p.add_argument("--radius", type=float, metavar="METRES", help="the preset's layout for this radius")
    p.add_argument("-o", "--output", default="tiles", metavar="DIR|URL", help="the folder or fsspec URL (default tiles)")
    p.add_argument("--max-level", type=int, metavar="L", help="the deepest tile level")
    p.add_argument("--min-level", type=int, default=0, metavar="L", help="tiles above this level have no content")
    p.add_argument("--region", metavar="LAT,LON,RADIUS_M", help="only the tiles near a place")
    p.add_argument("--frame", choices=["auto", "wgs84", "sphere"], default="auto")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    a = p.parse_args(argv)
    try:
        layout = {"n_c": a.n_c, "n_t": a.n_t, "d_b": a.d_b, "l_d": a.l_d, "d_c": a.d_c}
        if a.world:
            with Planet.open_world(a.world) as w:
                planet = w.planet
        elif a.dem:
            planet = Planet.from_dem(a.dem, a.seed, **layout)
        else:
            planet = Planet(a.preset, a.seed, radius=a.radius, **layout)
        region = None
        if a.region:
            try:
                region = [float(v) for v in a.region.split(",")]
            except ValueError:
                region = []
            if len(region) != 3:
                raise PmcError(f"--region is LAT,LON,RADIUS_M, got {a.region!r}")
        from dask.distributed import Client, LocalCluster

        cluster = None
        if a.scheduler:
            try:
                client = Client(a.scheduler, timeout=a.timeout)
            except (OSError, TimeoutError) as e:
                raise PmcError(f"no Dask scheduler answers at {a.scheduler}: {e}") from e
            where = f"scheduler {a.scheduler}"
        else:
            cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=":0")
            client = Client(cluster)
            where = f"a local cluster of {a.workers} workers"
        if not a.quiet:
            # The dashboard's progress and task stream show the subtrees being baked.
            print(f"pmc-bake: {where}, dashboard {client.dashboard_link}", file=sys.stderr)

        def say(s: Dict[str, Any]) -> None:
            if not a.quiet:
                print(
                    f"\r{s['subtrees'] + s['resumed']} subtrees, {s['tiles']} tiles, {s['bytes'] / 1e6:.1f} MB",
                    end="",
                    file=sys.stderr,
                )

        try:
            stats = tiles(
                planet,
                a.output,
                max_level=a.max_level,
                min_level=a.min_level,
                region=region,
                frame=a.frame,
                client=client,
                dem_url=a.dem_url,
                progress=say,
            )
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    except PmcError as e:
        print(f"\npmc-bake: error: {e}", file=sys.stderr)
        return 1
    if not a.quiet:
        print(
            f"\nbaked {stats['tiles']} tiles ({stats['bytes'] / 1e6:.1f} MB, {stats['subtrees']} subtrees"
            f"{', %d resumed' % stats['resumed'] if stats['resumed'] else ''}) into {a.output} in "
            f"{stats['seconds']:.1f} s, {stats['tiles_per_second']:.0f} tiles/s"
        )
    return 0


if __name__ == "__main__":
    # `python -m pmc.bake`: the tasks must come from the module `pmc.bake`, which workers import,
    # not from `__main__`, which they would receive pickled with its globals.
    from pmc.bake import main as _main

    sys.exit(_main())
