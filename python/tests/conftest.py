"""Shared fixtures of the Python package's tests: the `pmc` binary the bakes are compared with,
and one local Dask cluster of two worker processes for every distributed bake."""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _pmc_bin() -> pathlib.Path:
    given = os.environ.get("PMC_BIN")
    candidates = [pathlib.Path(given)] if given else [ROOT / "target" / "debug" / "pmc", ROOT / "target" / "release" / "pmc"]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    raise RuntimeError(
        f"no pmc binary at {', '.join(map(str, candidates))}: build it (cargo build --release -p pmc-cli) or set PMC_BIN"
    )


@pytest.fixture(scope="session")
def pmc_bin() -> pathlib.Path:
    """The `pmc` command line (PMC_BIN, else the workspace's build)."""
    return _pmc_bin()


@pytest.fixture(scope="session")
def dask_client():
    """A LocalCluster of 2 worker processes (one thread each), shared by the bake tests."""
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()
