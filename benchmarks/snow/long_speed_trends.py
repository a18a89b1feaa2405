"""Steady crack speed on 8 m columns against slab stiffness and collapse height (docs/validation.md, Snow).

The ladder PST's snow and cross-section (:data:`mpm_warp.studies.snow.LADDER_PST`: 0.3 m slab, 6 cm
weak layer, dx 10 mm, everything else ``pst_flat``) on an 8 m column, one parameter changed at a time
around the centre case, as in ``speed_trends.py`` (whose 2.2 m columns give the early phase only):

- the slab's Young's modulus ``E``: 2.5, 5 (centre), 10 MPa (density fixed);
- the weak layer's collapse height ``h_c``: 0.5, 1 (centre: the WEAC fit), 2 times the fit.

Each case is one run (:func:`mpm_warp.scenes.pst.cut_run`) with the saw stopped at 0.7 m, past the
centre's critical cut; the h_c x 0.5 layer, which arrested from 0.7 m on the 2.2 m column, is cut to
1.4 m. The steady speed is the median of the damage front's local speeds (0.5 m windows) centred beyond
5 m and ending before the far end zone (:func:`mpm_warp.studies.report.snow_runs.steady_speed`); beside it the same
run's early mean (the first 3 m from the cut), the slab's shear-wave speed ``c_s`` and Heierli's speed
with the run's collapse. Reference: the steady speed of long flat DEM PSTs is at most 0.6 c_s and
depends on the slab's and the layer's moduli (Bobillier et al. 2024).

Cases run as Dask tasks, one worker process per core; each finished case is kept in
``<out>/long_speed_trends_cases/`` and a rerun skips it (a killed run resumes by case). Writes
``benchmarks/snow/results/snow_long_speed_trends.json`` and ``.png``.

Usage::

    nohup .venv/bin/python benchmarks/snow/long_speed_trends.py > long_trends.log 2>&1 &
    .venv/bin/python benchmarks/snow/long_speed_trends.py --quick      # two short runs, to a temporary folder
"""

from __future__ import annotations

import datetime
import os
import sys
import time

import numpy as np

from mpm_warp.finite_json import load_json
from mpm_warp.studies.convergence import loglog_slope
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.fanout import dask_map
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.studies.snow import DEM_STEADY_MAX, STEADY_FROM, ladder_pst

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
COLUMN = [o for o in ladder_pst(0.01) if not o.startswith("scene.length=")] + ["scene.length=8.0"]
SLAB_E = (2.5e6, 5.0e6, 1.0e7)              # Pa
H_C_FACTORS = (0.5, 1.0, 2.0)               # of the WEAC fit of the layer's thickness
CUT = {1.0: 0.7, 0.5: 1.4}                  # m: the saw's stop per h_c factor (default 0.7)
FREE_RUN = 1.0                              # s after the saw stops: 8 m at 8 m/s


def one_case(param: str, value: float, cut: float, device: str, column: list, folder: str) -> dict:
    """One PST with ``param`` (``"slab.E"`` or ``"weak_layer.h_c"``) set to ``value``: runs in a Dask worker."""
    import mpm_warp as mw
    from mpm_warp.scenes.pst import cut_run
    from mpm_warp.scenes.weak_layer import stored_calibration

    path = os.path.join(folder, f"{param}_{value:.6g}.json")
    if os.path.exists(path):
        with open(path) as fh:
            row = load_json(fh)
        finished = datetime.datetime.fromtimestamp(os.path.getmtime(path), datetime.timezone.utc)
        return {**row, "from_earlier_run": True, "finished_at": row.get("finished_at") or finished.isoformat()}
    sc = mw.load_scenario("pst_flat", column + [f"scene.{param}={value!r}"])
    env = environment(device)            # the load when the case starts (write_json adds the load at its end)
    t0 = time.perf_counter()
    r = cut_run(sc, cut, run_distance=sc.scene.length, free_run=FREE_RUN, device=device, n_threads=1)
    s = r["summary"]
    prof = s.get("damage_speed_profile") or {"s": [], "speed": []}
    row = {"param": param, "value": value, "cut": cut, "propagated": r["propagated"], "front": r["front"],
           "early_speed": s.get("damage_speed_mean"), "early_over": s.get("damage_speed_mean_over"),
           "shear_wave_speed": sc.scene.equivalent_slab().material().s_wave_speed,
           "collapse_height": s.get("collapse_height"),
           "touchdown": s.get("touchdown"), "heierli_speed_run": s.get("heierli_speed_run"),
           "h_c_calibrated": stored_calibration(sc).h_c, "slab_E": sc.scene.slab.E,
           "speed_profile": {"s": list(prof["s"]), "speed": list(prof["speed"])},
           "steps": r["steps"], "wall_s": time.perf_counter() - t0,
           "finished_at": datetime.datetime.now(datetime.timezone.utc).isoformat(), "environment": env}
    write_json(os.path.splitext(os.path.basename(path))[0], row, folder)
    return row


