"""Does the snowpack change the critical cut as weac says? Layering, and slope-normal against vertical column ends.

Bisections of :func:`mpm_warp.scenes.pst.critical_cut` (classes of each trial, weac's static answer beside
each, docs/weac.md) on the ladder PST of the snow studies (2.2 m column, 6 cm weak layer at 6 cells,
``mpm_warp.studies.snow.LADDER_PST``):

- ``layers_stiff_bottom`` / ``layers_stiff_top``: the same 0.3 m slab of 250 kg/m^3 in three 10 cm layers of
  E = 1, 5, 20 MPa top to bottom, and reversed: does the bisected cut move the way weac's does, and is each
  within 20 % of weac's value for its column?
- ``ends_<normal|vertical>_<downslope|upslope>``: a 0.5 m slab (250 kg/m^3, 5 MPa) on a 35 deg slope, the
  column's ends normal to the slope or vertical, the saw from the downslope or the upslope end: the ratio of
  the cuts with slope-normal and vertical ends beside Birkeland et al. (2025), who measured up to 50 %
  shorter critical cuts with slope-normal ends.

Writes ``results/snowpack_critical_cut.json`` (merged case by case) and ``snowpack_critical_cut.png``.

Usage::

    python benchmarks/snow/snowpack_critical_cut.py                      # every case (hours on 2 cores)
    python benchmarks/snow/snowpack_critical_cut.py layers_stiff_top     # one case
    python benchmarks/snow/snowpack_critical_cut.py --figure             # the figure again from the JSON
    python benchmarks/snow/snowpack_critical_cut.py --quick              # one bisection step, 1.2 m column
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import time

import mpm_warp as mw
from mpm_warp.finite_json import load_json
from mpm_warp.scenes.pst import critical_cut
from mpm_warp.scenes.snowpack import SnowLayer
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parse_cases, parser
from mpm_warp.studies.snow import ladder_pst

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
OUT = "snowpack_critical_cut"
LADDER = ladder_pst(0.01)
STIFF_BOTTOM = tuple(SnowLayer(0.1, 250.0, E, 0.3) for E in (1e6, 5e6, 20e6))
ENDS = LADDER + ["scene.slab_thickness=0.5", "scene.slope_angle=35"]
CASES = {
    "layers_stiff_bottom": (LADDER, STIFF_BOTTOM, dict(lo=0.2, hi=0.6, tol=0.01)),
    "layers_stiff_top": (LADDER, tuple(reversed(STIFF_BOTTOM)), dict(lo=0.2, hi=0.6, tol=0.01)),
    **{f"ends_{ends}_{end}": (ENDS + [f"scene.column_ends='{'slope_normal' if ends == 'normal' else 'vertical'}'",
                                      f"scene.saw.cut_from='{end}'"], None, dict(lo=0.1, hi=0.8, tol=0.02))
       for ends in ("normal", "vertical") for end in ("downslope", "upslope")},
}
QUICK = (LADDER + ["scene.length=1.2"], STIFF_BOTTOM, dict(lo=0.1, hi=0.5, tol=0.25))


def scenario(overrides, layers) -> mw.Scenario:
    """The ladder PST with the overrides and, given ``layers``, that layered slab."""
    sc = mw.load_scenario("pst_flat", overrides)
    if layers is None:
        return sc
    d = mw.scenes.pst.PSTParams()
    p = dataclasses.replace(sc.scene, slab=d.slab, slab_thickness=d.slab_thickness, slab_layers=tuple(layers))
    return mw.scenes.pst.build(p, sc.time, sc.output, name=sc.name, precision=sc.precision)


def run_case(name: str, device: str) -> dict:
    overrides, layers, bracket = QUICK if name == "quick" else CASES[name]
    sc = scenario(overrides, layers)
    t0 = time.perf_counter()
    res = critical_cut(sc, device=device, log=lambda s: print(f"{name}: {s}", flush=True), **bracket)
    p = sc.scene
    out = {"overrides": overrides, "slab_layers": [dataclasses.asdict(ly) for ly in p.slab_stack()],
           "bracket": bracket, "value": res.value, "lo": res.lo, "hi": res.hi, "bracketed": res.bracketed,
           "note": res.note, "classes": res.classes, "trials": res.trials, "weac": res.weac,
           "slope_angle": p.slope_angle, "cut_from": p.saw.cut_from, "column_ends": p.column_ends, "dx": p.dx,
           "wall_s": time.perf_counter() - t0, "environment": environment(device)}
    a_w = res.weac.get("critical_cut")
    if a_w and math.isfinite(res.value):
        out["relative_to_weac"] = res.value / a_w - 1.0
    print(f"{name}: critical cut in [{res.lo:.3f}, {res.hi:.3f}] m, weac {a_w}, classes {res.classes}", flush=True)
    return out


def derived(cases: dict) -> dict:
    """The checks: the layering's direction against weac's, and the slope-normal/vertical ratios."""
    out = {}
    a, b = cases.get("layers_stiff_bottom"), cases.get("layers_stiff_top")
    if a and b:
        mpm, weac = b["value"] - a["value"], b["weac"]["critical_cut"] - a["weac"]["critical_cut"]
        out["layering"] = {"stiff_top_minus_stiff_bottom": mpm, "weac_stiff_top_minus_stiff_bottom": weac,
                           "same_direction": bool(mpm * weac > 0),
                           "within_20_percent_of_weac": bool(all(abs(c.get("relative_to_weac", math.inf)) <= 0.2
                                                                 for c in (a, b)))}
    for end in ("downslope", "upslope"):
        n, v = cases.get(f"ends_normal_{end}"), cases.get(f"ends_vertical_{end}")
        if n and v:
            out[f"ends_ratio_{end}"] = {"mpm": n["value"] / v["value"],
                                        "weac": n["weac"]["critical_cut"] / v["weac"]["critical_cut"]}
    return out


def figure(data: dict, path: str) -> None:
    plt = pyplot()

    cases = data["cases"]
    fig, ax = plt.subplots(figsize=(9, 1.9 + 0.5 * len(cases)))
    for i, c in enumerate(cases.values()):
        for tr in c["trials"]:
            ax.plot(tr["cut"], i, "o" if tr["propagated"] else "x", color="C3" if tr["propagated"] else "C0", ms=6)
        ax.plot([c["lo"], c["hi"]], [i, i], "-", color="k", lw=3, alpha=0.4)
        if c["weac"].get("critical_cut"):
            ax.plot(c["weac"]["critical_cut"], i, "*", color="C2", ms=11, mfc="none")
    ax.set_yticks(range(len(cases)), list(cases))
    ax.set(xlabel="saw cut length [m]", title="critical cut of each column: the bisection's trials and weac")
    handles = [ax.plot([], [], "x", color="C0", ms=6)[0], ax.plot([], [], "o", color="C3", ms=6)[0],
               ax.plot([], [], "-", color="k", lw=3, alpha=0.4)[0],
               ax.plot([], [], "*", color="C2", ms=11, mfc="none")[0]]
    ax.legend(handles, ["arrested", "propagated", "bracket", "weac (energy criterion, G = w_f)"], loc="upper center",
              bbox_to_anchor=(0.5, -0.16), ncols=4, fontsize=8, frameon=False)
    save_figure(fig, path)


def load(folder: str) -> dict:
    path = os.path.join(folder, OUT + ".json")
    if os.path.isfile(path):
        with open(path) as fh:
            return load_json(fh)
    return {"cases": {}}


def main(argv=None) -> int:
    ap = parser(__doc__, "the layered ladder PST on a 1.2 m column, bisected once")
    ap.add_argument("--figure", action="store_true", help="only redraw the figure from the JSON")
    a = parse_cases(ap, argv, CASES)
    folder = out_dir(a, RESULTS, OUT) if not a.figure else (a.out or RESULTS)
    if a.figure:
        figure(load(folder), os.path.join(folder, OUT + ".png"))
        return 0
    for name in (["quick"] if a.quick else (a.cases or list(CASES))):
        case = run_case(name, a.device)
        data = load(folder)
        data["cases"][name] = case
        data["checks"] = derived(data["cases"])
        print("wrote", write_json(OUT, data, folder), flush=True)
        figure(data, os.path.join(folder, OUT + ".png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
