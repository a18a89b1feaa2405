"""Does the PST step scale over the CPU's threads like an elastic step? Rates and a cost breakdown.

Two scenes, each at one and two threads, both through ``mw.run`` with the kernels compiled first:
``pst_demo`` (76,705 particles) over its first 0.25 s (settling, then the saw cutting) and the 2D
elastic block of the throughput benchmark at the same size (``n_grid`` 288: 82,944 particles) over
0.25 s. The rates are the median of ``--repeats`` runs, taken in turns (block, PST, block, ...), so that a
change in the machine's speed hits both alike. Then the breakdown: ``Stepper.profile`` over 200 steps
of each scene (the PST while the saw cuts, after settling), per stage and thread: the serial launches
(step size, walls, saw and monitors, column means, clock), P2G, the grid update and G2P, with each
stage's wall time beside each thread's own work. At two threads, last, an interleaved A/B of the step's
meeting point against ``threading.Barrier`` in the same stepper (8 batches of 100 steps each). Writes
``benchmarks/perf/results/pst_scaling_cpu.json``; the runs of one label (``--label``, default
``current``) replace that label's entry only, so a ``before`` run at an older commit stays beside.

Usage::

    python benchmarks/perf/pst_scaling.py [--label after] [--repeats 3] [--quick]
"""

from __future__ import annotations

import os
import statistics
import sys
import time

import mpm_warp as mw
from mpm_warp.finite_json import load_json
from mpm_warp.scenes import attach
from mpm_warp.studies.blocks import block_scenario
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
WINDOW_S = 0.25      # s: simulated time of each timed run
BLOCK_N_GRID = 288   # the elastic block's cells per axis: 82,944 particles, pst_demo's 76,705 within 8 %
PROFILE_STEPS = 200


def scenes(quick: bool) -> dict:
    """The two scenes: name -> (scenario, the time its profile starts at (s))."""
    pst = mw.load_scenario("pst_demo", ["output.fields=[]"] + (["scene.length=0.8"] if quick else []))
    block = block_scenario(96 if quick else BLOCK_N_GRID, dim=2)
    return {"pst_demo": (pst, pst.scene.saw_start + 0.02), "elastic_block": (block, 0.005)}


def rates(scs: dict, threads: int, window: float, repeats: int) -> dict:
    """Median particle-steps per wall second of each scene through ``mw.run`` (compiled by a short run first)."""
    runs = {name: [] for name in scs}
    for sc, _ in scs.values():
        mw.run(sc, device="cpu", n_threads=threads, end_time=0.002)
    for _ in range(repeats):
        for name, (sc, _) in scs.items():
            r = mw.run(sc, device="cpu", n_threads=threads, end_time=window)
            runs[name].append({"steps": r.steps, "wall_s": r.wall_time, "particle_steps_per_s": r.particle_steps_per_s,
                               "particles": r.n_particles})
    return {name: {"particles": rs[0]["particles"], "steps": rs[0]["steps"],
                   "particle_steps_per_s": statistics.median(x["particle_steps_per_s"] for x in rs), "runs": rs}
            for name, rs in runs.items()}


def breakdown(sc, t_start: float, threads: int, steps: int) -> dict:
    """``Stepper.profile`` of ``steps`` steps from ``t_start`` (s), in seconds per step."""
    sim = mw.Simulation(sc, device="cpu", n_threads=threads)
    attach(sim)
    sim.step_to(t_start)
    sim.stepper.set_frame_end(1e9)
    prof = sim.stepper.profile if hasattr(sim.stepper, "profile") else lambda n: _pool_rounds(sim.stepper, n)
    prof(5)   # the first steps after the frame end moved
    out = prof(steps)
    out["particles"] = sim.model.n_particles
    out["grid_nodes"] = int(sim.stepper.grid_m.size)
    return out


def meeting_ab(sc, t_start: float, rounds: int = 8, steps: int = 100) -> dict:
    """Interleaved A/B at two threads: the step's ``MeetingPoint`` against ``threading.Barrier`` (swapped in the
    same stepper, same state), ``rounds`` batches of ``steps`` steps each in alternating order; medians (s)."""
    import threading

    sim = mw.Simulation(sc, device="cpu", n_threads=2)
    attach(sim)
    sim.step_to(t_start)
    st = sim.stepper
    st.set_frame_end(1e9)
    kinds = {"meeting_point": st._barrier, "threading_barrier": threading.Barrier(st.n_threads)}
    times = {k: [] for k in kinds}
    for r in range(rounds):
        for name in (list(kinds) if r % 2 == 0 else list(kinds)[::-1]):
            st._barrier = kinds[name]
            t0 = time.perf_counter()
            st.steps(steps)
            times[name].append((time.perf_counter() - t0) / steps)
    st._barrier = kinds["meeting_point"]
    med = {k: statistics.median(v) for k, v in times.items()}
    return {"s_per_step": med, "times": times, "meeting_over_barrier": med["meeting_point"] / med["threading_barrier"]}