def with_steady_speed(row: dict, length: float, slab_thickness: float) -> dict:
    """``row`` with its ``steady_speed`` (m/s; None on a column too short) from its stored speed profile, on a
    column of ``length`` under a slab of ``slab_thickness`` (m), and how far from steady it is: the change from
    the first to the last steady window over that speed."""
    from mpm_warp.studies.report.snow_runs import steady_speed, steady_windows

    res = {"damage_speed_profile": row["speed_profile"], "column_length": length}
    inside = steady_windows(res, slab_thickness)
    v = steady_speed(res, slab_thickness)
    rise = (inside[-1] - inside[0]) / v if v and len(inside) > 1 else None
    return {**row, "steady_speed": v, "steady_window_rise": rise}


def _ratio(r: dict) -> float:
    v = r["steady_speed"]
    return v / r["shear_wave_speed"] if v is not None else float("nan")


def trends(rows: list[dict], h_fit: float) -> dict:
    """Per parameter: the cases (centre shared), the log-log slopes of the steady and early speeds, and checks."""
    centre = next(r for r in rows if r["param"] == "slab.E" and r["value"] == 5.0e6)
    out = {}
    for key, members in (("slab.E", sorted((r for r in rows if r["param"] == "slab.E"), key=lambda r: r["value"])),
                         ("weak_layer.h_c", sorted([r for r in rows if r["param"] == "weak_layer.h_c"] + [centre],
                                                   key=lambda r: r["h_c_calibrated"]))):
        x = [r["value"] if key == "slab.E" else r["collapse_height"] for r in members]
        steady = [np.nan if r["steady_speed"] is None else r["steady_speed"] for r in members]
        out[key] = {"cases": members, "slope_steady": loglog_slope(x, steady),
                    "slope_early": loglog_slope(x, [r["early_speed"] for r in members]),
                    "slope_heierli": loglog_slope(x, [r["heierli_speed_run"] for r in members]),
                    "heierli_exponent": 0.25 if key == "slab.E" else -0.25,
                    "steady_over_cs": [_ratio(r) for r in members],
                    "arrested": [r["value"] for r in members if not r["propagated"]]}
    out["h_c_fit"] = h_fit
    out["max_steady_over_cs"] = float(np.nanmax([_ratio(r) for r in rows]))
    return out


