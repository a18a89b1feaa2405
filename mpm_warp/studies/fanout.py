"""Independent cases of a study as Dask tasks, on a local cluster or a running scheduler."""

from __future__ import annotations

import os

__all__ = ["dask_map"]


def dask_map(fn, items: list, workers: int | None = None, scheduler: str | None = None) -> list:
    """``[fn(*item) for item in items]`` as Dask tasks, one per item, in item order.

    On ``scheduler`` (the address of a running Dask scheduler) or on a local cluster of ``workers`` processes
    (default: one per core, at most one per item) with one thread each; every worker's step runs on one CPU
    thread (``MPM_WARP_THREADS=1``), so the processes do not compete for the cores. ``fn`` must be importable
    by the workers (a module-level function).
    """
    from dask.distributed import Client, LocalCluster

    os.environ["MPM_WARP_THREADS"] = "1"
    n = max(1, min(workers or os.cpu_count() or 1, len(items)))
    cluster = None if scheduler else LocalCluster(n_workers=n, threads_per_worker=1, dashboard_address=None)
    try:
        with Client(scheduler or cluster) as client:
            return client.gather([client.submit(fn, *item, pure=False) for item in items])
    finally:
        if cluster is not None:
            cluster.close()
