"""Error against run time of the reference problems (docs/validation.md "Error against run time").

For each problem of :data:`mpm_warp.validation.PROBLEMS` (axial bar period,
self-weight column stress, weak-layer collapse) this runs

* a ladder of grid spacings ``dx`` (halving; 2 particles per cell and axis and
  CFL factor 0.4 fixed), and
* a ladder of CFL factors 0.8, 0.4, 0.2, 0.1 at one ``dx``,

and records, per run, the validation record of :mod:`mpm_warp.validation`
(relative error, wall time of the stepping without kernel compilation, steps,
particles, particle-steps per second, device, precision, Warp version). Wall
times are the median of ``--repeats`` runs (3); a case whose first run takes
longer than ``--repeat-limit`` seconds is run once only (stated per run as
``runs`` in the outputs). The errors are deterministic (checked: the spread
over repeats is stored).

Per problem it reports the observed order in ``dx`` (least-squares slope of
``log error`` on ``log dx`` over the ladder), the slope of ``log error`` against
``log wall time``, and the wall time needed for 1 % error, interpolated in
log-log between the two ladder runs that bracket it ("already at the
coarsest" or "not reached" otherwise, with the numbers). For the CFL ladder,
whose error is dominated by the spatial error, it also gives the change of the
measured quantity against the smallest CFL factor (an estimate of the time-
stepping error) and its order in the CFL factor.

The snow scenes' ladders (PST critical cut, crack speed, touchdown, collapse;
shear-test peak, softening slip, collapse) take hours on a CPU and run in
``error_vs_runtime_snow.py``.

Outputs ``benchmarks/convergence/results/error_vs_runtime.json`` (everything, with the
environment record), ``error_vs_runtime.md`` (tables) and ``error_vs_runtime.png``
(log-log error against wall time; solid: dx ladder, dashed: CFL ladder).

Run: ``python benchmarks/convergence/error_vs_runtime.py`` (about 6 min on one CPU core);
``--quick`` for a two-level smoke run (to a temporary folder); ``--plot-only`` redraws from the JSON.
The convergence arithmetic (orders, time to an error) is :mod:`mpm_warp.studies.convergence`.
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import time

from mpm_warp.errors import SimulationBlowUp
from mpm_warp.finite_json import dump_finite, load_json
from mpm_warp.studies.convergence import observed_order, time_to_target
from mpm_warp.studies.environment import check_provenance, environment
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.validation import PROBLEMS

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
TARGET = 0.01
CFL = 0.4
DT_LADDER_CFL = (0.8, 0.4, 0.2, 0.1)

#: per problem: dx ladder (m, halving), the dx of the CFL ladder, precision, label of the resolution
LADDERS = {
    "axial_bar": {"dx": [25.0 / 2**k for k in range(3, 9)], "dt_dx": 25.0 / 32.0, "precision": "float32",
                  "cells": lambda dx: f"{25.0 / dx:.0f} cells along L"},
    "self_weight_column": {"dx": [1.0 / 2**k for k in range(2, 8)], "dt_dx": 1.0 / 16.0, "precision": "float64",
                           "cells": lambda dx: f"{1.0 / dx:.0f} cells along H"},
    "weak_layer_collapse": {"dx": [1.0 / 2**k for k in range(7, 12)], "dt_dx": 1.0 / 256.0, "precision": "float64",
                            "cells": lambda dx: f"{(1.0 / 32.0) / dx:.0f} cells across D_wl"},
}
REFERENCE = {
    "axial_bar": "period 4 L / c = 10 s (L 25, E 100, rho 1, nu 0, v0 0.1); error |T / T_exact - 1|",
    "self_weight_column": ("sigma_yy = -rho g (H - Y) (H 1 m, E 1 MPa, nu 0.3, rho 250); error: RMS over Y > H/4 "
                           "of (sigma_yy + rho g (H - Y)) / (rho g H)"),
    "weak_layer_collapse": ("mean 1 - J_P of the layer against the uniaxial-strain closed form (xi 0.04, slab rho "
                            "1200, D_wl 1/32 m, h 1/16 m); error |mean / closed form - 1|"),
}


def _ok(r: dict) -> bool:
    """A run with a usable (finite, positive) error."""
    e = r.get("error")
    return e is not None and math.isfinite(e) and e > 0.0


def _f(x, fmt: str = ".2f") -> str:
    return "n/a" if x is None else format(x, fmt)


def timed_case(name: str, dx: float, cfl: float, precision: str, device: str, n_threads: int, repeats: int,
               repeat_limit: float) -> dict:
    """Run one case ``repeats`` times (once if the first run exceeds ``repeat_limit`` s); median wall time."""
    fn = PROBLEMS[name]
    recs = []
    for k in range(repeats):
        try:
            rec = fn(dx, cfl=cfl, precision=precision, device=device, n_threads=n_threads)
        except SimulationBlowUp as e:
            return {"problem": name, "dx": dx, "cfl": cfl, "precision": precision, "error": None,
                    "blow_up": str(e), "runs": k + 1}
        recs.append(rec)
        if rec["wall_time_s"] > repeat_limit:
            break
    out = dict(recs[0])
    walls = [r["wall_time_s"] for r in recs]
    out["wall_times_s"] = walls
    out["wall_time_s"] = float(statistics.median(walls))
    out["particle_steps_per_s"] = out["n_particles"] * out["steps"] / out["wall_time_s"]
    out["runs"] = len(recs)
    out["error_spread_over_runs"] = float(max(r["error"] for r in recs) - min(r["error"] for r in recs))
    if len(recs) < repeats:
        out["runs_note"] = (f"one run only: the first took {walls[0]:.0f} s > repeat limit {repeat_limit:g} s "
                            "(2 shared CPU cores)")
    return out


def summarise(name: str, dx_runs: list[dict], dt_runs: list[dict]) -> dict:
    """Observed orders, error-time slope, time to 1 % error, time-stepping error of the CFL ladder."""
    ok = [r for r in dx_runs if _ok(r)]
    s = {"observed_order_dx": observed_order([r["dx"] for r in ok], [r["error"] for r in ok]) if len(ok) > 1 else None,
         "observed_order_dx_finest3": (observed_order([r["dx"] for r in ok[-3:]], [r["error"] for r in ok[-3:]])
                                       if len(ok) > 2 else None),
         "error_time_slope": (observed_order([r["wall_time_s"] for r in ok], [r["error"] for r in ok])
                              if len(ok) > 1 else None),
         "time_to_1pct": time_to_target(ok, TARGET)}
    okt = sorted((r for r in dt_runs if r.get("error") is not None), key=lambda r: -r["cfl"])
    if okt:
        ref = okt[-1]
        for r in okt:
            r["change_vs_smallest_cfl"] = abs(r["measured"] - ref["measured"]) / abs(ref["reference"])
        d = [(r["cfl"], r["change_vs_smallest_cfl"]) for r in okt[:-1] if r["change_vs_smallest_cfl"] > 0]
        # an order only where the change falls with the CFL factor (else it is round-off or settling noise)
        falls = len(d) > 1 and all(b[1] < a[1] for a, b in zip(d, d[1:], strict=False))
        s["observed_order_cfl_of_change"] = observed_order(*zip(*d, strict=True)) if falls else None
        s["observed_order_cfl_of_error"] = (observed_order([r["cfl"] for r in okt], [r["error"] for r in okt])
                                            if len(okt) > 1 else None)
    return s


def pst_estimate() -> dict:
    """Where the snow scenes' ladders are: not here (hours on a CPU), in ``error_vs_runtime_snow.py``."""
    return {"included": False,
            "note": ("the PST (critical cut, crack speed, touchdown, collapse) and shear-test (peak, delta_s, "
                     "collapse) ladders run in benchmarks/convergence/error_vs_runtime_snow.py -> "
                     "benchmarks/convergence/results/error_vs_runtime_snow.{json,png}")}


