"""How much load do the rows next to a stiffness jump carry, with and without the laminate closure?

The settled column (:mod:`mpm_warp.studies.interface_column`: ``pst_demo``'s substratum, 3 cm weak layer and
slab between slip walls, settled as the PST settles) at 3, 4, 6, 12 and 24 cells across the layer: each
particle row's ``sigma_yy`` beside the overburden at its height, without and with ``scene.interface_closure``
(docs/model.md §5b). The other parts, each without and with the closure: ``model1d``, the same column as a 1D
static problem (:mod:`mpm_warp.studies.interface_model1d`; also B-bar-like averaging per cell and layer);
``free``, ``pst_demo`` itself settled (free ends), the particle column at x = 2.1 m; ``pst``, ``pst_demo``
running, the rows 0.1 m ahead of its damage front once it has passed 1.2 m (the saw stops at 0.6 m);
``shear``, the shear test's peak against the given tau_p at 4 and 8 cells (and at 4 on a sample twice as
long); ``cost``, CPU time per particle-step of ``pst_demo`` while settling; ``ladder`` (not by default), the PST
ladder's two coarsest levels (``pst_flat`` as the error ladder runs it). Parts run apart are merged into the
file. Writes ``benchmarks/snow/results/interface_stress_<dev>.json`` and ``.png`` (sigma_yy / overburden per
row against the height above the layer's base).

Usage::

    .venv/bin/python benchmarks/snow/interface_stress.py [--parts column model1d free pst shear cost ladder] [--quick]
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.finite_json import load_json
from mpm_warp.scenes.pst import critical_cut
from mpm_warp.scenes.shear_test import shear_curves
from mpm_warp.studies import interface_model1d
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.interface_column import column_rows, free_column_rows, running_rows, step_cost
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.snow import PST_BRACKET, PST_DX, ladder_pst

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
CELLS = (3, 4, 6, 12, 24)
SHEAR_CELLS = (4, 8)
PARTS = ("column", "model1d", "free", "pst", "shear", "cost", "ladder")
#: the running PST: the rows this far (m) ahead of the damage front, once it has passed this (m) from the cut end
PST_AHEAD, PST_FRONT = 0.1, 1.2
#: the PST ladder's two coarsest levels (3 and 6 cells across its 6 cm layer)
LADDER_DX = PST_DX[:2]
ON = "scene.interface_closure=true"


def _slim(r: dict) -> dict:
    return {k: v for k, v in r.items() if k != "rows"}


def column_part(cells, device: str) -> dict:
    out = {}
    for label, over in (("off", ()), ("on", (ON,))):
        out[label] = [_slim(column_rows(c, overrides=over, device=device)) for c in cells]
    out["cost_ratio_on_over_off"] = [b["s_per_particle_step"] / a["s_per_particle_step"]
                                     for a, b in zip(out["off"], out["on"], strict=True)]
    return out


def model1d_part(cells) -> dict:
    out = {}
    for scheme in interface_model1d.SCHEMES:
        runs = []
        for c in cells:
            r = interface_model1d.static_rows(c, scheme)
            k = r["near"]
            runs.append({"cells": float(c), "dx": r["dx"], "worst": r["worst"],
                         "zero_energy_modes": r["zero_energy_modes"], "y0": r["y"][k].tolist(),
                         "ratio": r["ratio"][k].tolist()})
        out[scheme] = runs
    return out


def cost_part(device: str, rounds: int = 3) -> dict:
    """pst_demo's step without and with the closure, alternated ``rounds`` times (the best of each)."""
    runs = {"off": [], "on": []}
    for _ in range(rounds):
        for label, over in (("off", ()), ("on", (ON,))):
            runs[label].append(step_cost("pst_demo", over, device=device))
    best = {k: min(r["s_per_particle_step"] for r in v) for k, v in runs.items()}
    return {**runs, "best_s_per_particle_step": best, "ratio_on_over_off": best["on"] / best["off"]}


def ladder_part(device: str) -> dict:
    """The PST ladder's two coarsest levels without and with the closure: critical cut, speed, touchdown, collapse
    height (as ``benchmarks/convergence/error_vs_runtime_snow.py`` runs a level)."""
    out = {}
    for label, over in (("off", []), ("on", [ON])):
        levels = []
        for dx in LADDER_DX:
            sc = mw.load_scenario("pst_flat", ladder_pst(dx) + over)
            t0 = time.perf_counter()
            res = critical_cut(sc, device=device, base_run_distance=sc.scene.length, base_free_run=0.5,
                               **PST_BRACKET, workers=1, n_threads=1)
            b = res.base
            levels.append({"dx": dx, "cells_across_layer": sc.scene.weak_layer_thickness / dx,
                           "critical_cut": res.value if res.bracketed else float("nan"),
                           "critical_cut_bracket": [res.lo, res.hi], "bracketed": res.bracketed,
                           "speed": b.get("damage_speed_mean"), "touchdown": b.get("touchdown"),
                           "collapse_height": b.get("collapse_height"), "wall_s": time.perf_counter() - t0,
                           "steps": int(sum(t["steps"] for t in res.trials))})
        out[label] = levels
    return out


def pst_part(device: str) -> dict:
    return {label: _slim(running_rows("pst_demo", over, ahead=PST_AHEAD, min_front=PST_FRONT, device=device))
            for label, over in (("off", ()), ("on", (ON,)))}


def free_part(device: str) -> dict:
    return {label: _slim(free_column_rows(overrides=over, device=device))
            for label, over in (("off", ()), ("on", (ON,)))}


