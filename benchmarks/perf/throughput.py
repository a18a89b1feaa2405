"""Throughput of the MLS-MPM step beside Taichi, by dimension, material, size and thread count.

Usage::

    python benchmarks/perf/throughput.py [--device cpu|cuda:0] [--dims 3 2] [--materials elastic plastic]
                                    [--particles 13824 32768 110592 262144] [--steps 50] [--threads 1 2]

``--particles`` are approximate counts: each becomes the even ``n_grid`` with
``n_grid**dim`` closest to it (2 particles per cell and axis in a unit box).
The elastic block is ``common.block_scenario`` (E = 1e5 Pa, rho = 1000, dt =
1e-4 s, free fall); the plastic block is the struck Cam-Clay snow of
``plastic_block.py``. Both engines follow the protocol of ``warp_block`` /
``taichi_peer`` (compiled, warmed up, median of three repeats from one
snapshot; Taichi in its own process per configuration). On the CPU each row
also has ``cpu_utilisation`` and ``particle_steps_per_cpu_s`` (per second of
process CPU time): on a machine whose cores are shared with other work the
wall-clock rates move with that load, the CPU-time rates much less. 2D is plane strain
(``[domain] dimension = 2`` in mpm_warp). Writes ``benchmarks/perf/results/<name>.json`` (default
``throughput_<device>``) after every configuration, so a run stopped early
keeps what it measured.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # siblings, and benchmarks/common.py
RESULTS = os.path.join(HERE, "results")

import plastic_block as pb  # noqa: E402
import warp_block  # noqa: E402
from common import environment, write_json  # noqa: E402
from taichi_peer import run_taichi_block_subprocess  # noqa: E402

DEFAULT_PARTICLES = [13824, 32768, 110592, 262144]


#: Smallest elastic grid: the block [0.25, 0.75] must lie inside the slip walls three cells in from the box edge.
MIN_N_GRID_ELASTIC = 16


def n_grid_for(particles: float, dim: int, material: str = "elastic") -> int:
    """Even cells per axis with ``n_grid**dim`` closest to ``particles``, at least the scene's minimum."""
    n = 2 * round(float(particles) ** (1.0 / dim) / 2.0)
    return max(n, pb.MIN_N_GRID if material == "plastic" else MIN_N_GRID_ELASTIC)


def measure(dim: int, material: str, n_grid: int, steps: int, device: str, threads: int | None,
            taichi: bool, repeats: int = 3, taichi_timeout_s: float = 600.0) -> list[dict]:
    """Rows of one configuration: mpm_warp, Taichi (or why it is missing), and the ratio."""
    cuda = device.startswith("cuda")
    w = warp_block.run_block(dim, material, n_grid, steps, device=device, n_threads=threads, repeats=repeats,
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
        repeats: int = 3, results_dir: str | None = None, taichi_timeout_s: float = 600.0,
        size_major: bool = False) -> dict:
    """Measure every configuration, rewriting the JSON after each; return the result dict.

    Configurations run dimension by dimension, material by material, size by
    size; ``size_major`` puts the size loop outermost instead (all small runs
    first, as a time-boxed run wants). ``seconds`` holds the time of each.
    """
    out = {"benchmark": "MLS-MPM block throughput beside Taichi (float32; elastic: Hencky StVK block in free fall, "
                        "plastic: struck Cam-Clay snow block of plastic_block.py)",
           "environment": environment(device), "steps": steps, "repeats": repeats, "rows": [], "seconds": {}}
    configs = [(dim, material, N) for dim in dims for material in materials for N in particles]
    if size_major:
        configs.sort(key=lambda c: particles.index(c[2]))  # stable: dims and materials keep their order
    for dim, material, N in configs:
        n = n_grid_for(N, dim, material)
        for nt in threads_list:
            t0 = time.perf_counter()
            out["rows"] += measure(dim, material, n, steps, device, nt, taichi, repeats, taichi_timeout_s)
            out["seconds"][f"{dim}d_{material}_{n}_{nt}"] = time.perf_counter() - t0
            write_json(name, out, results_dir or RESULTS)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--dims", type=int, nargs="+", default=[3, 2], choices=(2, 3))
    ap.add_argument("--materials", nargs="+", default=["elastic", "plastic"], choices=("elastic", "plastic"))
    ap.add_argument("--particles", type=float, nargs="+", default=DEFAULT_PARTICLES)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=None,
                    help="CPU thread counts (default 1 and all cores; CUDA: one launch stream)")
    ap.add_argument("--no-taichi", action="store_true")
    ap.add_argument("--name", default=None, help="result file name (default throughput_<cpu|cuda>)")
    a = ap.parse_args(argv)
    cuda = a.device.startswith("cuda")
    threads = [1] if cuda else (a.threads or sorted({1, os.cpu_count() or 1}))
    name = a.name or f"throughput_{'cuda' if cuda else 'cpu'}"
    run(a.dims, a.materials, a.particles, a.steps, a.device, threads, not a.no_taichi, name, a.repeats)
    print("wrote", name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
