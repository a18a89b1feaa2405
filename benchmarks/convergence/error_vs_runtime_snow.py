"""Error against run time for the snow scenes: how fine must a PST and a shear test be.

Two ladders of grid spacings (halving; 2 particles per cell and axis and CFL factor 0.4 fixed), on
this machine's CPU in 2D (plane strain), float32:

- ``pst``: a flat PST of the production snow (``pst_flat``'s slab, layer and saw) on a 2.2 m column
  with a 0.3 m slab and a 6 cm weak layer, so that the coarsest level still has the minimum 3 cells
  across the layer: dx = 20, 10, 5, 2.5 mm = 3, 6, 12, 24 cells. Quantities: the critical cut
  (bisection on the saw's stop position, trial runs forked from one base run:
  :func:`mpm_warp.scenes.pst.critical_cut`, bracket [0.1, 0.7] m to 2 cm at every level; on a CPU the
  24-cell level's inside a narrowed bracket on that bracket's grid, ``--pst-bracket``), the mean damage-front
  speed from the base run's 0.7 m cut to the far end zone (1.2 m), the touchdown distance and the collapse
  height of the base run (outside the far end zone);
- ``shear``: the shear test of SI Note 2 (``shear_test``) at 3, 6, 12, 24 cells across its 3 cm
  layer. Quantities: peak, softening slip ``delta_s`` (to the bond's loss in the layer's interior, at least
  one layer thickness from the sample's ends) and ``delta_s_whole_layer`` (to the whole layer's, which waits
  for the traction-free ends), collapse at the end of the 8 mm push.

Per quantity: the error of each level against the finest, against a Richardson extrapolation of the
three finest where the observed order allows it (0.5 <= p <= 4, monotone), each level's wall time
(the stepping, kernels compiled), steps, particles and particle-steps per second; the wall time to
5 % and to 1 % error (log-log interpolation along the ladder, or "not reached"). One level is also run
in float64 (``--precision-level``) to say whether float32 limits a quantity.

``--field-level`` runs the ladder PST once more at the field protocol's resolution, off the halving ladder:
``mpm_warp.field.protocol.FieldProtocol.cells_across`` cells across the layer (4: dx 15 mm), the same
bisection and base run as every level. Its error is stated against the PST ladder's reference
(``field_level`` in the JSON); the field batch's cost check quotes it (docs/field.md).

The ladder PST, its levels and bisection grid are :mod:`mpm_warp.studies.snow`; the errors, orders
and times :mod:`mpm_warp.studies.convergence`.

Writes ``benchmarks/convergence/results/error_vs_runtime_snow.json`` after every level (a killed run keeps the
finished levels; a rerun skips them unless ``--redo``) and ``error_vs_runtime_snow.png`` (error
against wall time, log-log, one line per quantity).

Usage (hours on 2 CPU cores; the finest PST level dominates)::

    nohup .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py > ladder.log 2>&1 &
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --quick     # 3-cell shear test, to a temp folder
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --ladder shear --levels 0 1   # the two coarsest
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --ladder pst --levels 3 --device cuda:0  # GPU
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --ladder pst --levels 3 --base-only \
        --workdir runs/   # the 24-cell base run on the CPU, over several sessions (rerun to resume)
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --field-level   # the 4-cell PST (minutes)
    .venv/bin/python benchmarks/convergence/error_vs_runtime_snow.py --ladder pst --levels 3 \
        --pst-bracket 0.30625 0.34375 --workers 2 --threads 2
        # its critical cut, bisected where the coarser levels put it (one trial each side)

A level run on a GPU records its device and serves as a reference; the wall times to 5 % and 1 % are
this CPU's only.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument
from mpm_warp.finite_json import load_json
from mpm_warp.memory import estimate_memory
from mpm_warp.scenes.pst import critical_cut
from mpm_warp.studies.convergence import errors_against_reference, ladder_summary
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.studies.snow import (
    PST_BRACKET,
    PST_DX,
    SHEAR_CELLS,
    field_level_dx,
    grid_bracket,
    ladder_pst,
    merge_pst_parts,
    pst_part,
)

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
OUT = "error_vs_runtime_snow"
TARGETS = (0.05, 0.01)
QUANTITIES = {"pst": ("critical_cut", "speed", "touchdown", "collapse_height"),
              "shear": ("peak", "delta_s", "delta_s_whole_layer", "collapse")}


def pst_level(dx: float, precision: str, bracket: dict, device: str, workers: int = 1,
              n_threads: int | None = None) -> dict:
    """One PST level: critical cut by bisection, and the base run's speed, touchdown and collapse height."""
    sc = mw.load_scenario("pst_flat", ladder_pst(dx) + [f'precision="{precision}"'])
    t0 = time.perf_counter()
    res = critical_cut(sc, device=device, base_run_distance=sc.scene.length, base_free_run=0.5, **bracket,
                       workers=workers, n_threads=n_threads,
                       log=lambda s: print(f"  pst dx {dx}: {s}", flush=True))
    wall = time.perf_counter() - t0
    b = res.base
    steps = int(sum(t["steps"] for t in res.trials))          # the base run's and every trial's own
    n_particles = estimate_memory(sc, device).n_particles
    return {"dx": dx, "cells_across_layer": sc.scene.weak_layer_thickness / dx, "precision": precision,
            "critical_cut": res.value if res.bracketed else math.nan, "critical_cut_bracket": [res.lo, res.hi],
            "bracketed": res.bracketed, "note": res.note, "trials": res.trials,
            "speed": b.get("damage_speed_mean"), "speed_over": b.get("damage_speed_mean_over"),
            "touchdown": b.get("touchdown"), "collapse_height": b.get("collapse_height"),
            "wall_time_s": wall, "n_particles": n_particles, "steps": steps,
            "particle_steps_per_s": n_particles * steps / wall,
            "simulated_s": float(sum(t["t_end"] - t["t_start"] for t in res.trials)),
            "bisection": bracket}


