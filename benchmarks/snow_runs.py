"""Full-resolution snow runs: PST on flat ground and on a slope, shear test, critical cut length.

Each scene runs at the resolution of its file in ``scenarios/`` (CPU by
default; one after the other: the machine has 2 cores) and writes
``benchmarks/results/snow_<case>.json`` and ``snow_<case>.png``:

- ``pst_flat`` / ``pst_slope``: crack speed fitted on the steady part, side by
  side with field values (20-30 m/s, Bergfeld et al. 2021), Heierli's anticrack
  speed (with the collapse height measured in the run and with the one of the
  hardening law) and the slab's Rayleigh speed; touchdown distance against
  Heierli and the field (~2.7 m); collapse height;
- ``shear_test``: peak and residual shear strength, collapse fraction and
  critical sliding displacement against SI Note 2 (~20 %, ~2 mm);
- ``critical_cut``: critical cut length by bisection over coarse PST runs
  (pst_demo's resolution) against Gaume et al. (2017);
- ``pst_demo``: the demo scene, timed;
- ``snow_summary.json`` / ``.png``: every comparison in one table, and crack
  speed and touchdown of the flat and sloped PSTs side by side.

Usage::

    nohup .venv/bin/python benchmarks/snow_runs.py --cases demo,flat,slope,shear,critical > snow.log 2>&1 &

Run files (HDF5) go to ``--h5dir`` (default: a temporary folder), not to the repository.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from common import RESULTS, environment, write_json  # noqa: E402

import mpm_warp as mw  # noqa: E402
from mpm_warp.loader import load_scenario  # noqa: E402
from mpm_warp.scenes.fronts import arrival_speed, critical_cut_length  # noqa: E402
from mpm_warp.scenes.pst.references import critical_cut_length_formula, heierli_speed, heierli_touchdown  # noqa: E402
from mpm_warp.scenes.shear_test import shear_curves, shear_summary  # noqa: E402

FIELD_SPEED = (20.0, 30.0)  # m/s, PST crack speeds (Bergfeld et al. 2021; MODEL.md 6)
FIELD_TOUCHDOWN = 2.7       # m, PST touchdown distance (Bergfeld et al. 2021)
SI_COLLAPSE = 0.20          # -, shear test collapse fraction (SI Note 2)
SI_SLIDING = 0.002          # m, critical sliding displacement (SI Note 2)
FIELD_CUT = (0.2, 0.5)      # m, field critical cut lengths (MODEL.md 6: tens of cm)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _rel(a: float, b: float) -> float:
    return (a - b) / b if b and np.isfinite(a) else math.nan


def pst_case(name: str, scene: str, h5dir: str, device: str, overrides=None) -> dict:
    """Run one PST scene, write its JSON and figure, return the results."""
    path = os.path.join(h5dir, f"{name}.h5")
    t0 = time.perf_counter()
    res = mw.run(scene, output=path, device=device, overrides=overrides, overwrite=True)   # --h5dir may be reused
    mon = res.monitor
    elapsed = time.perf_counter() - t0
    ex = dict(res.scene_result)
    sc = mon.params
    d = sc.references()
    slab = sc.slab
    h_c = ex["collapse_height"]
    refs = {
        "field_speed_range": list(FIELD_SPEED),
        "heierli_speed_measured_collapse": heierli_speed(slab.E, sc.slab_thickness, slab.density, h_c),
        "heierli_speed_law_collapse": d["heierli_speed"],
        "rayleigh_speed": d["rayleigh_speed"],
        "shear_wave_speed": d["shear_wave_speed"],
        "field_touchdown": FIELD_TOUCHDOWN,
        "heierli_touchdown_measured_collapse": heierli_touchdown(slab.E, sc.slab_thickness, slab.density, h_c),
        "heierli_touchdown_law_collapse": d["heierli_touchdown"],
        "collapse_height_law": d["collapse_height_law"],
    }
    c = ex["speed"]
    cmp_ = {
        "speed_vs_field_mid": _rel(c, float(np.mean(FIELD_SPEED))),
        "speed_vs_heierli_measured": _rel(c, refs["heierli_speed_measured_collapse"]),
        "speed_over_rayleigh": c / refs["rayleigh_speed"] if np.isfinite(c) else math.nan,
        "speed_over_shear_wave": c / refs["shear_wave_speed"] if np.isfinite(c) else math.nan,
        "touchdown_vs_field": _rel(ex["touchdown"], FIELD_TOUCHDOWN),
        "touchdown_vs_heierli_measured": _rel(ex["touchdown"], refs["heierli_touchdown_measured_collapse"]),
        "collapse_vs_law": _rel(h_c, d["collapse_height_law"]),
    }
    sb, tb = mon.arrival_times()
    out = {"case": name, "scene": scene, "overrides": overrides or [], "environment": environment(res.device),
           "n_particles": res.n_particles, "steps": res.steps, "sim_time": res.sim_time,
           "stepping_wall_time_s": res.wall_time, "total_wall_time_s": elapsed,
           "particle_steps_per_s": res.particle_steps_per_s, "results": ex, "references": refs,
           "relative_differences": cmp_, "scene_parameters": sc.to_dict(),
           "series": {"time": mon.times, "front": mon.series["front"], "failure_front": mon.series["failure_front"],
                      "collapse_height": mon.series["collapse_height"]},
           "arrival": {"s": sb.tolist(), "t": [float(v) if np.isfinite(v) else None for v in tb]}}
    write_json(f"snow_{name}", out)
    _pst_figure(name, mon, ex, refs)
    return out


def _pst_figure(name: str, mon, ex: dict, refs: dict) -> None:
    plt = _plt()
    sc = mon.params
    t = np.asarray(mon.times)
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    ax[0].plot(t, mon.series["front"], "k-", label="collapse front")
    ax[0].plot(t, mon.series["failure_front"], "r--", label="failure front")
    ax[0].plot(t, mon.series["saw"], "b:", label="saw")
    sb, tb = mon.arrival_times()
    ok = np.isfinite(tb)
    ax[0].plot(tb[ok], sb[ok], ".", ms=2, color="0.5", label="bin arrival")
    lo, hi = ex["speed_fit_window"]
    if np.isfinite(ex["speed"]):
        fit = arrival_speed(sb, tb, lo, hi)
        ss = np.linspace(lo, hi, 10)
        ax[0].plot(fit.intercept + ss / fit.speed, ss, "g-", lw=3, alpha=0.5, label=f"fit {ex['speed']:.1f} m/s")
    ax[0].set(xlabel="t (s)", ylabel="distance from cut end (m)", title=f"{name}: crack front")
    ax[0].legend(fontsize=7)
    # slab-base deflection profiles
    mk = sc.markers()
    s_mk = sc.distance_from_cut_end(mk)
    uy = np.stack([np.asarray(mon.series[f"marker{k}_uy"]) for k in range(len(mk))], axis=1)
    i0 = min(int(np.searchsorted(t, sc.saw_start)), len(t) - 1)
    w = -(uy - uy[i0]) * 1000.0
    front = np.asarray(mon.series["front"])
    for i in np.linspace(i0, len(t) - 1, 7).astype(int):
        ax[1].plot(s_mk, w[i], label=f"t = {t[i]:.3f} s, front {front[i]:.2f} m")
    ax[1].axhline(ex["collapse_height"] * 1000, color="k", ls=":", label="collapse height")
    ax[1].invert_yaxis()
    ax[1].set(xlabel="distance from cut end (m)", ylabel="slab base deflection (mm)",
              title=f"touchdown {ex['touchdown']:.2f} m")
    ax[1].legend(fontsize=6)
    labels = ["run", "field 20-30", "Heierli (h_c run)", "Heierli (h_c law)", "Rayleigh", "c_s"]
    vals = [ex["speed"], np.mean(FIELD_SPEED), refs["heierli_speed_measured_collapse"],
            refs["heierli_speed_law_collapse"], refs["rayleigh_speed"], refs["shear_wave_speed"]]
    ax[2].bar(labels, vals, color=["k", "tab:green", "tab:blue", "tab:cyan", "tab:orange", "tab:red"])
    ax[2].errorbar([1], [np.mean(FIELD_SPEED)], yerr=[[5.0], [5.0]], color="k", capsize=5)
    ax[2].set(ylabel="crack speed (m/s)", title="crack speed vs references")
    ax[2].tick_params(axis="x", labelrotation=30, labelsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, f"snow_{name}.png"), dpi=110)
    plt.close(fig)


def shear_case(h5dir: str, device: str, overrides=None) -> dict:
    """Run the shear test, write its JSON and figure."""
    path = os.path.join(h5dir, "shear_test.h5")
    t0 = time.perf_counter()
    res = mw.run("shear_test", output=path, device=device, overrides=overrides, overwrite=True)
    mon = res.monitor
    elapsed = time.perf_counter() - t0
    series = {k: np.asarray(v) for k, v in mon.series.items()}
    c = shear_curves(mon.params, mon.times, series)
    n0 = len(mon.times) - len(c["u"])
    out = {"case": "shear_test", "environment": environment(res.device), "n_particles": res.n_particles,
           "steps": res.steps, "stepping_wall_time_s": res.wall_time, "total_wall_time_s": elapsed,
           "scene_parameters": mon.params.to_dict(), "references": mon.params.references(),
           "curves": {k: np.asarray(v).tolist() for k, v in c.items()},
           "failed_fraction": series["failed_fraction"][n0:].tolist(),
           "layer_shear_stress": series["layer_shear_stress"][n0:].tolist()}
    return shear_report(out)


def shear_report(out: dict) -> dict:
    """Results, comparisons, JSON and figure of a shear test from its stored curves (``out["curves"]``)."""
    c = {k: np.asarray(v, dtype=float) for k, v in out["curves"].items()}
    sm = shear_summary(c["u"], c["tau"], c["axial"])
    d = out.get("references") or out["scene_parameters"]["derived"]  # files written before the scenes package
    ex = {"peak_shear_stress": sm.peak_stress, "residual_shear_stress": sm.residual_stress,
          "peak_displacement": sm.peak_displacement, "softening_displacement": sm.softening_displacement,
          "drop_displacement": sm.drop_displacement, "collapse_fraction": sm.collapse_fraction,
          "min_stress_after_peak": float(np.min(c["tau"][sm.peak_index + 1:])) if sm.peak_index + 1 < len(c["tau"])
          else math.nan,
          "peak_q": float(np.max(c["q"])), "sigma_n": d["sigma_n"], "collapse_fraction_law": d["collapse_fraction_law"]}
    out["results"] = ex
    out["references"] = {"si_collapse_fraction": SI_COLLAPSE, "si_sliding_displacement": SI_SLIDING}
    out["relative_differences"] = {"collapse_vs_si": _rel(ex["collapse_fraction"], SI_COLLAPSE),
                                   "collapse_vs_law": _rel(ex["collapse_fraction"], ex["collapse_fraction_law"]),
                                   "sliding_vs_si": _rel(ex["softening_displacement"], SI_SLIDING)}
    write_json("snow_shear_test", out)
    plt = _plt()
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    g = c["gamma"]
    ax[0].plot(g, c["tau"], "k-", label="push force / area (wall reaction)")
    if "layer_shear_stress" in out:
        ax[0].plot(g, out["layer_shear_stress"], "-", color="0.6", lw=0.8, label="mean sigma_xy of the layer")
    ax[0].axhline(ex["peak_shear_stress"], color="r", ls=":", label="peak (intact)")
    ax[0].axhline(ex["residual_shear_stress"], color="b", ls=":", label="residual")
    if np.isfinite(ex["softening_displacement"]):
        d_wl = out["scene_parameters"]["weak_layer_thickness"]
        g_end = (ex["peak_displacement"] + ex["softening_displacement"]) / d_wl
        ax[0].axvline(g_end, color="g", ls="--", label=f"end of softening, delta_s = "
                                                        f"{ex['softening_displacement'] * 1e3:.2f} mm")
    ax[0].set(xlabel="shear strain u / D_wl", ylabel="shear stress (Pa)", title="shear stress")
    ax[0].legend(fontsize=7)
    ax[1].plot(g, c["q"], "k-")
    ax[1].set(xlabel="shear strain", ylabel="Mises q (Pa)", title="Mises stress (SI Fig. 1 middle)")
    ax[2].plot(g, c["axial"], "k-")
    ax[2].axhline(SI_COLLAPSE, color="g", ls=":", label="SI ~20 %")
    ax[2].axhline(ex["collapse_fraction_law"], color="b", ls="--", label="hardening law at sigma_n")
    ax[2].set(xlabel="shear strain", ylabel="axial strain (compaction +)", title="axial strain (SI Fig. 1 bottom)")
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, "snow_shear_test.png"), dpi=110)
    plt.close(fig)
    return out


def critical_case(h5dir: str, device: str, tau_p: float | None, lo: float = 0.0, hi: float = 0.4,
                  tol: float = 0.03) -> dict:
    """Critical cut length by bisection over coarse PST runs (pst_demo's resolution and geometry)."""
    runs = []

    def propagates(a: float) -> bool:
        a = max(a, 1e-3)
        speed = 4.0
        end = 0.1 + a / speed + 0.12  # settle, cut, then time for the crack to cross the column
        res = mw.run("pst_demo", device=device, overrides=[f"scene.saw.cut_length={a}", f"time.end={end}"])
        ex = res.scene_result
        runs.append({"cut_length": a, "propagated": ex["propagated"], "front_final": ex["front_final"],
                     "wall_time_s": res.wall_time})
        print(f"  critical cut: a = {a:.3f} m -> propagated {ex['propagated']}", flush=True)
        return bool(ex["propagated"])

    t0 = time.perf_counter()
    try:
        b = critical_cut_length(propagates, lo, hi, tol)
        a_c, bracket = b.value, [b.lo, b.hi]
    except ValueError as e:
        a_c, bracket = math.nan, [lo, hi]
        print(f"  critical cut: {e}", flush=True)
    formula = gaume_formula(tau_p)
    out = {"case": "critical_cut", "scene": "pst_demo", "environment": environment(device or "cpu"),
           "critical_cut_length": a_c, "bracket": bracket, "runs": runs, "tolerance": tol,
           "references": {"gaume2017_formula": formula, "tau_p_used": tau_p, "field_range": list(FIELD_CUT)},
           "relative_differences": {"vs_formula": _rel(a_c, formula)}, "total_wall_time_s": time.perf_counter() - t0}
    write_json("snow_critical_cut", out)
    return out


def gaume_formula(tau_p: float | None) -> float:
    """Gaume et al. (2017) flat-ground critical cut length (m) for pst_demo's layers and a shear strength (Pa)."""
    if not tau_p:
        return math.nan
    sc = load_scenario("pst_demo").scene
    G = sc.weak_layer.material(sc.sigma_n).mu
    return critical_cut_length_formula(tau_p, sc.slab.E, sc.slab.nu, sc.weak_layer_thickness, G, sc.slab.density)


def _refresh_critical_reference(summary: dict) -> None:
    """Fill the critical-cut formula once a shear test's peak strength is known (runs in any order)."""
    cc, sh = summary.get("critical_cut"), summary.get("shear_test")
    path = os.path.join(RESULTS, "snow_critical_cut.json")
    if not cc or not sh or not os.path.exists(path):
        return
    # same weak layer with p0_ini = 3 sigma_n: the strength scales with the slab load, so the shear
    # test's peak (pst_flat's slab) is scaled to pst_demo's slab
    scale = load_scenario("pst_demo").scene.sigma_n / sh["sigma_n"]
    tau_p = sh["peak_shear_stress"] * scale
    formula = gaume_formula(tau_p)
    data = json.load(open(path))
    data["references"].update(gaume2017_formula=formula, tau_p_used=tau_p,
                              tau_p_note="shear_test peak x sigma_n(pst_demo) / sigma_n(shear_test)")
    data["relative_differences"] = {"vs_formula": _rel(data["critical_cut_length"], formula)}
    write_json("snow_critical_cut", data)
    cc.update(data["references"], relative_differences=data["relative_differences"])


def summary_figure(summary: dict) -> None:
    """``snow_summary.png``: crack speed and touchdown of the PST runs (flat vs slope) against the references."""
    cases = [c for c in ("pst_demo", "pst_flat", "pst_slope") if c in summary]
    if not cases:
        return
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(12, 4))
    x = np.arange(len(cases))
    w = 0.2
    sp = [summary[c]["speed"] for c in cases]
    he = [summary[c]["heierli_speed_measured_collapse"] for c in cases]
    cr = [summary[c]["rayleigh_speed"] for c in cases]
    ax[0].bar(x - w, sp, w, color="k", label="run")
    ax[0].bar(x, he, w, color="tab:blue", label="Heierli (h_c of the run)")
    ax[0].bar(x + w, cr, w, color="tab:orange", label="Rayleigh c_R")
    ax[0].axhspan(*FIELD_SPEED, color="tab:green", alpha=0.3, label="field PST 20-30 m/s")
    ax[0].set_xticks(x, cases)
    ax[0].set(ylabel="crack speed (m/s)", title="crack speed: flat vs slope")
    ax[0].legend(fontsize=7)
    td = [summary[c]["touchdown"] for c in cases]
    ht = [summary[c]["heierli_touchdown_measured_collapse"] for c in cases]
    ax[1].bar(x - w / 2, td, w, color="k", label="run")
    ax[1].bar(x + w / 2, ht, w, color="tab:blue", label="Heierli (h_c of the run)")
    ax[1].axhline(FIELD_TOUCHDOWN, color="tab:green", label="field ~2.7 m")
    ax[1].set_xticks(x, cases)
    ax[1].set(ylabel="touchdown distance (m)", title="touchdown distance")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, "snow_summary.png"), dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="demo,flat,slope,shear,critical")
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--h5dir", default=None)
    ap.add_argument("--set", action="append", default=[], help="override for the PST scenes (key=value)")
    ap.add_argument("--reanalyze", action="store_true",
                    help="rebuild the shear test's results and figure from its stored curves (no run)")
    a = ap.parse_args(argv)
    h5dir = a.h5dir or tempfile.mkdtemp(prefix="snow_runs_")
    os.makedirs(h5dir, exist_ok=True)
    cases = a.cases.split(",")
    summary_path = os.path.join(RESULTS, "snow_summary.json")
    summary = json.load(open(summary_path)) if os.path.exists(summary_path) else {}
    for case, scene in (("demo", "pst_demo"), ("flat", "pst_flat"), ("slope", "pst_slope")):
        if case in cases:
            print(f"{scene} ...", flush=True)
            r = pst_case(scene, scene, h5dir, a.device, a.set)
            summary[scene] = {"speed": r["results"]["speed"], "touchdown": r["results"]["touchdown"],
                              "collapse_height": r["results"]["collapse_height"], **r["references"],
                              "relative_differences": r["relative_differences"],
                              "propagated": r["results"]["propagated"], "wall_time_s": r["total_wall_time_s"]}
            print(json.dumps(summary[scene], default=float), flush=True)
            json.dump(summary, open(summary_path, "w"), indent=1, default=float)
    if "shear" in cases:
        print("shear_test ...", flush=True)
        if a.reanalyze:
            r = shear_report(json.load(open(os.path.join(RESULTS, "snow_shear_test.json"))))
        else:
            r = shear_case(h5dir, a.device)
        summary["shear_test"] = {**r["results"], "relative_differences": r["relative_differences"],
                                 "wall_time_s": r["total_wall_time_s"]}
        print(json.dumps(summary["shear_test"], default=float), flush=True)
        json.dump(summary, open(summary_path, "w"), indent=1, default=float)
    if "critical" in cases:
        print("critical cut length ...", flush=True)
        tau_p = None  # filled in by _refresh_critical_reference once a shear test is known
        r = critical_case(h5dir, a.device, tau_p)
        summary["critical_cut"] = {"critical_cut_length": r["critical_cut_length"], "bracket": r["bracket"],
                                   **r["references"], "relative_differences": r["relative_differences"]}
        print(json.dumps(summary["critical_cut"], default=float), flush=True)
        json.dump(summary, open(summary_path, "w"), indent=1, default=float)
    _refresh_critical_reference(summary)
    json.dump(summary, open(summary_path, "w"), indent=1, default=float)
    summary_figure(summary)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
