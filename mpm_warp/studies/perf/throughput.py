"""The block throughput beside Taichi: sizes to grids, one configuration's rows, and a run over many.

``benchmarks/perf/throughput.py`` (its command line and figure) and the device suite's throughput part
(``benchmarks/perf/device_suite.py``) run :func:`run`; both engines follow the protocol of :mod:`.warp_block`
and :mod:`.taichi_peer` (Taichi in its own process per configuration).
"""

from __future__ import annotations

import time

from .. import plastic_block as pb
from ..environment import environment, write_json
from .taichi_peer import run_taichi_block_subprocess
from .warp_block import run_block

#: Smallest elastic grid: the block [0.25, 0.75] must lie inside the slip walls three cells in from the box edge.
MIN_N_GRID_ELASTIC = 16


def n_grid_for(particles: float, dim: int, material: str = "elastic") -> int:
    """Even cells per axis with ``n_grid**dim`` closest to ``particles``, at least the scene's minimum.

    Parameters
    ----------
    particles : float
        Approximate particle count (the block has ``n_grid**dim`` particles: 2 per cell and axis in a unit box).
    dim : {2, 3}
    material : {"elastic", "plastic"}
        The minimum: :data:`MIN_N_GRID_ELASTIC`, or ``plastic_block.MIN_N_GRID`` for the struck Cam-Clay block.

    Examples
    --------
    >>> n_grid_for(4096, 3), n_grid_for(4096, 2), n_grid_for(1000, 3)
    (16, 64, 16)
    """
    n = 2 * round(float(particles) ** (1.0 / dim) / 2.0)
    return max(n, pb.MIN_N_GRID if material == "plastic" else MIN_N_GRID_ELASTIC)


def measure(dim: int, material: str, n_grid: int, steps: int, device: str, threads: int | None,
            taichi: bool, repeats: int = 3, taichi_timeout_s: float = 600.0) -> list[dict]:
    """Rows of one configuration: mpm_warp, Taichi (or why it is missing), and the ratio.

    Parameters
    ----------
    dim, material, n_grid
        The block (:func:`.warp_block.run_block`).
    steps, repeats : int
        Timed steps per repeat and repeats (the median is reported).
    device : str
        Warp device; Taichi runs on ``cuda`` for a CUDA device, else on the CPU.
    threads : int or None
        CPU threads of both engines (None: all).
    taichi : bool
        Whether to run the Taichi peer too.
    taichi_timeout_s : float
        Wall-clock limit of the Taichi child, seconds.

    Returns
    -------
    list of dict
        The mpm_warp row (with ``ratio_vs_taichi`` and, on the CPU, ``ratio_vs_taichi_cpu_time`` when Taichi ran)
        and the Taichi row or ``{"engine": "taichi", ..., "error": reason}``.
    """
    cuda = device.startswith("cuda")
    w = run_block(dim, material, n_grid, steps, device=device, n_threads=threads, repeats=repeats,
                  stages=(threads == 1 and not cuda), diagnostics=(material == "plastic"))
    print(f"mpm_warp {dim}D {material:7s} N {w['n_particles']:9d} threads {w['threads']}: "
          f"{w['particle_steps_per_s'] / 1e6:8.2f} M particle-steps/s", flush=True)
    rows = [w]
    if not taichi:
        return rows
    arch = "cuda" if cuda else "cpu"
    res, err = run_taichi_block_subprocess(n_grid, steps, arch=arch, cpu_max_num_threads=None if cuda else threads,
                                           repeats=repeats, dim=dim, material=material, warmup=w.get("warmup"),
                                           diagnostics=(material == "plastic"), timeout_s=taichi_timeout_s)
    if res is None:
        rows.append({"engine": "taichi", "dim": dim, "material": material, "n_grid": n_grid, "threads": threads,
                     "error": err})
        print(f"taichi   {dim}D {material:7s} N {n_grid**dim:9d}: unavailable ({err})", flush=True)
        return rows
    rows.append(res)
    w["taichi_particle_steps_per_s"] = res["particle_steps_per_s"]
    w["ratio_vs_taichi"] = w["particle_steps_per_s"] / res["particle_steps_per_s"]
    if not cuda:  # on a shared CPU: particle-steps per second of process CPU time, robust to other users' load
        for r in (w, res):
            r["particle_steps_per_cpu_s"] = r["particle_steps_per_s"] / r["cpu_utilisation"]
        w["ratio_vs_taichi_cpu_time"] = w["particle_steps_per_cpu_s"] / res["particle_steps_per_cpu_s"]
    msg = f"  -> mpm_warp/taichi {w['ratio_vs_taichi']:.2f}"
    if material == "plastic" and "observables" in res:
        w["agreement_with_taichi"] = pb.agreement(w["observables"], res["observables"])
        msg += f"; observables agree: {w['agreement_with_taichi']['agree']}"
    print(f"taichi   {dim}D {material:7s} N {res['n_particles']:9d} threads {res['threads']}: "
          f"{res['particle_steps_per_s'] / 1e6:8.2f} M particle-steps/s{msg}", flush=True)
    return rows


def run(dims, materials, particles, steps: int, device: str, threads_list, taichi: bool, name: str,
        repeats: int = 3, *, results_dir: str, taichi_timeout_s: float = 600.0, size_major: bool = False,
        env: dict | None = None) -> dict:
    """Measure every configuration, rewriting ``<results_dir>/<name>.json`` after each; return the result dict.

    Configurations run dimension by dimension, material by material, size by
    size; ``size_major`` puts the size loop outermost instead (all small runs
    first, as a time-boxed run wants). ``seconds`` holds the wall time of each (s).

    Parameters
    ----------
    dims, materials : list
        Dimensions (2, 3) and materials ("elastic", "plastic").
    particles : list of float
        Approximate particle counts (:func:`n_grid_for`).
    steps, repeats : int
        Timed steps per repeat, repeats.
    device : str
        Warp device.
    threads_list : list of int or None
        CPU thread counts, each a configuration of its own.
    taichi : bool
        Whether to run the Taichi peer beside each.
    name, results_dir : str
        The JSON's name (without ``.json``) and folder.
    taichi_timeout_s : float
        Wall-clock limit of each Taichi child, seconds.
    env : dict or None
        The result's environment record (default: :func:`~mpm_warp.studies.environment.environment` of ``device``,
        taken now).
    """
    out = {"benchmark": "MLS-MPM block throughput beside Taichi (float32; elastic: Hencky StVK block in free fall, "
                        "plastic: struck Cam-Clay snow block of mpm_warp.studies.plastic_block)",
           "environment": environment(device) if env is None else env, "steps": steps, "repeats": repeats,
           "rows": [], "seconds": {}}
    configs = [(dim, material, N) for dim in dims for material in materials for N in particles]
    if size_major:
        configs.sort(key=lambda c: particles.index(c[2]))  # stable: dims and materials keep their order
    for dim, material, N in configs:
        n = n_grid_for(N, dim, material)
        for nt in threads_list:
            t0 = time.perf_counter()
            out["rows"] += measure(dim, material, n, steps, device, nt, taichi, repeats, taichi_timeout_s)
            out["seconds"][f"{dim}d_{material}_{n}_{nt}"] = time.perf_counter() - t0
            write_json(name, out, results_dir)
    return out
