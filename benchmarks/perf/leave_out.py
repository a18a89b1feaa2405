"""What a scene does not need costs nothing: plasticity, walls, fields.

Times the same 110k-particle block (n_grid 48, one CPU thread by default) as
(a) elastic without walls, (b) elastic with the six box walls, (c) Cam-Clay
that stays inside its yield surface (the return is compiled in but only the
yield check runs), (d) Cam-Clay whose every particle yields every step, and
reports device bytes per particle of each. Writes
``benchmarks/perf/results/leave_out_<device>.json``.

Usage: ``python benchmarks/perf/leave_out.py [--n-grid 48] [--steps 30] [--threads 1] [--quick]``.
"""

from __future__ import annotations

import os
import statistics
import sys

from mpm_warp import CamClaySnow, Simulation
from mpm_warp.studies.blocks import block_scenario
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.timing import time_steps

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def main(argv=None) -> int:
    ap = parser(__doc__, "n_grid 24 (14k particles), 5 steps")
    ap.add_argument("--n-grid", type=int, default=48)
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args(argv)
    if a.quick:
        a.n_grid, a.steps = 24, 5
    E, nu, rho = 1e5, 0.3, 1000.0
    strong = CamClaySnow(E, nu, rho, M=1.2, beta=0.3, xi=1.0, p0_ini=1e5)  # never reaches yield
    # no consolidation and no cohesion to speak of: gravity loading yields every particle every step
    weak = CamClaySnow(E, nu, rho, M=1.2, beta=0.0, xi=1e-3, p0_ini=0.0)
    cases = {
        "elastic_no_walls": block_scenario(a.n_grid, boundary="none"),
        "elastic_box_walls": block_scenario(a.n_grid, boundary="slip"),
        "camclay_elastic_range_box_walls": block_scenario(a.n_grid, material=strong, boundary="slip"),
        "camclay_yielding_box_walls": block_scenario(a.n_grid, material=weak, boundary="slip"),
    }
    rows = {}
    for name, sc in cases.items():
        sim = Simulation(sc, device=a.device, n_threads=a.threads)
        ts = time_steps(sim, a.steps)
        med = statistics.median(ts)
        N = sim.model.n_particles
        yielded = None
        if sim.state.log_jp is not None:
            yielded = float((sim.state.log_jp.numpy() != sim.model.groups[0].material.initial_log_jp).mean())
        rows[name] = {"n_particles": N, "s_per_step": med, "particle_steps_per_s": N / med, "times": ts,
                      "bytes_per_particle": sim.model.bytes_per_particle(sim.state),
                      "walls": len(sim.model.walls), "plastic": sim.model.has_plastic,
                      "fraction_with_plastic_history": yielded}
        print(f"{name:34s} {N / med / 1e6:6.2f} M particle-steps/s  {rows[name]['bytes_per_particle']:.1f} B/particle"
              + (f"  yielded {yielded:.2f}" if yielded is not None else ""), flush=True)
    base = rows["elastic_no_walls"]["s_per_step"]
    for r in rows.values():
        r["time_vs_elastic_no_walls"] = r["s_per_step"] / base
    out = {"benchmark": "cost of walls and plasticity on the same block", "n_grid": a.n_grid, "threads": a.threads,
           "environment": environment(a.device), "cases": rows}
    name = result_name("leave_out", a)
    print("wrote", write_json(name, out, out_dir(a, RESULTS, "leave_out")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
