"""Shared pieces of the benchmarks: the elastic block scene, timing, environment record."""

from __future__ import annotations

import datetime
import json
import os
import platform
import statistics
import time

import numpy as np
import warp as wp

import mpm_warp

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def block_scenario(n_grid: int, material=None, boundary: str = "slip", precision: str = "float32",
                   dt: float = 1e-4, dim: int = 3) -> mpm_warp.Scenario:
    """The throughput scene shared with ``taichi_mpm.py``.

    Unit box (square in 2D) with slip faces three cells in from the grid edge,
    block ``[0.25, 0.75]^dim`` with 2 particles per cell and axis
    (``n_grid^dim`` particles), Hencky elastic E = 1e5 Pa, nu = 0.3,
    rho = 1000 kg/m^3, gravity along -y, fixed dt = 1e-4 s. ``dim = 2`` is
    plane strain (per metre of depth).
    """
    dx = 1.0 / n_grid
    mat = material or mpm_warp.Elastic(1e5, 0.3, 1000.0)
    return mpm_warp.Scenario(
        name=f"block{n_grid}_{dim}d",
        domain=mpm_warp.Domain((3 * dx,) * dim, (1 - 3 * dx,) * dim, dx, boundary=boundary, dimension=dim),
        time=mpm_warp.TimeControl(end=1.0, frame_interval=1.0, dt=dt),
        materials={"m": mat},
        blocks=(mpm_warp.Block("m", (0.25,) * dim, (0.75,) * dim),),
        precision=precision,
    )


def time_steps(sim: mpm_warp.Simulation, steps: int, repeats: int = 3, warmup: int = 3) -> list[float]:
    """Seconds per step of ``repeats`` timed batches of ``steps`` steps (kernels compiled beforehand)."""
    st = sim.stepper
    st.set_frame_end(1e9)
    st.steps(warmup)
    wp.synchronize_device(sim.device)
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        st.steps(steps)
        wp.synchronize_device(sim.device)
        out.append((time.perf_counter() - t0) / steps)
    return out


def clock_for(device: str):
    """The timer of a benchmark on ``device``: process CPU time on the CPU, wall time on CUDA.

    The development CPU's two cores are shared with other work; a one-thread
    launch's CPU time is its own work, while its wall time grows with the
    other users' load. On CUDA the host only waits, so wall time it is.
    """
    return time.perf_counter if wp.get_device(device).is_cuda else time.process_time


def stage_times(sim: mpm_warp.Simulation, steps: int = 10) -> dict[str, float]:
    """Median seconds per step of each stage, launched one stage at a time (one thread; CPU time on the CPU)."""
    st = sim.stepper
    st.set_frame_end(1e9)
    acc = {"p2g": [], "grid_update": [], "g2p": []}
    dev = sim.device
    clock = clock_for(dev)
    for _ in range(steps):
        st._begin.launch()
        if getattr(st, "_wall_state", None) is not None:
            st._wall_state.launch()
        wp.synchronize_device(dev)
        t0 = clock()
        for k in range(st.n_threads):
            st._scatter(k)
        wp.synchronize_device(dev)
        t1 = clock()
        for g in st._grid:
            g.launch()
        wp.synchronize_device(dev)
        t2 = clock()
        for g in st._g2p:
            g.launch()
        wp.synchronize_device(dev)
        t3 = clock()
        st._end.launch()
        acc["p2g"].append(t1 - t0)
        acc["grid_update"].append(t2 - t1)
        acc["g2p"].append(t3 - t2)
    return {k: statistics.median(v) for k, v in acc.items()}


def environment(device: str) -> dict:
    """Device, versions and date of a benchmark run."""
    import h5py

    dev = wp.get_device(device) if device else None
    env = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "device": device,
        "device_name": dev.name if dev is not None else "",
        "cuda_driver": _version_str(wp.get_cuda_driver_version()) if dev is not None and dev.is_cuda else None,
        "cuda_toolkit": _version_str(wp.get_cuda_toolkit_version()) if dev is not None and dev.is_cuda else None,
        "load_average_1_5_15_min": list(os.getloadavg()),
        "git_commit": _git_commit(),
        "cpu": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "mpm_warp": mpm_warp.__version__,
        "warp": wp.config.version,
        "numpy": np.__version__,
        "h5py": h5py.__version__,
    }
    try:
        import importlib.metadata as md

        env["taichi"] = md.version("taichi")
    except Exception:  # noqa: BLE001 - optional
        env["taichi"] = None
    return env


def _git_commit() -> str | None:
    """The checkout's commit (with ``+dirty`` when it has uncommitted changes), None outside git."""
    import subprocess

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    try:
        head = subprocess.run(["git", "-C", root, "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", root, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")


def _version_str(v) -> str | None:
    return ".".join(str(p) for p in v) if v else None


def write_json(name: str, data: dict, results_dir: str | None = None) -> str:
    """Write ``<results_dir or benchmarks/results>/<name>.json``; return its path.

    When ``data`` has an ``environment`` the load average at writing time is
    added beside the one at the start (how busy the shared machine was).
    """
    if isinstance(data.get("environment"), dict):
        data["environment"]["load_average_at_end_1_5_15_min"] = list(os.getloadavg())
    results_dir = results_dir or RESULTS
    os.makedirs(results_dir, exist_ok=True)
    path = os.path.join(results_dir, name + ".json")
    with open(path, "w") as fh:
        json.dump(data, fh, indent=1, default=float)
        fh.write("\n")
    return path


def dask_map(fn, items: list, workers: int | None = None, scheduler: str | None = None) -> list:
    """``[fn(*item) for item in items]`` as Dask tasks, one per item, in item order.

    On ``scheduler`` (the address of a running Dask scheduler) or on a local cluster of ``workers`` processes
    (default: one per core, at most one per item) with one thread each; every worker's step runs on one CPU
    thread (``MPM_WARP_THREADS=1``), so the processes do not compete for the cores.
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