def pst_cut_level(dx: float, precision: str, bracket: dict, device: str, workers: int,
                  n_threads: int | None) -> dict:
    """A PST level's critical cut searched inside a narrowed ``bracket`` (:func:`grid_bracket`).

    The base run saws to the bracket's top only, so its speed, touchdown and collapse height are not the
    ladder's (those come from the level's 0.7 m base run, :func:`pst_base_level`): only the critical cut,
    its trials and the search's wall time are returned.
    """
    sc = mw.load_scenario("pst_flat", ladder_pst(dx) + [f'precision="{precision}"'])
    t0 = time.perf_counter()
    res = critical_cut(sc, device=device, **bracket, workers=workers, n_threads=n_threads,
                       log=lambda s: print(f"  pst dx {dx}: {s}", flush=True))
    wall = time.perf_counter() - t0
    steps = int(sum(t["steps"] for t in res.trials))
    n_particles = estimate_memory(sc, device).n_particles
    return {"dx": dx, "cells_across_layer": sc.scene.weak_layer_thickness / dx, "precision": precision,
            "critical_cut": res.value if res.bracketed else math.nan, "critical_cut_bracket": [res.lo, res.hi],
            "bracketed": res.bracketed, "critical_cut_note": res.note, "trials": res.trials,
            "critical_cut_wall_s": wall, "critical_cut_steps": steps,
            "bisection": {**bracket, "narrowed_from": dict(PST_BRACKET), "workers": workers, "n_threads": n_threads},
            "speed": math.nan, "speed_over": [math.nan, math.nan], "touchdown": math.nan, "collapse_height": math.nan,
            "wall_time_s": wall, "n_particles": n_particles, "steps": steps,
            "particle_steps_per_s": n_particles * steps / wall, "part": "critical_cut",
            "note": "critical cut only (narrowed bracket); the level's base run is a separate --base-only run"}


