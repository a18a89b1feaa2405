"""The plastic step beside Taichi: the struck Cam-Clay block (``mpm_warp.studies.plastic_block``) in both engines.

Usage: ``python benchmarks/perf/plastic_step.py [--n-grid 32 48 64] [--n-grid-2d 128 256 512] [--steps 50]
[--threads 1] [--device cpu] [--quick]``.
Writes ``benchmarks/perf/results/plastic_step_<device>.json``.

For every size both engines run the same scene with the same protocol
(``mpm_warp.studies.perf``: ``warp_block`` / ``taichi_peer``; compiled, warmed up to yield, median of
``--repeats`` repeats of ``--steps`` steps from one snapshot; Taichi in its own
process). Each row records:

* particle-steps/s of both and their ratio, by wall clock and per second of
  process CPU time (robust when other work shares the cores);
* the return kinds of every timed step in both engines (fraction yielding, cap
  and dry-side returns), checked against ``mpm_warp.studies.plastic_block.check_return_kinds``;
* the observables after the same steps (mean p, mean q, mean log_Jp, mean
  |log_Jp - log_Jp(0)|) and whether they agree within ``mpm_warp.studies.plastic_block.AGREEMENT``;
* where the time goes: mpm_warp per stage (one thread), its step with
  plasticity compiled out (an elastic material of the same E, nu, rho on the
  same state), and its constitutive update and the update's parts alone on
  the step's trial states (``update_cost``, as ``return_cost.py``: small-strain check, principal
  strains, return, and a decomposition-free prototype checked against the
  engine); Taichi's step with the return compiled out (SVD kept).
"""

from __future__ import annotations

import os
import statistics
import sys

from mpm_warp.studies import plastic_block as pb
from mpm_warp.studies.blocks import block_simulation
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.perf.taichi_peer import run_taichi_block_subprocess
from mpm_warp.studies.perf.update_cost import update_cost
from mpm_warp.studies.perf.warp_block import run_block
from mpm_warp.studies.protocol import out_dir, parser, result_name

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def compare_size(dim: int, n_grid: int, steps: int, threads: int, device: str, repeats: int, taichi: bool) -> dict:
    """One size: mpm_warp and Taichi rows, ratio, agreement and where the time goes."""
    w = run_block(dim, "plastic", n_grid, steps, device=device, n_threads=threads, repeats=repeats,
                  stages=True, diagnostics=True, return_share=True)
    sim = block_simulation(dim, "plastic", n_grid, device, n_threads=1)
    sim.stepper.set_frame_end(1e9)
    sim.stepper.steps(w["warmup"])
    cost = update_cost(sim)
    w["update_parts_s_per_step"] = cost
    step = w["s_per_step"] if device.startswith("cuda") else w["cpu_s_per_step"]  # same clock as update_cost
    for part in ("update", "principal_path_update", "series_check", "principal", "return"):
        w[f"{part}_share"] = cost[f"{part}_s"] / step
    out = {"dim": dim, "n_grid": n_grid, "n_particles": w["n_particles"], "threads": threads, "mpm_warp": w}
    print(f"mpm_warp {dim}D N {w['n_particles']:7d} threads {w['threads']}: {w['particle_steps_per_s'] / 1e6:6.3f} "
          f"M particle-steps/s; plasticity {w['plasticity_share']:.2f} of the step; alone: update "
          f"{w['update_share']:.2f} (with the eigen-decomposition {w['principal_path_update_share']:.2f}), "
          f"series check {w['series_check_share']:.2f}, eigen {w['principal_share']:.2f}, return "
          f"{w['return_share']:.2f}; min yielded {min(k['yielded'] for k in w['return_kinds']):.3f}", flush=True)
    if not taichi:
        return out
    arch = "cuda" if device.startswith("cuda") else "cpu"
    t, err = run_taichi_block_subprocess(n_grid, steps, arch=arch, cpu_max_num_threads=None if arch == "cuda"
                                         else threads, repeats=repeats, dim=dim, material="plastic",
                                         warmup=w["warmup"], diagnostics=True, return_share=True)
    if t is None:
        out["taichi"] = {"error": err}
        print("taichi unavailable:", err, flush=True)
        return out
    out["taichi"] = t
    out["ratio_vs_taichi"] = w["particle_steps_per_s"] / t["particle_steps_per_s"]
    if arch == "cpu":  # on a shared CPU: per second of process CPU time, robust to other users' load
        for r in (w, t):
            r["particle_steps_per_cpu_s"] = r["particle_steps_per_s"] / r["cpu_utilisation"]
        out["ratio_vs_taichi_cpu_time"] = w["particle_steps_per_cpu_s"] / t["particle_steps_per_cpu_s"]
    out["agreement"] = pb.agreement(w["observables"], t["observables"])
    print(f"taichi   {dim}D N {t['n_particles']:7d} threads {t['threads']}: {t['particle_steps_per_s'] / 1e6:6.3f} "
          f"M particle-steps/s ({t['p2g_scatter']}); return share {t['return_share']:.2f} -> warp/taichi "
          f"{out['ratio_vs_taichi']:.2f} (per CPU second {out.get('ratio_vs_taichi_cpu_time', float('nan')):.2f}); "
          f"observables agree: {out['agreement']['agree']}", flush=True)
    return out


def main(argv=None) -> int:
    ap = parser(__doc__, "3D at 24 cells and 2D at 48, 5 steps, one repeat")
    ap.add_argument("--n-grid", type=int, nargs="+", default=[32, 48, 64], help="3D sizes (cells per axis)")
    ap.add_argument("--n-grid-2d", type=int, nargs="*", default=[128, 256, 512], help="2D (plane strain) sizes")
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-taichi", action="store_true")
    ap.add_argument("--name", default=None, help="result file name (default plastic_step_<device>)")
    a = ap.parse_args(argv)
    if a.quick:
        a.n_grid, a.n_grid_2d, a.steps, a.repeats = [24], [48], 5, 1
    env = environment(a.device)
    sizes = [(3, n) for n in a.n_grid] + [(2, n) for n in a.n_grid_2d]
    rows = [compare_size(d, n, a.steps, a.threads, a.device, a.repeats, not a.no_taichi) for d, n in sizes]
    ratios = {d: [r["ratio_vs_taichi"] for r in rows if r["dim"] == d and "ratio_vs_taichi" in r] for d in (3, 2)}
    cpu_ratios = {d: [r["ratio_vs_taichi_cpu_time"] for r in rows if r["dim"] == d and "ratio_vs_taichi_cpu_time" in r]
                  for d in (3, 2)}
    out = {"benchmark": "plastic step beside Taichi: struck Cam-Clay snow block (mpm_warp.studies.plastic_block), "
                        "3D and 2D (plane strain), float32",
           "scene": {"material": {"E": pb.YOUNG_E, "nu": pb.POISSON_NU, "density": pb.DENSITY, "M": pb.M_CSL,
                                  "beta": pb.BETA, "xi": pb.XI, "p0_ini": pb.P0_INI},
                     "impact_speed": pb.IMPACT_SPEED, "strain_rate": pb.strain_rate(), "cfl": pb.CFL},
           "environment": env, "steps": a.steps, "repeats": a.repeats, "rows": rows,
           "median_ratio_vs_taichi": {f"{d}d": statistics.median(v) for d, v in ratios.items() if v},
           "median_ratio_vs_taichi_cpu_time": {f"{d}d": statistics.median(v) for d, v in cpu_ratios.items() if v}}
    name = a.name or result_name("plastic_step", a)
    print("wrote", write_json(name, out, out_dir(a, RESULTS, "plastic_step")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
