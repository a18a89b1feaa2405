"""Crack speed against slab stiffness and collapse height (docs/validation.md, Snow: "speed grows with slab
stiffness, falls with collapse height").

On the PST of the error-against-run-time ladder at its 6-cell level (2.2 m column, 0.3 m slab, 6 cm
weak layer, dx 10 mm; everything else ``pst_flat``), one parameter is changed at a time around the
centre case:

- the slab's Young's modulus ``E``: 1.25, 2.5, 5 (centre), 7.5, 10 MPa (density fixed);
- the weak layer's collapse height ``h_c`` (a field quantity of the calibration,
  :mod:`mpm_warp.scenes.weak_layer.calibration`): 0.5, 1 (centre: the WEAC fit, 4.7 mm for 6 cm),
  2 times the fit.

Each case is one run (:func:`mpm_warp.scenes.pst.cut_run`): the saw stops at 0.7 m, beyond every
case's critical cut, and the crack runs into the far end zone; its speed is the damage front's mean
from the cut to the end zone (1.9 m). Beside it, Heierli's (2005) speed of an elastic slab on a
collapsing layer with the run's own measured collapse height, ``c ~ E^(1/4) h_f^(-1/4)``. The
log-log slopes ``d ln c / d ln E`` and ``d ln c / d ln h_f`` (the measured collapse on the axis) are
reported against Heierli's +1/4 and -1/4.

Cases run as Dask tasks (:func:`mpm_warp.studies.fanout.dask_map`, one worker process per core). Writes
``benchmarks/snow/results/snow_speed_trends.json`` and ``.png``.

Usage::

    nohup .venv/bin/python benchmarks/snow/speed_trends.py > trends.log 2>&1 &
    .venv/bin/python benchmarks/snow/speed_trends.py --quick      # three runs, to a temporary folder
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from mpm_warp.finite_json import load_json
from mpm_warp.scenes.weak_layer import stored_calibration
from mpm_warp.studies.convergence import loglog_slope
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.fanout import dask_map
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.studies.snow import FIELD_SPEED, ladder_pst

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: the ladder PST (mpm_warp.studies.snow) at dx 10 mm, 6 cells across its 6 cm layer
COLUMN = ladder_pst(0.01)
CUT = 0.7                                   # m: the saw's stop, beyond every case's critical cut
SLAB_E = (1.25e6, 2.5e6, 5.0e6, 7.5e6, 1.0e7)  # Pa
H_C_FACTORS = (0.5, 1.0, 2.0)               # of the WEAC fit of the layer's thickness


def one_case(param: str, value: float, device: str, column: list = COLUMN, cut: float = CUT) -> dict:
    """One PST with ``param`` (``"slab.E"`` or ``"weak_layer.h_c"``) set to ``value``: runs in a Dask worker."""
    import mpm_warp as mw
    from mpm_warp.scenes.pst import cut_run

    sc = mw.load_scenario("pst_flat", column + [f"scene.{param}={value!r}"])
    t0 = time.perf_counter()
    r = cut_run(sc, cut, run_distance=sc.scene.length, free_run=0.5, device=device, n_threads=1)
    s = r["summary"]
    return {"param": param, "value": value, "propagated": r["propagated"], "front": r["front"],
            "speed": s.get("damage_speed_mean"), "speed_over": s.get("damage_speed_mean_over"),
            "collapse_height": s.get("collapse_height"), "touchdown": s.get("touchdown"),
            "heierli_speed_run": s.get("heierli_speed_run"), "h_c_calibrated": stored_calibration(sc).h_c,
            "slab_E": sc.scene.slab.E, "steps": r["steps"], "wall_s": time.perf_counter() - t0}


def figure(data: dict, path: str) -> None:
    import matplotlib.ticker

    plt = pyplot()

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    cut = data.get("cut", CUT)
    for ax, (key, xlabel, xscale) in zip(axes, (("slab.E", "slab Young's modulus E [MPa]", 1e-6),
                                                 ("weak_layer.h_c", "weak layer's collapse height h_c [mm]", 1e3)),
                                          strict=True):
        rows = data["trends"][key]["cases"]
        x = np.array([r["value"] if key == "slab.E" else r["h_c_calibrated"] for r in rows]) * xscale
        ran = np.array([bool(r["propagated"]) for r in rows])
        ax.plot(x[ran], [r["speed"] for r, k in zip(rows, ran, strict=True) if k], "o-", color="C3",
                label=f"damage front, mean {cut:g}-{rows[0]['speed_over'][1]:.1f} m "
                      f"(slope {data['trends'][key]['slope_speed']:+.2f})")
        ax.plot(x[ran], [r["heierli_speed_run"] for r, k in zip(rows, ran, strict=True) if k], "s--", color="C2",
                label=f"Heierli, run's collapse (slope {data['trends'][key]['slope_heierli']:+.2f})"
                      + ("" if key == "slab.E" else "\n(slopes against the measured collapse)"))
        for r, xv, k in zip(rows, x, ran, strict=True):
            if not k:
                ax.annotate(f"no crack from a {cut:g} m cut\n(front stopped at {r['front']:.2f} m)",
                            (xv, FIELD_SPEED[0]), xytext=(5, 20), textcoords="offset points", fontsize=8,
                            arrowprops=dict(arrowstyle="->"))
        ax.axhspan(*FIELD_SPEED, color="0.88", label="field 20-30 m/s")
        ax.set(xscale="log", yscale="log", xlabel=xlabel, ylabel="crack speed [m/s]")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xticks(x)
        ax.set_xlim(x.min() / 1.15, x.max() * 1.15)
        ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
        lo, hi = ax.get_ylim()
        ax.set_yticks([v for v in (5, 10, 12.5, 15, 17.5, 20, 22.5, 25, 30, 40, 50, 60, 80, 100, 150)
                       if lo <= v <= hi])
        ax.legend(fontsize=8)
    axes[0].set_title("speed against slab stiffness (h_c: WEAC fit)", fontsize=9)
    axes[1].set_title("speed against collapse height (h_c x 0.5, 1, 2 of the WEAC fit; E = 5 MPa)", fontsize=9)
    fig.suptitle("PST (2.2 m column, 0.3 m slab, 6 cm layer at 6 cells, cut 0.7 m): one parameter at a time",
                 fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "a smoke run: a 1.2 m column (too short for the trends) cut to 0.4 m; slab E 2.5 and "
                         "5 MPa, h_c 2 x the fit")
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--figure-only", action="store_true", help="redraw the figure from the JSON in --out (or results)")
    a = ap.parse_args(argv)
    name = "snow_speed_trends" + ("_quick" if a.quick else "")
    if a.figure_only:
        folder = a.out or RESULTS
        with open(os.path.join(folder, name + ".json")) as fh:
            figure(load_json(fh), os.path.join(folder, name + ".png"))
        return 0
    slab_e, h_c_factors = ((2.5e6, 5.0e6), (1.0, 2.0)) if a.quick else (SLAB_E, H_C_FACTORS)
    from mpm_warp.scenes.references import weac_collapse_height

    h_fit = weac_collapse_height(0.06)
    cases = [("slab.E", e) for e in slab_e] + [("weak_layer.h_c", f * h_fit) for f in h_c_factors if f != 1.0]
    t0 = time.perf_counter()
    column, cut = (COLUMN + ["scene.length=1.2"], 0.4) if a.quick else (COLUMN, CUT)
    rows = dask_map(one_case, [(p, v, a.device, column, cut) for p, v in cases], a.workers, a.scheduler)
    centre = next(r for r in rows if r["param"] == "slab.E" and r["value"] == 5.0e6)
    trends = {}
    for key, members in (("slab.E", [r for r in rows if r["param"] == "slab.E"]),
                         ("weak_layer.h_c", sorted([r for r in rows if r["param"] == "weak_layer.h_c"] + [centre],
                                                   key=lambda r: r["collapse_height"]))):
        x = [r["value"] if key == "slab.E" else r["collapse_height"] for r in members]
        trends[key] = {"cases": members, "slope_speed": loglog_slope(x, [r["speed"] for r in members]),
                       "slope_heierli": loglog_slope(x, [r["heierli_speed_run"] for r in members]),
                       "heierli_exponent": 0.25 if key == "slab.E" else -0.25,
                       "arrested": [r["value"] for r in members if not r["propagated"]],
                       "monotone": bool(np.all(np.diff([r["speed"] for r in members]) *
                                               (1 if key == "slab.E" else -1) > 0))}
    data = {"trends": trends, "column": column, "cut": cut, "h_c_fit": h_fit, "wall_s": time.perf_counter() - t0,
            "environment": environment(a.device)}
    folder = out_dir(a, RESULTS, "speed_trends")
    print("wrote", write_json(name, data, folder))
    figure(data, os.path.join(folder, name + ".png"))
    for key, t in trends.items():
        print(f"{key}: speed slope {t['slope_speed']:+.3f} (Heierli with the runs' collapse {t['slope_heierli']:+.3f},"
              f" closed form {t['heierli_exponent']:+.2f}); monotone {t['monotone']}")
        for r in t["cases"]:
            print(f"  {r['param']} = {r['value']:.4g}: speed {r['speed']:.3g} m/s, "
                  f"collapse {r['collapse_height']:.4g} m, touchdown {r['touchdown']:.3g} m, "
                  f"Heierli {r['heierli_speed_run']:.3g} m/s, {r['wall_s']:.0f} s")
    return 0 if all(t["monotone"] for t in trends.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
