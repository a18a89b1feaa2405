"""Critical cut length of the PST by bisection on the saw's stop position.

Each case bisects :func:`mpm_warp.scenes.pst.critical_cut` on a PST column (trial runs forked from
one base run, :mod:`mpm_warp.scenes.pst.critical`) and writes ``benchmarks/snow/results/snow_critical_cut.json``
(one entry per case, merged into what is there) and ``snow_critical_cut.png`` (the trials: cut
against outcome, with the bracket, beside Gaume et al. 2017's formula and weac's static critical cut):

- ``flat``: ``pst_flat`` on a 3 m column;
- ``flat_closure``: ``flat`` with the laminate closure at the layers' interfaces (``scene.interface_closure``,
  docs/model.md §5b);
- ``slope``: ``pst_slope`` (30 deg) on a 3 m column;
- ``flat_saw_half``: ``flat`` with the saw at half speed (0.5 m/s);
- ``ladder_saw_half``: the PST of the error-against-run-time ladder at 6 cells across its layer
  (``benchmarks/convergence/error_vs_runtime_snow.py``, level 1, whose critical cut is the reference) with the saw
  at half speed: the saw-speed check at a tenth of ``flat_saw_half``'s cost. The dx-halving check is
  that ladder's next level.
- ``ladder_slope``: that PST on a 30 deg slope (``pst_slope``'s angle), the saw cutting from the
  upslope end (the crack runs downslope);
- ``ladder_slope_cut_downslope_end``: the same with the saw cutting from the downslope end
  (``saw.cut_from = "downslope"``): the crack runs upslope.

Usage::

    nohup .venv/bin/python benchmarks/snow/critical_cut.py flat slope ladder_saw_half ladder_slope > cut.log 2>&1 &
    .venv/bin/python benchmarks/snow/critical_cut.py     # no case: the figure again from the JSON files
    .venv/bin/python benchmarks/snow/critical_cut.py --quick     # one bisection step, to a temporary folder
"""

from __future__ import annotations

import math
import os
import sys
import time

import mpm_warp as mw
from mpm_warp.finite_json import load_json
from mpm_warp.scenes.pst import critical_cut
from mpm_warp.scenes.pst.static import weac_answer
from mpm_warp.scenes.weak_layer import stored_calibration
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parse_cases, parser
from mpm_warp.studies.snow import FIELD_CUT, ladder_pst

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
#: the error ladder's results (benchmarks/convergence/): its PST's own bisections are the ladder cases' references
LADDER_RESULTS = os.path.join(os.path.dirname(HERE), "convergence", "results")
#: the column of the bisections: 3 m leaves 1 m of run beyond a 0.8 m cut and the slab's end zone
COLUMN = ["scene.length=3.0", "scene.marker_spacing=0.1"]
#: the PST of the error-against-run-time ladder at its level 1 (dx 10 mm, 6 cells across a 6 cm layer)
LADDER = ladder_pst(0.01)
CASES = {
    "flat": ("pst_flat", COLUMN, dict(lo=0.1, hi=0.8, tol=0.02)),
    "flat_closure": ("pst_flat", COLUMN + ["scene.interface_closure=true"], dict(lo=0.1, hi=0.8, tol=0.02)),
    "slope": ("pst_slope", COLUMN, dict(lo=0.05, hi=0.8, tol=0.02)),
    "flat_saw_half": ("pst_flat", COLUMN + ["scene.saw.speed=0.5"], dict(lo=0.1, hi=0.8, tol=0.02)),
    "ladder_saw_half": ("pst_flat", LADDER + ["scene.saw.speed=0.5"], dict(lo=0.1, hi=0.7, tol=0.02)),
    "ladder_slope": ("pst_slope", LADDER, dict(lo=0.05, hi=0.7, tol=0.02)),
    "ladder_slope_cut_downslope_end": ("pst_slope", LADDER + ["scene.saw.cut_from='downslope'"],
                                       dict(lo=0.05, hi=0.7, tol=0.02)),
}
#: --quick: the ladder PST on a 1.2 m column bisected once (bracket [0.1, 0.5] m to 0.25 m: the base run, 2 trials)
QUICK = ("pst_flat", LADDER + ["scene.length=1.2"], dict(lo=0.1, hi=0.5, tol=0.25))
OUT = "snow_critical_cut"