def _pool_rounds(st, n: int) -> dict:
    """The same breakdown for the stepper before its threads met at a barrier (three pool rounds a step: the
    ``before`` entry, at commit bc28d92)."""
    nt = st.n_threads
    busy = {s: [0.0] * nt for s in ("p2g", "grid", "g2p")}
    walls = {s: 0.0 for s in busy}
    serial = 0.0
    stages = {"p2g": st._scatter, "grid": lambda k: st._grid[k].launch(), "g2p": lambda k: st._g2p[k].launch()}
    t_all = time.perf_counter()
    for _ in range(n):
        t0 = time.perf_counter()
        st._begin.launch()
        if st._wall_state is not None:
            st._wall_state.launch()
        for launch in [*st.actions, *st._closure]:
            launch.launch()
        serial += time.perf_counter() - t0
        for name, run in stages.items():
            def timed(k, run=run):
                a = time.perf_counter()
                run(k)
                return time.perf_counter() - a
            t0 = time.perf_counter()
            took = [timed(0)] if st._pool is None else list(st._pool.map(timed, range(nt)))
            walls[name] += time.perf_counter() - t0
            for k, b in enumerate(took):
                busy[name][k] += b
        t0 = time.perf_counter()
        for launch in [*st._columns, st._end]:
            launch.launch()
        serial += time.perf_counter() - t0
    out = {"threads": nt, "steps": n, "total": (time.perf_counter() - t_all) / n, "serial": serial / n}
    for s in walls:
        out[s] = {"wall": walls[s] / n, "busy": [b / n for b in busy[s]]}
    return out


def _has_meeting_point() -> bool:
    try:
        import mpm_warp.meeting  # noqa: F401  (the step's threads meet there since commit b319260)
    except ImportError:
        return False
    return True


def main(argv=None) -> int:
    ap = parser(__doc__, "a 0.8 m PST and a 96^2 block over 0.02 s, one repeat")
    ap.add_argument("--label", default="current", help="name of this run's entry (e.g. before, after)")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs of each scene and thread count")
    a = ap.parse_args(argv)
    window, repeats = (0.02, 1) if a.quick else (WINDOW_S, a.repeats)
    scs = scenes(a.quick)
    entry = {"environment": environment("cpu"), "window_s": window, "repeats": repeats, "threads": {}}
    t0 = time.perf_counter()
    for nt in (1, 2):
        row = {"rates": rates(scs, nt, window, repeats)}
        row["pst_over_block"] = (row["rates"]["pst_demo"]["particle_steps_per_s"]
                                 / row["rates"]["elastic_block"]["particle_steps_per_s"])
        row["breakdown"] = {name: breakdown(sc, ts, nt, 20 if a.quick else PROFILE_STEPS)
                            for name, (sc, ts) in scs.items()}
        if nt == 2 and _has_meeting_point():
            row["meeting_ab"] = {name: meeting_ab(sc, ts, 2 if a.quick else 8, 20 if a.quick else 100)
                                 for name, (sc, ts) in scs.items()}
        entry["threads"][str(nt)] = row
        print(f"{nt} thread(s): PST {row['rates']['pst_demo']['particle_steps_per_s'] / 1e6:.2f}, block "
              f"{row['rates']['elastic_block']['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s, "
              f"PST/block {row['pst_over_block']:.3f}", flush=True)
    entry["seconds"] = time.perf_counter() - t0
    entry["environment"]["load_average_at_end_1_5_15_min"] = list(os.getloadavg())
    folder = out_dir(a, RESULTS, "pst_scaling")
    name = result_name("pst_scaling", a)
    path = os.path.join(folder, name + ".json")
    data = {"benchmark": __doc__.splitlines()[0], "runs": {}}
    if os.path.exists(path):
        with open(path) as fh:
            data = load_json(fh)
    data["runs"][a.label] = entry
    print(write_json(name, data, folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