def figure(data: dict, path: str) -> None:
    import matplotlib.ticker

    plt = pyplot()

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    rows = {(r["param"], r["value"]): r for k in ("slab.E", "weak_layer.h_c") for r in data["trends"][k]["cases"]}
    ax = axes[0]
    ran = [r for r in sorted(rows.values(), key=lambda r: (r["param"], r["value"])) if r["propagated"]]
    for i, r in enumerate(ran):  # an arrested case has no speed profile (it is marked on the right)
        p = r["speed_profile"]
        lab = (f"E {r['value'] / 1e6:g} MPa" if r["param"] == "slab.E" and r["value"] != 5e6 else
               "centre (E 5 MPa, h_c fit)" if r["param"] == "slab.E" else
               f"h_c {r['h_c_calibrated'] * 1e3:.2f} mm")
        ax.plot(p["s"], p["speed"], "-", color=f"C{i}", label=lab)
    ax.axvspan(*data["steady_range"], color="0.9",
               label="steady range (window centres)")
    ax.set(xlabel="damage front position from the cut end [m]", ylabel="local crack speed (0.5 m windows) [m/s]",
           xlim=(0, 8))
    ax.set_title("local speed along the 8 m column", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    for ax, (key, xlabel, xscale) in zip(axes[1:], (("slab.E", "slab Young's modulus E [MPa]", 1e-6),
                                                     ("weak_layer.h_c", "run's collapse height [mm]", 1e3)),
                                          strict=True):
        t = data["trends"][key]
        ok = [r for r in t["cases"] if r["propagated"] and r["steady_speed"] is not None]
        x = np.array([r["value"] if key == "slab.E" else r["collapse_height"] for r in ok]) * xscale
        ax.plot(x, [r["steady_speed"] for r in ok], "o-", color="C3",
                label=f"steady, beyond {STEADY_FROM:g} m (slope {t['slope_steady']:+.2f})")
        ax.plot(x, [r["early_speed"] for r in ok], "^:", color="C0",
                label=f"early mean, first 3 m (slope {t['slope_early']:+.2f})")
        ax.plot(x, [r["heierli_speed_run"] for r in ok], "s--", color="C2",
                label=f"Heierli, run's collapse (slope {t['slope_heierli']:+.2f})")
        ax.plot(x, [DEM_STEADY_MAX * r["shear_wave_speed"] for r in ok], "k-.", lw=0.8,
                label=f"{DEM_STEADY_MAX:g} c_s (DEM maximum)")
        for r in t["cases"]:
            if not r["propagated"]:
                ax.annotate(f"h_c {r['h_c_calibrated'] * 1e3:.2f} mm: no crack from a {r['cut']:g} m cut\n"
                            f"(front stopped at {r['front']:.2f} m)" if key != "slab.E" else
                            f"E {r['value'] / 1e6:g} MPa: no crack from a {r['cut']:g} m cut",
                            (0.2, 0.58), xycoords="axes fraction", fontsize=8)
        ax.set(xscale="log", xlabel=xlabel, ylabel="crack speed [m/s]")
        ax.set_xticks(x)
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.legend(fontsize=7, loc="upper left" if key == "slab.E" else "upper right",
                  bbox_to_anchor=(0.0, 1.0) if key == "slab.E" else (1.0, 0.9))
    axes[1].set_title("against slab stiffness (h_c: WEAC fit)", fontsize=9)
    axes[2].set_title("against collapse height (h_c x 0.5, 1, 2; E 5 MPa)", fontsize=9)
    fig.suptitle("PST on an 8 m column (0.3 m slab, 6 cm layer, dx 10 mm): one parameter at a time", fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "a 1.5 m column cut to 0.5 m, slab E 5 MPa and h_c x 2 (too short for a steady window)")
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--figure-only", action="store_true", help="redraw the figure from the JSON in --out (or results)")
    a = ap.parse_args(argv)
    name = "snow_long_speed_trends" + ("_quick" if a.quick else "")
    folder = out_dir(a, RESULTS, "long_speed_trends")
    if a.figure_only:
        with open(os.path.join(folder, name + ".json")) as fh:
            figure(load_json(fh), os.path.join(folder, name + ".png"))
        return 0
    from mpm_warp.scenes.references import weac_collapse_height

    h_fit = weac_collapse_height(0.06)
    column = COLUMN + (["scene.length=1.5"] if a.quick else [])
    es, fs = ((5.0e6,), (1.0, 2.0)) if a.quick else (SLAB_E, H_C_FACTORS)
    cases = [("weak_layer.h_c", f * h_fit, 0.5 if a.quick else CUT.get(f, 0.7)) for f in fs if f != 1.0]
    cases = sorted(cases, key=lambda c: -c[2]) + [("slab.E", e, 0.5 if a.quick else 0.7) for e in sorted(es)[::-1]]
    parts = os.path.join(folder, "long_speed_trends_cases")
    os.makedirs(parts, exist_ok=True)
    t0 = time.perf_counter()
    rows = dask_map(one_case, [(p, v, c, a.device, column, parts) for p, v, c in cases], a.workers, a.scheduler)
    import mpm_warp as mw
    from mpm_warp.studies.report.snow_runs import steady_range

    p = mw.load_scenario("pst_flat", column).scene
    rows = [with_steady_speed(r, p.length, p.slab_thickness) for r in rows]
    data = {"trends": trends(rows, h_fit), "column": column, "steady_from": STEADY_FROM,
            "steady_range": steady_range(p.length, p.slab_thickness), "free_run": FREE_RUN,
            "wall_s": time.perf_counter() - t0, "case_wall_s": sum(r["wall_s"] for r in rows),
            "cases_from_earlier_run": sum(bool(r.get("from_earlier_run")) for r in rows),
            "environment": environment(a.device)}
    print("wrote", write_json(name, data, folder))
    figure(data, os.path.join(folder, name + ".png"))
    for key in ("slab.E", "weak_layer.h_c"):
        t = data["trends"][key]
        print(f"{key}: steady slope {t['slope_steady']:+.3f}, early {t['slope_early']:+.3f}, "
              f"Heierli {t['slope_heierli']:+.3f} (closed form {t['heierli_exponent']:+.2f})")
        for r in t["cases"]:
            print(f"  {r['param']} = {r['value']:.4g} (cut {r['cut']:g} m): propagated {r['propagated']}, steady "
                  f"{r['steady_speed']} m/s ({_ratio(r):.2f} c_s, rising {r['steady_window_rise']} across the "
                  f"window), early {r['early_speed']:.3g} m/s, "
                  f"collapse {r['collapse_height']:.4g} m, {r['steps']} steps, {r['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
