"""Throughput of the elastic MLS-MPM step beside Taichi, per size, thread count and stage.

Usage: ``python benchmarks/throughput.py [--device cpu|cuda] [--sizes 24 32 48 64] [--steps 50]``.
Writes ``benchmarks/results/throughput_<device>.json``. Kernels are compiled
before timing; each figure is the median of three batches; Taichi runs the same
scene (``taichi_peer.py``) in the same benchmark run, each configuration in
its own process, and the ratios compare the two.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
from common import block_scenario, environment, stage_times, time_steps, write_json  # noqa: E402
from taichi_peer import run_taichi_block_subprocess  # noqa: E402

import mpm_warp  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--sizes", type=int, nargs="+", default=[24, 32, 48, 64])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--no-taichi", action="store_true")
    a = ap.parse_args(argv)
    cores = os.cpu_count() or 1
    cuda = a.device.startswith("cuda")
    thread_counts = [1] if cuda else sorted({1, cores})
    rows = []
    for n in a.sizes:
        for nt in thread_counts:
            sim = mpm_warp.Simulation(block_scenario(n), device=a.device, n_threads=nt)
            ts = time_steps(sim, a.steps)
            med = statistics.median(ts)
            N = sim.model.n_particles
            row = {"n_grid": n, "n_particles": N, "threads": sim.stepper.n_threads, "engine": "mpm_warp",
                   "s_per_step": med, "particle_steps_per_s": N / med, "times_s_per_step": ts,
                   "bytes_per_particle": sim.model.bytes_per_particle(sim.state),
                   "grid_bytes_per_particle": (sim.stepper.grid_m_all.capacity + sim.stepper.grid_p_all.capacity) / N,
                   "com_y": float(sim.state.x.numpy()[:, 1].astype(np.float64).mean())}
            if nt == 1:
                row["stages_s"] = stage_times(sim)
            rows.append(row)
            print(f"warp   n_grid {n:3d} N {N:7d} threads {row['threads']}: {N / med / 1e6:6.2f} M particle-steps/s",
                  flush=True)
            if not a.no_taichi:
                arch = "cuda" if cuda else "cpu"
                res, err = run_taichi_block_subprocess(n, steps=a.steps + 3, arch=arch,
                                                       cpu_max_num_threads=None if cuda else nt)
                if res is None:
                    rows.append({"n_grid": n, "threads": nt, "engine": "taichi", "error": err})
                    print(f"taichi n_grid {n}: unavailable ({err})", flush=True)
                    continue
                res = dict(res, engine="taichi", threads=nt)
                rows.append(res)
                row["taichi_particle_steps_per_s"] = res["particle_steps_per_s"]
                row["ratio_vs_taichi"] = row["particle_steps_per_s"] / res["particle_steps_per_s"]
                print(f"taichi n_grid {n:3d} N {res['n_particles']:7d} threads {nt}: "
                      f"{res['particle_steps_per_s'] / 1e6:6.2f} M/s  -> warp/taichi {row['ratio_vs_taichi']:.2f}",
                      flush=True)
    out = {"benchmark": "elastic block throughput (MLS-MPM, Hencky StVK, float32, dt 1e-4, 50 steps)",
           "environment": environment(a.device), "rows": rows}
    path = write_json(f"throughput_{'cuda' if cuda else 'cpu'}", out)
    print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