def pst_base_level(dx: float, precision: str, device: str, workdir: str) -> dict | None:
    """One PST level's base run alone (speed, touchdown, collapse height; no critical cut), resumable.

    The run the critical-cut search starts with (cut at the bracket's top, frames every 0.01 s, stopped
    once the damage front is in the far end zone or 0.5 s after the saw stopped), as a run file with a
    checkpoint every frame in ``workdir``: a call after a kill, or in a later session, resumes it
    (:func:`mpm_warp.resume`). For a level that takes hours on this CPU (the 24-cell PST: about 8 h).
    Returns the level's record once the run is done, None when it stopped early (the sessions' wall
    times and steps add up in ``<run>.sessions.json``).
    """
    from mpm_warp.scenes.pst.analysis import end_zone

    cut = PST_BRACKET["hi"]
    sc = mw.load_scenario("pst_flat", ladder_pst(dx) + [f'precision="{precision}"',
                                                   f"scene.saw.cut_length={cut!r}", "output.checkpoint_every=1",
                                                   "time.frame_interval=0.01"])
    p = sc.scene
    goal = p.length - end_zone(p)                 # base_run_distance = length: into the end zone
    t_saw_end = p.saw_start + cut / p.saw.speed
    t_stop = t_saw_end + 0.5
    os.makedirs(workdir, exist_ok=True)
    path = os.path.join(workdir, f"pst_dx{dx:g}_{precision}.h5")
    log_path = path[:-3] + ".sessions.json"
    sessions = json.load(open(log_path)) if os.path.isfile(log_path) else []
    # a session's record is rewritten at every frame (after its checkpoint): a killed session keeps the wall
    # time and steps up to its last checkpoint, and the work it lost after that is redone and counted once
    now = {}

    def started(sim):
        now.update(t0=time.perf_counter(), steps_from=sim.stepper.clock()[2])
        # the code of each session: a resume in a later session runs the code of its day (the same physics;
        # rounding may differ, so the level is one run only where every session ran one commit)
        sessions.append({"wall_time_s": 0.0, "steps": 0, "t_end": sim.time, "done": False, "t_start": sim.time,
                         "git_commit": environment(device).get("git_commit")})

    def running(sim, frame):                      # False stops the run: the front reached the end zone
        # as the critical-cut search's base run: the saw reaches the cut first, the front is checked from the
        # first frame after it (a crack that outruns the saw does not end the run early: the collapse height is
        # that of the run's last frame)
        front_in = sim.time >= t_saw_end + 0.01 - 1e-9 and sim.monitors["pst"].damage_front(sim.time) >= goal
        sessions[-1].update(wall_time_s=time.perf_counter() - now["t0"], t_end=sim.time,
                            steps=sim.stepper.clock()[2] - now["steps_from"],
                            done=bool(front_in or sim.time >= t_stop - 1e-9))
        if sessions[-1]["done"]:
            sessions[-1]["result"] = {k: v for k, v in sim.monitors["pst"].result().items()
                                      if k in ("damage_speed_mean", "damage_speed_mean_over", "touchdown",
                                               "collapse_height")}
        with open(log_path + ".tmp", "w") as fh:
            json.dump(sessions, fh, indent=1)
        os.replace(log_path + ".tmp", log_path)
        return not front_in

    if not (sessions and sessions[-1]["done"]):
        if os.path.isfile(path):
            mw.resume(path, device=device, end_time=t_stop, callback=running, on_start=started)
        else:
            mw.run(sc, output=path, device=device, end_time=t_stop, callback=running, on_start=started)
    last = sessions[-1]
    if not last["done"]:
        return None
    r = last["result"]
    wall = sum(x["wall_time_s"] for x in sessions)
    steps = sum(x["steps"] for x in sessions)
    n_particles = estimate_memory(sc, device).n_particles
    return {"dx": dx, "cells_across_layer": p.weak_layer_thickness / dx, "precision": precision,
            "critical_cut": math.nan, "critical_cut_bracket": [math.nan, math.nan], "bracketed": False,
            "note": "base run only (critical cut not bisected)", "trials": [],
            "speed": r["damage_speed_mean"], "speed_over": r["damage_speed_mean_over"], "touchdown": r["touchdown"],
            "collapse_height": r["collapse_height"], "wall_time_s": wall, "n_particles": n_particles,
            "steps": steps, "particle_steps_per_s": n_particles * steps / wall, "simulated_s": last["t_end"],
            "sessions": len(sessions), "run_file": path, "part": "base_run"}


def shear_level(cells: int, precision: str, device: str) -> dict:
    """One shear-test level: peak, softening slip, collapse."""
    sc = mw.load_scenario("shear_test")
    dx = sc.scene.weak_layer_thickness / cells
    rr = mw.run("shear_test", device=device, overrides=[f"scene.dx={dx!r}", f'precision="{precision}"'])
    r = rr.scene_result
    return {"dx": dx, "cells_across_layer": cells, "precision": precision, "peak": r["peak_shear_stress"],
            "delta_s": r["softening_displacement"], "delta_s_whole_layer": r["softening_displacement_whole_layer"],
            "collapse": r["collapse_fraction"],
            "wall_time_s": rr.wall_time, "steps": rr.steps, "n_particles": rr.n_particles,
            "particle_steps_per_s": rr.particle_steps_per_s}


def summarise(ladder: str, levels: list[dict]) -> dict:
    """Errors against the finest level and the Richardson value, orders, times to 5 % and 1 %, per quantity
    (float32 levels; :func:`mpm_warp.studies.convergence.ladder_summary`)."""
    return ladder_summary([lv for lv in levels if lv["precision"] == "float32"], QUANTITIES[ladder], TARGETS)