def plot(data: dict, path: str) -> None:
    """Log-log error against wall time: one colour per problem; solid dx ladder, dashed CFL ladder."""
    plt = pyplot()

    fig, ax = plt.subplots(figsize=(8.5, 6))
    colors = dict(zip(data["problems"], plt.cm.tab10.colors, strict=False))
    for name, p in data["problems"].items():
        c = colors[name]
        dxr = [r for r in p["dx_ladder"] if _ok(r)]
        ax.plot([r["wall_time_s"] for r in dxr], [r["error"] for r in dxr], "-o", color=c, ms=5,
                label=f"{name}: dx ladder (order {_f(p['summary']['observed_order_dx'])})")
        for r in dxr:
            ax.annotate(f"{r['cells_label'].split()[0]}", (r["wall_time_s"], r["error"]), fontsize=6, color=c,
                        textcoords="offset points", xytext=(3, 3))
        dtr = [r for r in p["dt_ladder"] if _ok(r)]
        ax.plot([r["wall_time_s"] for r in dtr], [r["error"] for r in dtr], "--^", color=c, ms=5, mfc="none",
                label=f"{name}: CFL ladder at {dtr[0]['cells_label'].split()[0]} cells" if dtr else None)
        for r in dtr:
            ax.annotate(f"C={r['cfl']:g}", (r["wall_time_s"], r["error"]), fontsize=6, color=c,
                        textcoords="offset points", xytext=(3, -9))
        t1 = p["summary"]["time_to_1pct"]
        if t1.get("status") == "interpolated":
            ax.plot(t1["wall_time_s"], TARGET, "*", color=c, ms=11, mec="k", mew=0.5)
    ax.axhline(TARGET, color="k", lw=0.7, ls=":", label="1 % error (star: interpolated time)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of the stepping, median (s; compilation excluded)")
    ax.set_ylabel("relative error against the reference")
    env = data["environment"]
    ax.set_title(f"Error against run time ({env['device']}, {env['n_threads']} thread, warp {env['warp']}; "
                 "labels: cells)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="lower left")
    save_figure(fig, path)


def markdown(data: dict) -> str:
    """Tables of every run and the per-problem summary."""
    env = data["environment"]
    lines = [f"# Error against run time ({data['date']})", "",
             f"Device {env['device']} ({env['cpu']}), {env['n_threads']} thread, warp {env['warp']}, "
             f"mpm_warp {env['mpm_warp']}, numpy {env['numpy']}. Wall time: stepping only (compilation and "
             f"measurements between frames excluded), median of `runs` runs; CFL factor {CFL} on the dx ladder, "
             "2 particles per cell and axis.", ""]
    for name, p in data["problems"].items():
        lines += [f"## {name}", "", f"Reference: {p['reference']}. Precision {p['precision']}.", "",
                  "| ladder | dx (m) | resolution | CFL | mean dt (s) | steps | particles | error | signed | "
                  "wall (s) | runs | particle-steps/s |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for lad in ("dx_ladder", "dt_ladder"):
            for r in p[lad]:
                if r.get("error") is None:
                    lines.append(f"| {lad[:2]} | {r['dx']:.5g} | | {r['cfl']:g} | blow-up: {r.get('blow_up')} "
                                 "| | | | | | | |")
                    continue
                lines.append(f"| {lad[:2]} | {r['dx']:.5g} | {r['cells_label']} | {r['cfl']:g} | {r['dt_mean_s']:.3g} "
                             f"| {r['steps']} | {r['n_particles']} | {100 * r['error']:.4f} % | "
                             f"{100 * r['signed_error']:+.4f} % | {r['wall_time_s']:.3g} | {r['runs']} | "
                             f"{r['particle_steps_per_s']:.3g} |")
        s = p["summary"]
        t1 = s["time_to_1pct"]
        if t1["status"] == "interpolated":
            t1s = (f"{t1['wall_time_s']:.3g} s (interpolated in log-log at dx ~ {t1['dx']:.3g} m, between "
                   + " and ".join(f"{100 * b['error']:.2f} % in {b['wall_time_s']:.3g} s" for b in t1["between"]) + ")")
        elif "error" in t1:
            t1s = f"{t1['status']}: {100 * t1['error']:.3f} % at dx {t1['dx']:.4g} m in {t1['wall_time_s']:.3g} s"
        else:
            t1s = t1["status"]
        lines += ["", f"- observed order in dx (all levels): {_f(s['observed_order_dx'])}; finest three: "
                      f"{_f(s['observed_order_dx_finest3'])}",
                  f"- slope of log error against log wall time: {_f(s['error_time_slope'])}",
                  f"- wall time for 1 % error: {t1s}"]
        if "observed_order_cfl_of_change" in s:
            ch = ", ".join(f"C {r['cfl']:g}: {r['change_vs_smallest_cfl']:.2e}" for r in p["dt_ladder"]
                           if r.get("error") is not None)
            oc = s["observed_order_cfl_of_change"]
            lines.append(f"- CFL ladder: change of the measured value against the smallest C (relative to the "
                         f"reference): {ch}; order in C " + (f"{oc:.2f}" if oc is not None else
                                                             "n/a (the change does not fall with C: noise level)"))
        lines.append("")
    pst = data["pst"]
    lines += ["## Snow scenes (not included)", "", pst.get("note", ""), ""]
    if "n_particles" in pst:
        lines += [f"pst_demo: dx {pst['dx']} m, {pst['n_particles']} particles, ~{pst['steps_estimate']} steps, "
                  f"{pst['particle_steps']:.2g} particle-steps per run.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = parser(__doc__, "the two coarsest dx, CFL 0.4 and 0.2, one run each")
    ap.add_argument("--problems", nargs="+", default=list(LADDERS), choices=list(LADDERS))
    ap.add_argument("--threads", type=int, default=1, help="CPU threads of the step (1: comparable, shared machine)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--repeat-limit", type=float, default=120.0,
                    help="run a case once only when its first run takes longer than this (s)")
    ap.add_argument("--plot-only", action="store_true", help="redraw the figure and tables from the JSON in --out")
    a = ap.parse_args(argv)
    name = "error_vs_runtime" + ("_quick" if a.quick else "")
    folder = (a.out or RESULTS) if a.plot_only else out_dir(a, RESULTS, "error_vs_runtime")
    path, stem = os.path.join(folder, name + ".json"), os.path.join(folder, name)
    if a.plot_only:
        with open(path) as fh:
            data = load_json(fh)
        plot(data, stem + ".png")
        with open(stem + ".md", "w") as fh:
            fh.write(markdown(data))
        return 0
    env = environment(a.device)
    data = {"benchmark": "error_vs_runtime", "date": env["date"][:10], "environment": {**env, "n_threads": a.threads},
            "settings": {"cfl_dx_ladder": CFL, "cfl_ladder": list(DT_LADDER_CFL), "particles_per_cell_per_axis": 2,
                         "repeats": a.repeats, "repeat_limit_s": a.repeat_limit, "target_error": TARGET},
            "problems": {}, "pst": pst_estimate()}
    t_all = time.perf_counter()
    for name in a.problems:
        lad = LADDERS[name]
        dxs = lad["dx"][:2] if a.quick else lad["dx"]
        cfls = (0.4, 0.2) if a.quick else DT_LADDER_CFL
        reps = 1 if a.quick else a.repeats
        # warm-up: load (compile) this problem's kernels once, outside every timing
        PROBLEMS[name](dxs[0], precision=lad["precision"], device=a.device, n_threads=a.threads)
        p = {"reference": REFERENCE[name], "precision": lad["precision"], "dx_ladder": [], "dt_ladder": []}
        data["problems"][name] = p
        jobs = [("dx_ladder", dx, CFL) for dx in dxs] + [("dt_ladder", lad["dt_dx"], c) for c in cfls]
        for ladder, dx, cfl in jobs:
            r = timed_case(name, dx, cfl, lad["precision"], a.device, a.threads, reps, a.repeat_limit)
            r["cells_label"] = lad["cells"](dx)
            p[ladder].append(r)
            err = f"{100 * r['error']:.4f} %" if r.get("error") is not None else "blow-up"
            print(f"{name} {ladder} dx {dx:.5g} cfl {cfl:g}: error {err}, wall {r.get('wall_time_s', 0):.3g} s "
                  f"(runs {r['runs']}), steps {r.get('steps')}, particles {r.get('n_particles')}", flush=True)
            p["summary"] = summarise(name, p["dx_ladder"], p["dt_ladder"])
            data["wall_time_benchmark_s"] = time.perf_counter() - t_all
            check_provenance(folder, data)                # no result from uncommitted code in results
            with open(path + ".tmp", "w") as fh:
                dump_finite(data, fh, indent=1, default=float)
            os.replace(path + ".tmp", path)
        s = p["summary"]
        print(f"{name}: order in dx {_f(s['observed_order_dx'])}, time to 1 %: {s['time_to_1pct']}", flush=True)
    plot(data, stem + ".png")
    with open(stem + ".md", "w") as fh:
        fh.write(markdown(data))
    print(f"done in {time.perf_counter() - t_all:.0f} s: {path}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