def _plt():
    plt = pyplot()

    return plt


def load(folder: str) -> dict:
    path = os.path.join(folder, OUT + ".json")
    if os.path.isfile(path):
        with open(path) as fh:
            data = load_json(fh)
        if isinstance(data.get("cases"), dict):
            return data
    return {"cases": {}}


def ladder_rows() -> dict:
    """The ladder PST's own bisections (``error_vs_runtime_snow.json``): the references of the ``ladder_*`` cases."""
    path = os.path.join(LADDER_RESULTS, "error_vs_runtime_snow.json")
    if not os.path.isfile(path):
        return {}
    with open(path) as fh:
        levels = load_json(fh)["ladders"]["pst"]
    out = {}
    for lv in levels:
        if lv["precision"] == "float32" and lv.get("bracketed"):
            lo, hi = lv["critical_cut_bracket"]
            sc = mw.load_scenario("pst_flat", ladder_pst(lv["dx"]))
            label = f"ladder, dx {1e3 * lv['dx']:g} mm (error ladder)"
            if lv.get("bisection", {}).get("narrowed_from"):
                label = label[:-1] + ", narrowed)"
            out[label] = {"trials": lv["trials"], "lo": lo, "hi": hi,
                          "gaume": sc.scene.references(stored_calibration(sc)).get("critical_cut_gaume"),
                          "weac": weac_cut(sc)}
    return out


def weac_cut(sc) -> float | None:
    """weac's static critical cut (m) of the scenario's column (:mod:`mpm_warp.scenes.pst.static`), or None."""
    answer = weac_answer(sc.scene, stored_calibration(sc))
    return answer.get("critical_cut")


def case_weac(c: dict) -> float | None:
    """A case's weac critical cut: stored with it, else computed for its column (older JSON, whose slope sign
    still named the saw's end: a negative angle was the cut from the downslope end)."""
    if "weac" not in c and "scene" in c:
        c = {**c, "overrides": [o.replace("scene.slope_angle=-30.0", "scene.saw.cut_from='downslope'")
                                for o in c["overrides"]]}
        c["weac"] = weac_cut(mw.load_scenario(c["scene"], c["overrides"]))
    w = c.get("weac")
    return w.get("critical_cut") if isinstance(w, dict) else w


def figure(data: dict, path: str) -> None:
    """Every case's trials (and the ladder PST's own bisections, its references), bracket and Gaume's value."""
    plt = _plt()
    cases = {**ladder_rows(), **data["cases"]}
    fig, ax = plt.subplots(figsize=(9, 2.0 + 0.55 * len(cases)))
    for i, c in enumerate(cases.values()):
        for tr in c["trials"]:
            ax.plot(tr["cut"], i, "o" if tr["propagated"] else "x", color="C3" if tr["propagated"] else "C0", ms=7)
        ax.plot([c["lo"], c["hi"]], [i, i], "-", color="k", lw=3, alpha=0.4)
        if c.get("gaume") is not None:
            ax.plot(c["gaume"], i, "D", color="C2", ms=7, mfc="none")
        w = case_weac(c)
        if w is not None:
            ax.plot(w, i, "*", color="C1", ms=11)
    ax.axvspan(*FIELD_CUT, color="0.9", zorder=0)
    labels = {"flat": "pst_flat (3 m column, 4 cells)", "flat_closure": "pst_flat, interface closure",
              "slope": "pst_slope (3 m column, 4 cells)",
              "flat_saw_half": "pst_flat, saw 0.5 m/s", "ladder_saw_half": "ladder, saw 0.5 m/s",
              "ladder_slope": "ladder, 30 deg, cut from the upslope end",
              "ladder_slope_cut_downslope_end": "ladder, 30 deg, cut from the downslope end"}
    ax.set_yticks(range(len(cases)), [labels.get(k, k) for k in cases])
    ax.set(xlabel="saw cut length [m]", title="PST critical cut: the bisections' trials and brackets")
    key = [ax.plot([], [], "x", color="C0", ms=7, label="trial: arrested")[0],
           ax.plot([], [], "o", color="C3", ms=7, label="trial: propagated")[0],
           ax.plot([], [], "-", color="k", lw=3, alpha=0.4, label="bracket")[0],
           ax.plot([], [], "*", color="C1", ms=11, label="weac (static, G = w_f)")[0],
           ax.plot([], [], "D", color="C2", ms=7, mfc="none", label="Gaume et al. 2017 (flat formula)")[0]]
    ax.legend(handles=key, loc="upper center", bbox_to_anchor=(0.5, -0.12 - 0.3 / len(cases)), ncol=3,
              fontsize=8, frameon=False, title=f"grey: the field's {FIELD_CUT[0]:g}-{FIELD_CUT[1]:g} m",
              title_fontsize=8)
    save_figure(fig, path)