def figure(data: dict, path: str) -> None:
    import matplotlib.ticker

    plt = pyplot()

    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6))
    for ax, ladder in zip(axes, ("pst", "shear"), strict=True):
        lv = [x for x in data["ladders"].get(ladder, []) if x["precision"] == "float32"]
        summ = data["summary"].get(ladder, {})
        drawn = False
        for k, q in enumerate(QUANTITIES[ladder]):
            if q not in summ:
                continue
            use_r = summ[q]["reference_used_for_time_to"] == "richardson"
            e = summ[q]["error_vs_richardson"] if use_r else summ[q]["error_vs_finest"]
            pts = [(w["wall_time_s"], ee) for w, ee in zip(lv, e, strict=False)
                   if np.isfinite(ee) and ee > 0 and w.get("device", "cpu") == "cpu"]
            if pts:
                drawn = True
                # an error against the finest level falls towards it even when the quantity does not converge:
                # say so where the changes between levels grow
                ch = np.abs(np.diff([v for v in summ[q]["values"] if np.isfinite(v)]))
                grows = len(ch) >= 2 and bool(np.all(np.diff(ch) > 0))
                ax.loglog(*zip(*pts, strict=True), "o-", color=f"C{k}",
                          label=f"{q} (vs {'Richardson' if use_r else 'finest'})"
                                + (": changes grow, not converging" if grows else ""))
        for t in TARGETS:
            ax.axhline(t, color="0.6", ls=":", lw=1)
        ax.set(xlabel="wall time of the level [s] (CPU, 2D, float32)", ylabel="relative error",
               title=f"{ladder}: dx halving, " + ", ".join(f"{x['cells_across_layer']:.0f}" for x in lv)
                     + " cells across the layer")
        # levels without a value (e.g. a PST whose crack does not run) are said, not silently left out
        missing = [f"{x['cells_across_layer']:.0f} cells: {x['note']}" for x in lv if x.get("note") and not all(
            x.get(q) is not None and np.isfinite(x[q]) for q in QUANTITIES[ladder])]
        for q in QUANTITIES[ladder]:               # an error of 0 below the finest level has no place on a log axis
            e = summ.get(q, {}).get("error_vs_finest", [])
            same = [f"{lv[i]['cells_across_layer']:.0f}" for i in range(len(e) - 1) if e[i] == 0.0]
            if same and summ[q]["reference_used_for_time_to"] == "finest level":
                missing.append(f"{q}: {', '.join(same)} cells give the finest's value (error 0, not drawn)")
        if missing:
            ax.text(0.02, 0.02, "\n".join(missing), transform=ax.transAxes, fontsize=8, va="bottom")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        if drawn:
            ax.legend(fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    save_figure(fig, path)


def load(results: str, name: str = OUT) -> dict:
    path = os.path.join(results, name + ".json")
    if os.path.isfile(path):
        with open(path) as fh:
            return load_json(fh)
    return {"ladders": {"pst": [], "shear": []}, "summary": {}}


def main(argv=None) -> int:
    ap = parser(__doc__, "the shear ladder's coarsest level, 3 cells, float32")
    ap.add_argument("--ladder", choices=["pst", "shear", "both"], default="both")
    ap.add_argument("--levels", type=int, nargs="*", default=None, help="level indices (default all)")
    ap.add_argument("--precision-level", type=int, default=1, help="level also run in float64 (-1: none)")
    ap.add_argument("--redo", action="store_true", help="run levels the JSON already has")
    ap.add_argument("--base-only", action="store_true",
                    help="PST: the base run alone (no critical cut), checkpointed in --workdir and resumed by the "
                         "same command after a kill (for the 24-cell level: about 8 h on a 2-core CPU)")
    ap.add_argument("--workdir", default="error_vs_runtime_snow_runs", help="run files of --base-only")
    ap.add_argument("--pst-bracket", type=float, nargs=2, metavar=("LO", "HI"),
                    help="PST: the critical cut alone, bisected inside [LO, HI] m (points of the full bracket's "
                         "bisection grid), merged into the level's base-only record (for the 24-cell level on a CPU)")
    ap.add_argument("--workers", type=int, default=1, choices=(1, 2),
                    help="PST critical cut: 2 runs the trials of the bracket's bottom and first midpoint at once")
    ap.add_argument("--threads", type=int, default=None, help="CPU threads of each simulation")
    ap.add_argument("--field-level", action="store_true",
                    help="only the PST at the field protocol's cells across the layer (off the halving ladder), "
                         "its error against the PST ladder's reference")
    a = ap.parse_args(argv)
    if a.quick:
        a.ladder, a.levels, a.precision_level = "shear", [0], -1
    if a.pst_bracket:
        try:
            grid_bracket(*a.pst_bracket)
        except InvalidArgument as e:
            ap.error(f"--pst-bracket: {e}")
    a.results = out_dir(a, RESULTS, OUT)
    name = OUT + ("_quick" if a.quick else "")
    data = load(a.results, name)
    data["environment"] = environment(a.device)
    commit = data["environment"].get("git_commit")   # the code this process runs (it may change while it runs)
    if a.field_level:
        return run_field_level(a, name)
    ladders = ["shear", "pst"] if a.ladder == "both" else [a.ladder]
    for ladder in ladders:
        n = len(PST_DX if ladder == "pst" else SHEAR_CELLS)
        idx = list(range(n)) if a.levels is None else a.levels
        jobs = [(i, "float32") for i in idx]
        if a.precision_level >= 0 and (a.levels is None or a.precision_level in idx):
            jobs.append((a.precision_level, "float64"))
        have = data["ladders"].setdefault(ladder, [])
        for i, prec in jobs:
            done = [x for x in have if x.get("level") == i and x["precision"] == prec]
            want = "critical_cut" if ladder == "pst" and a.pst_bracket else "base_run" if ladder == "pst" and \
                a.base_only else "both"
            if done and not a.redo and pst_part(done[0]) in (want, "both"):
                continue
            print(f"{ladder} level {i} ({prec})", flush=True)
            if ladder == "pst" and a.pst_bracket:
                rec = pst_cut_level(PST_DX[i], prec, grid_bracket(*a.pst_bracket), a.device, a.workers, a.threads)
            elif ladder == "pst" and a.base_only:
                rec = pst_base_level(PST_DX[i], prec, a.device, a.workdir)
                if rec is None:
                    print(f"pst level {i}: stopped before its end; the same command resumes it", flush=True)
                    continue
            elif ladder == "pst":
                # one bracket for every level: the base run saws to its top, so the speed is measured over
                # the same distance at every level
                rec = pst_level(PST_DX[i], prec, dict(PST_BRACKET), a.device, a.workers, a.threads)
            else:
                rec = shear_level(SHEAR_CELLS[i], prec, a.device)
            rec["level"], rec["device"] = i, a.device     # a level run on a GPU is not a CPU wall time
            rec["git_commit"] = commit                    # levels may come from different runs
            data = load(a.results, name)   # merged into what is there now: another process may have written levels
            data["environment"] = environment(a.device)
            data.pop("environment_pst", None)        # an older layout's second environment: each level names its code
            have = data["ladders"].setdefault(ladder, [])
            if ladder == "pst" and (a.pst_bracket or a.base_only):    # the level's other part, when there
                other = [x for x in have if x.get("level") == i and x["precision"] == prec]
                rec = merge_pst_parts(rec, other[0] if other else None)
            have[:] = [x for x in have if not (x.get("level") == i and x["precision"] == prec)] + [rec]
            have.sort(key=lambda x: (x["precision"], x["level"]))
            data["summary"] = {k: summarise(k, v) for k, v in data["ladders"].items()}
            if data.get("field_level"):            # its error follows the ladder's reference
                data["field_level"]["errors"] = errors_against_reference(data["field_level"]["record"],
                                                                   data["summary"].get("pst", {}), QUANTITIES["pst"])
            write_json(name, data, a.results)
            figure(data, os.path.join(a.results, name + ".png"))
            print(json.dumps({k: rec[k] for k in rec if k in (*QUANTITIES[ladder], "wall_time_s")}), flush=True)
    print("results in", a.results, flush=True)
    return 0


def run_field_level(a, name: str) -> int:
    """``--field-level``: the ladder PST at the field protocol's resolution, merged into the JSON as ``field_level``."""
    data = load(a.results, name)
    if data.get("field_level") and not a.redo:
        print("the field level is in the JSON already (--redo runs it again)", flush=True)
        return 0
    dx = field_level_dx()
    print(f"pst field level: dx {dx:g} m", flush=True)
    rec = pst_level(dx, "float32", dict(PST_BRACKET), a.device, a.workers, a.threads)
    rec["device"] = a.device
    rec["git_commit"] = environment(a.device).get("git_commit")
    data = load(a.results, name)
    env = environment(a.device)
    env["load_average_at_end_1_5_15_min"] = list(os.getloadavg())
    data["environment_field_level"] = env
    errors = errors_against_reference(rec, data.get("summary", {}).get("pst", {}), QUANTITIES["pst"])
    data["field_level"] = {"record": rec, "errors": errors}
    write_json(name, data, a.results, end_load=False)     # the ladder's own environment stays as its levels left it
    print(json.dumps({q: e["error"] for q, e in data["field_level"]["errors"].items()}), flush=True)
    print("results in", a.results, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