def shear_part(cells, device: str) -> dict:
    """The shear test at ``cells`` and, at the first, on a sample of twice the length (its free ends' share)."""
    out = {}
    base = mw.load_scenario("shear_test").scene
    cases = [(n, base.sample_length) for n in cells] + [(cells[0], 2.0 * base.sample_length)]
    for label, over in (("off", []), ("on", [ON])):
        runs = []
        for n, Ls in cases:
            dx = base.weak_layer_thickness / n
            t0 = time.perf_counter()
            rr = mw.run("shear_test", device=device, overrides=[f"scene.dx={dx!r}", f"scene.sample_length={Ls!r}",
                                                                 *over])
            mon = rr.monitor
            c = shear_curves(mon.params, mon.times, {k: np.asarray(v) for k, v in mon.series.items()})
            res = rr.scene_result
            runs.append({"cells": n, "dx": dx, "sample_length": Ls, "wall_s": time.perf_counter() - t0,
                         "steps": rr.steps,
                         "peak_shear_stress": res["peak_shear_stress"], "tau_p": res["tau_p_calibrated"],
                         "peak_over_tau_p": res["peak_shear_stress"] / res["tau_p_calibrated"],
                         "residual_shear_stress": res["residual_shear_stress"],
                         "softening_displacement": res["softening_displacement"],
                         "tau_curve": {k: np.asarray(c[k])[::10].tolist() for k in ("slip", "tau")}})
        out[label] = runs
    return out


def figure(data: dict, path: str) -> None:
    plt = pyplot()

    col = data["column"]
    fig, ax = plt.subplots(1, 2, figsize=(12, 5), sharey=True)
    for a, label in zip(ax, ("off", "on"), strict=True):
        for k, r in enumerate(col[label]):
            base = data["substratum_depth"]
            h = [(x["y0"] - base) / data["weak_layer_thickness"] for x in r["near"]]
            a.plot([x["ratio"] for x in r["near"]], h, "o-", ms=3, color=f"C{k}",
                   label=f"{r['cells']:g} cells (dx {1e3 * r['dx']:.3g} mm): worst {100 * r['worst']:.1f} %")
        a.axvline(1.0, color="k", lw=0.8)
        a.axvspan(0.95, 1.05, color="0.9", zorder=0)
        for y in (0.0, 1.0):
            a.axhline(y, color="0.5", ls=":", lw=0.8)
        a.set(xlabel="sigma_yy / overburden per particle row [-]",
              title=f"interface closure {label}" + (" (plain MLS-MPM)" if label == "off" else " (laminate)"))
        a.legend(fontsize=7)
    ax[0].set_ylabel("height above the weak layer's base / its thickness [-]")
    fig.suptitle("settled column (pst_demo's stack between slip walls): rows within 3 cells of the weak layer; "
                 "grey band: 5 %", fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "the column at 3 and 4 cells only")
    ap.add_argument("--parts", nargs="+", default=[p for p in PARTS if p != "ladder"], choices=list(PARTS),
                    help="parts to run (default all but ladder, about 12 min of CPU more)")
    a = ap.parse_args(argv)
    cells = (3, 4) if a.quick else CELLS
    parts = ["column", "model1d"] if a.quick else a.parts
    sc = mw.load_scenario("pst_demo")
    data = {"scenario": "pst_demo", "weak_layer_thickness": sc.scene.weak_layer_thickness,
            "substratum_depth": sc.scene.substratum_depth, "tolerance": 0.05}
    folder = out_dir(a, RESULTS, "interface_stress")
    name = result_name("interface_stress", a)
    old = os.path.join(folder, name + ".json")
    if os.path.exists(old):  # parts run apart: keep the others
        with open(old) as f:
            data = {**load_json(f), **data}
    run = {"column": lambda: column_part(cells, a.device), "model1d": lambda: model1d_part(cells),
           "free": lambda: free_part(a.device), "shear": lambda: shear_part(SHEAR_CELLS, a.device),
           "cost": lambda: cost_part(a.device), "ladder": lambda: ladder_part(a.device),
           "pst": lambda: pst_part(a.device)}
    for part in parts:
        t0 = time.perf_counter()
        data[part] = run[part]()
        data[part]["part_wall_s"] = time.perf_counter() - t0
        data[part]["environment"] = environment(a.device)
    data["environment"] = environment(a.device)
    print("wrote", write_json(name, data, folder))
    if "column" in data:
        figure(data, os.path.join(folder, name + ".png"))
        for label in ("off", "on"):
            for r in data["column"][label]:
                print(f"closure {label}, {r['cells']:g} cells: worst row {100 * r['worst']:.2f} % off the overburden, "
                      f"{r['wall_s']:.1f} s")
    for scheme, runs in ((k, v) for k, v in (data.get("model1d") or {}).items() if k in interface_model1d.SCHEMES):
        print(f"1D static, {scheme}: worst row " + ", ".join(f"{100 * r['worst']:.2f} %" for r in runs))
    for label, levels in ((k, v) for k, v in (data.get("ladder") or {}).items() if k in ("off", "on")):
        for r in levels:
            print(f"PST ladder, closure {label}, dx {r['dx']}: critical cut {r['critical_cut']}, speed {r['speed']}, "
                  f"touchdown {r['touchdown']}, collapse height {r['collapse_height']}, {r['wall_s']:.0f} s")
    if "cost" in data:
        print(f"cost per particle-step, closure on / off: {data['cost']['ratio_on_over_off']:.3f}")
    for label, runs in ((k, v) for k, v in (data.get("shear") or {}).items() if k in ("off", "on")):
        for r in runs:
            print(f"shear test, closure {label}, {r['cells']} cells, sample {r.get('sample_length')} m: peak / tau_p = "
                  f"{r['peak_over_tau_p']:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
