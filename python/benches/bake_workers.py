"""The distributed bake's speed: tiles per second with 1 and 2 Dask workers on this machine,
beside `pmc tiles bake` (every core, one process) on the same region. Figures for
docs/BENCHMARKS.md ("The distributed bake").

    python python/benches/bake_workers.py [--pmc target/release/pmc] [--region 39,0,60000] [--max-level 12]
"""

import argparse
import os
import pathlib
import shutil
import subprocess
import tempfile
import time

import pmc
import pmc.bake


def count(folder: pathlib.Path):
    files = [p for p in folder.rglob("*") if p.is_file()]
    return sum(1 for p in files if p.suffix == ".glb"), sum(p.stat().st_size for p in files)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pmc", default="target/release/pmc")
    ap.add_argument("--region", default="39,0,60000")
    ap.add_argument("--max-level", type=int, default=12)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    region = [float(v) for v in a.region.split(",")]
    work = pathlib.Path(tempfile.mkdtemp(prefix="pmc-bake-bench-"))
    try:
        from dask.distributed import Client, LocalCluster

        rows = []
        for _ in range(a.repeat):
            out = work / "cli"
            t0 = time.perf_counter()
            subprocess.run([a.pmc, "tiles", "bake", "--quiet", "--preset", "earth", "--region", a.region, "--max-level", str(a.max_level), "-o", str(out)], check=True)
            secs = time.perf_counter() - t0
            tiles, size = count(out)
            rows.append(("pmc tiles bake (one process, every core)", tiles, size, secs))
            shutil.rmtree(out)
        for workers in (1, 2):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
            client = Client(cluster)
            for _ in range(a.repeat):
                out = work / f"dask{workers}"
                s = pmc.bake.tiles(pmc.Planet("earth", 7), str(out), region=region, max_level=a.max_level, client=client)
                tiles, size = count(out)
                rows.append((f"pmc.bake.tiles, {workers} worker{'s' if workers > 1 else ''}", tiles, size, s["seconds"]))
                shutil.rmtree(out)
            client.close()
            cluster.close()
        print(f"earth preset, region {a.region}, max level {a.max_level}, {os.cpu_count()} CPUs")
        for name, tiles, size, secs in rows:
            print(f"{name:45s} {tiles:6d} tiles {size / 1e6:7.1f} MB {secs:7.2f} s {tiles / secs:7.0f} tiles/s")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