def reference(name: str, data: dict) -> float | None:
    """The critical cut at full saw speed (m): the ``flat`` case, or the ladder's level 1 (float32)."""
    if name == "flat":
        return data["cases"].get("flat", {}).get("value")
    path = os.path.join(LADDER_RESULTS, "error_vs_runtime_snow.json")
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        levels = load_json(fh)["ladders"]["pst"]
    hit = [lv for lv in levels if lv.get("level") == 1 and lv["precision"] == "float32"]
    return hit[0]["critical_cut"] if hit else None


def run_case(name: str, data: dict, device: str) -> dict:
    scene, overrides, bracket = QUICK if name == "quick" else CASES[name]
    sc = mw.load_scenario(scene, overrides)
    t0 = time.perf_counter()
    res = critical_cut(sc, device=device, log=lambda s: print(f"{name}: {s}", flush=True), **bracket)
    wall = time.perf_counter() - t0
    refs = sc.scene.references(stored_calibration(sc))
    out = {"scene": scene, "overrides": overrides, "bracket": bracket, "value": res.value, "bracketed": res.bracketed,
           "note": res.note, "lo": res.lo,
           "hi": res.hi, "trials": res.trials, "runaway_cut_of_base": res.runaway_cut, "wall_s": wall,
           "dx": sc.scene.dx, "saw_speed": sc.scene.saw.speed, "slope_angle": sc.scene.slope_angle,
           "gaume": refs.get("critical_cut_gaume"),
           "weac": res.weac, "classes": res.classes,
           "base_speed_mean": res.base.get("damage_speed_mean"), "base_propagated": res.base.get("propagated"),
           "environment": environment(device)}
    print(f"{name}: critical cut in [{res.lo:.3f}, {res.hi:.3f}] m ({wall:.0f} s) {res.note}", flush=True)
    return out


def main(argv=None) -> int:
    ap = parser(__doc__, "the ladder PST at 6 cells on a 1.2 m column, bisected once: a base run and two trials")
    a = parse_cases(ap, argv, CASES, "none: redraw the figure")
    if a.quick:
        a.cases = ["quick"]
    folder = (a.out or RESULTS) if not a.cases else out_dir(a, RESULTS, "critical_cut")
    data = load(folder)
    if not a.cases:                   # the figure again, from the JSON files as they are
        figure(data, os.path.join(folder, OUT + ".png"))
        return 0
    for name in a.cases:
        case = run_case(name, data, a.device)
        data = load(folder)           # merged into what is there now: another process may have written a case
        data["cases"][name] = case
        for other, ref in (("flat_saw_half", reference("flat", data)), ("ladder_saw_half", reference("ladder", data))):
            if other in data["cases"] and ref is not None and math.isfinite(ref):
                data["cases"][other]["reference_value"] = ref
                data["cases"][other]["change_from_reference"] = data["cases"][other]["value"] / ref - 1.0
        print("wrote", write_json(OUT, data, folder), flush=True)
        figure(data, os.path.join(folder, OUT + ".png"))
    return 0 if all(math.isfinite(c["value"]) for c in data["cases"].values()) else 1


if __name__ == "__main__":
    sys.exit(main())
