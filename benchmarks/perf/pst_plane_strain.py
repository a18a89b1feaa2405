"""Cost of a plane-strain PST per simulated second: true 2D against the quasi-2D slab.

The same PST (``pst_demo``'s physics at its dx of 7.5 mm, on a shorter column) runs in true 2D
(``scene.plane_strain = "2d"``) and as the quasi-2D slab (``"slab"``: 3D, one cell thick in z between slip
walls, which each 2D particle layer equals to round-off, tests/test_pst_plane_strain.py). Each settles
(untimed; the kernels compile then), is snapshotted, and the window after settling (the saw cutting) is
run ``--repeats`` times from that snapshot. Reported per mode: particles, steps in the window, wall and
process CPU seconds per simulated second (median), particle-steps per CPU second; and the slab/2D ratios.
One thread each (``MPM_WARP_THREADS=1``), so both get one core; on a shared machine the CPU time is the
figure to compare (wall time also counts the other users' load). Writes
``benchmarks/perf/results/pst_plane_strain_cpu.json``.

Usage::

    MPM_WARP_THREADS=1 .venv/bin/python benchmarks/perf/pst_plane_strain.py [--quick]
"""

from __future__ import annotations

import os
import statistics
import sys
import time

os.environ.setdefault("MPM_WARP_THREADS", "1")

import mpm_warp as mw  # noqa: E402  (after the thread count is set)
from mpm_warp.scenes import attach  # noqa: E402
from mpm_warp.studies.environment import environment, write_json  # noqa: E402
from mpm_warp.studies.protocol import out_dir, parser, result_name  # noqa: E402

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def measure(mode: str, overrides: list[str], window: float, repeats: int, device: str) -> dict:
    """Settle one PST in ``mode``, then time ``repeats`` runs of the ``window`` (s) after settling."""
    sc = mw.load_scenario("pst_demo", overrides + [f"scene.plane_strain='{mode}'"])
    sim = mw.Simulation(sc, device=device, n_threads=1)
    attach(sim)
    t_settled = sc.scene.saw_start
    t0 = time.perf_counter()
    sim.step_to(t_settled)
    settle_wall = time.perf_counter() - t0
    snap = sim.snapshot()
    steps0 = sim.stepper.clock()[2]
    wall, cpu, steps = [], [], []
    for _ in range(repeats):
        sim.load_snapshot(*snap)
        w0, c0 = time.perf_counter(), time.process_time()
        sim.step_to(t_settled + window)
        steps.append(sim.stepper.clock()[2] - steps0)  # a synchronisation: the window's steps are done
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    n = sim.model.n_particles
    cpu_med = statistics.median(cpu)
    return {"mode": mode, "dimension": sc.domain.dimension, "particles": n, "steps": steps[0],
            "steps_all": steps, "settle_wall_s": settle_wall, "window_wall_s": wall, "window_cpu_s": cpu,
            "wall_s_per_simulated_s": statistics.median(wall) / window,
            "cpu_s_per_simulated_s": cpu_med / window,
            "particle_steps_per_cpu_s": n * steps[0] / cpu_med}


def main(argv=None) -> int:
    ap = parser(__doc__, "a 0.8 m column, settled for 0.05 s, a 0.01 s window, one repeat")
    ap.add_argument("--length", type=float, default=1.2, help="column length (m)")
    ap.add_argument("--window", type=float, default=0.05, help="timed window after settling (s)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--settle", type=float, default=0.1, help="settling duration (s); the ramp is half of it")
    ap.add_argument("--name", default=None, help="result file name (default pst_plane_strain_<cpu|cuda>)")
    a = ap.parse_args(argv)
    if a.quick:
        a.length, a.settle, a.window, a.repeats = 0.8, 0.05, 0.01, 1
    name = a.name or result_name("pst_plane_strain", a)
    overrides = [f"scene.length={a.length}", f"scene.settle.duration={a.settle}",
                 f"scene.settle.gravity_ramp={0.5 * a.settle}", f"scene.saw.cut_length={min(0.6, a.length / 2)}",
                 f"time.end={a.settle + a.window}", "output.fields=[]"]
    env = environment(a.device)
    res = {}
    for mode in ("2d", "slab"):
        res[mode] = measure(mode, overrides, a.window, a.repeats, a.device)
        print({k: v for k, v in res[mode].items()}, flush=True)
    ratio = {k: res["slab"][k] / res["2d"][k] for k in ("wall_s_per_simulated_s", "cpu_s_per_simulated_s")}
    ratio["particle_steps_per_cpu_s_2d_over_slab"] = (res["2d"]["particle_steps_per_cpu_s"]
                                                      / res["slab"]["particle_steps_per_cpu_s"])
    print("slab / 2D:", ratio)
    path = write_json(name, {
        "what": "pst_demo physics (dx 7.5 mm, 2 particles per cell and axis, float32) on a shorter column; cost "
                "of the window after settling (the saw cutting), true 2D against the quasi-2D slab, one thread",
        "scene_overrides": overrides, "window_s": a.window, "repeats": a.repeats, "threads": 1,
        "modes": res, "slab_over_2d": ratio, "environment": env}, out_dir(a, RESULTS, "pst_plane_strain"))
    print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
