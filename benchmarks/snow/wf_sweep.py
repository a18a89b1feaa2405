"""Crack speed and critical cut against the weak layer's fracture energy w_f: a Dask sweep.

For each ``w_f`` (default 0.1, 0.3, 0.79, 1.7 J/m^2: the field's range and the library's default;
the rest of the layer as ``pst_flat``) one Dask task bisects the critical cut
(:func:`mpm_warp.scenes.pst.critical_cut`, trial runs forked from one base run) on the PST of the
error-against-run-time ladder at its 6-cell level (2.2 m column, 0.3 m slab, 6 cm layer, dx 10 mm:
minutes per case on one core); its base run (the saw to ``hi``) runs on into the far end zone, and
its mean front speed is the crack speed. Tasks run on a local Dask cluster (one worker process per core, one
thread each) or on ``--scheduler``. Writes ``benchmarks/snow/results/snow_wf_sweep.json`` and ``.png``
(speed and critical cut against ``w_f``, beside the field band, Heierli's speed and Gaume et al.
2017's critical cut, which does not depend on ``w_f``).

Usage::

    nohup .venv/bin/python benchmarks/snow/wf_sweep.py > wf.log 2>&1 &
    .venv/bin/python benchmarks/snow/wf_sweep.py --quick      # two cases, to a temporary folder
"""

from __future__ import annotations

import math
import os
import sys
import time

from mpm_warp.scenes.weak_layer import stored_calibration
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.fanout import dask_map
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.studies.snow import FIELD_CUT, FIELD_SPEED, ladder_pst

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: the ladder PST (mpm_warp.studies.snow) at dx 10 mm, 6 cells across its 6 cm layer
COLUMN = ladder_pst(0.01)


def one_case(w_f: float, lo: float, hi: float, tol: float, device: str, column: list = COLUMN) -> dict:
    """Critical cut and crack speed of pst_flat with fracture energy ``w_f`` (J/m^2): runs in a Dask worker."""
    import mpm_warp as mw
    from mpm_warp.scenes.pst import critical_cut

    sc = mw.load_scenario("pst_flat", column + [f"scene.weak_layer.w_f={w_f!r}", "scene.weak_layer.delta_s=0.0"])
    t0 = time.perf_counter()
    lines = []
    res = critical_cut(sc, lo, hi, tol=tol, base_run_distance=sc.scene.length, device=device, n_threads=1,
                       log=lines.append)
    b = res.base
    cal = stored_calibration(sc)
    return {"w_f": w_f, "delta_s": cal.delta_s, "kappa_s": cal.kappa_s, "debond_energy": cal.debond_energy,
            "critical_cut": res.value, "bracketed": res.bracketed, "note": res.note, "lo": res.lo, "hi": res.hi,
            "trials": res.trials, "runaway_cut_of_base": res.runaway_cut,
            "speed": b.get("damage_speed_mean"), "speed_over": b.get("damage_speed_mean_over"),
            "deflection_speed": b.get("deflection_speed_mean"), "speed_max": b.get("damage_speed_max"),
            "speed_profile": b.get("damage_speed_profile"), "ran_to_end": b.get("ran_to_end"),
            "collapse_height": b.get("collapse_height"), "heierli_speed_run": b.get("heierli_speed_run"),
            "heierli_speed": b.get("heierli_speed"), "critical_cut_gaume": b.get("critical_cut_gaume"),
            "wall_s": time.perf_counter() - t0, "log": lines}


def figure(rows: list, path: str) -> None:
    plt = pyplot()

    w = [r["w_f"] for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    cut = rows[0]["speed_over"][0]  # the base run saws to the top of the bracket
    ax[0].plot(w, [r["speed"] for r in rows], "o-", color="C3",
               label=f"damage front, mean from the base run's {cut:g} m cut")
    ax[0].plot(w, [r["heierli_speed_run"] for r in rows], "s--", color="C2", label="Heierli (run's collapse)")
    ax[0].axhspan(*FIELD_SPEED, color="0.88", label="field 20-30 m/s")
    ax[0].set(xscale="log", xlabel="fracture energy w_f [J/m^2]", ylabel="crack speed [m/s]", title="speed")
    ax[0].legend(fontsize=8)
    for r in rows:
        ax[1].plot([r["w_f"]] * 2, [r["lo"], r["hi"]], "-", color="C0", lw=4, alpha=0.5)
    ax[1].plot(w, [r["critical_cut"] for r in rows], "o-", color="C0", label="bisection (bar: bracket)")
    for r in rows:
        if not math.isfinite(r["critical_cut"]):
            ax[1].annotate(f"no crack from a\n{r['hi']:g} m cut", (r["w_f"], r["hi"]), xytext=(-70, -30),
                           textcoords="offset points", fontsize=8, arrowprops=dict(arrowstyle="->"))
    ax[1].plot(w, [r["critical_cut_gaume"] for r in rows], "D:", color="C2", mfc="none",
               label="Gaume et al. 2017 (no w_f)")
    ax[1].axhspan(*FIELD_CUT, color="0.88", label="0.15-0.6 m")
    ax[1].set(xscale="log", xlabel="fracture energy w_f [J/m^2]", ylabel="critical cut [m]", title="critical cut")
    ax[1].legend(fontsize=8)
    fig.suptitle("PST (2.2 m column, 0.3 m slab, 6 cm layer at 6 cells): the weak layer's fracture energy swept, "
                 "everything else fixed", fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "a 1.2 m column, w_f 0.3 and 0.79 J/m^2, bracket [0.1, 0.5] m bisected once")
    ap.add_argument("--w-f", default="0.1,0.3,0.79,1.7", help="fracture energies (J/m^2), comma separated")
    ap.add_argument("--lo", type=float, default=0.05)
    ap.add_argument("--hi", type=float, default=1.2)
    ap.add_argument("--tol", type=float, default=0.02)
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    a = ap.parse_args(argv)
    if a.quick:
        a.w_f, a.lo, a.hi, a.tol = "0.3,0.79", 0.1, 0.5, 0.25
    values = [float(v) for v in a.w_f.split(",")]
    t0 = time.perf_counter()
    column = COLUMN + ["scene.length=1.2"] if a.quick else COLUMN
    rows = dask_map(one_case, [(w, a.lo, a.hi, a.tol, a.device, column) for w in values], a.workers, a.scheduler)
    rows.sort(key=lambda r: r["w_f"])
    data = {"cases": rows, "column": column, "bracket": [a.lo, a.hi, a.tol], "wall_s": time.perf_counter() - t0,
            "environment": environment(a.device)}
    name = "snow_wf_sweep" + ("_quick" if a.quick else "")
    folder = out_dir(a, RESULTS, "wf_sweep")
    print("wrote", write_json(name, data, folder))
    figure(rows, os.path.join(folder, name + ".png"))
    for r in rows:
        print(f"w_f {r['w_f']:.3g} J/m^2: critical cut {r['critical_cut']:.3g} m [{r['lo']:.3g}, {r['hi']:.3g}] "
              f"{r['note']}; speed {r['speed']:.3g} m/s (Heierli {r['heierli_speed_run']:.3g}); {r['wall_s']:.0f} s")
    return 0 if all(math.isfinite(r["critical_cut"]) for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
