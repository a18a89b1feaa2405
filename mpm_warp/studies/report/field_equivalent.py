"""The equivalent weak layer against the thin layer resolved, on one field column run by the field protocol
(benchmarks/field/equivalent_layer.py)."""

from __future__ import annotations

from .core import section
from .fmt import check_line, env_note, fx, table

#: the runs in the order the table lists them, and what each is
RUNS = {"resolved": "the thin layer resolved", "equivalent_4_cells": "its equivalent layer, 4 cells",
        "equivalent_3_cells": "its equivalent layer, 3 cells",
        "control_plain_4_cells": "control: the layer plainly thickened, 4 cells"}


def _pct(v) -> str:
    return "-" if v is None else f"{100 * v:+.2f} %"


@section("field", "The equivalent weak layer against the thin layer resolved",
         "field/results/field_equivalent_layer.json", lambda d: "python benchmarks/field/equivalent_layer.py",
         question="A thin weak layer over the budget's grid runs as a thicker equivalent layer with its fracture "
                  "energy, strength, collapse height and stiffness per unit area. Does the column run as it does "
                  "with the thin layer resolved?",
         follows="Field outcomes against the observers")
def render_equivalent(data: dict, ctx) -> list[str]:
    col, tol, checks = data["column"], data["tolerances"], data["checks"]
    runs = {r["label"]: r for r in data["runs"]}
    rows = []
    for key, what in RUNS.items():
        r, c = runs.get(key), checks.get(key, {})
        if r is None:
            continue
        rows.append([what, r["predicted"], fx(r["runaway_cut"], 3), _pct(c.get("runaway_cut_change")),
                     fx(r["speed"], 1), _pct(c.get("speed_change")), _pct(c.get("weac_cut_change")),
                     f"{r['particles']:,}", fx(r["wall_s"], 0)])
    out = [f"A {col['length_cm']} cm column, {col['slab_cm']} cm of slab over a {col['weak_layer_cm']} cm weak "
           f"layer (w_f {col['w_f']:g} J/m^2, slope {col['slope_deg']:g} deg), by the field protocol. Changes "
           "against the resolved run.", ""]
    out += table(["run", "class", "runaway cut (m)", "change", "front speed (m/s)", "change", "weac's cut change",
                  "particles", "wall (s)"], rows)
    eq = [k for k in ("equivalent_4_cells", "equivalent_3_cells") if k in checks]
    ok = all(checks[k]["same_class"] and checks[k]["cut_within"] and checks[k]["speed_within"] for k in eq)
    worst = max((abs(checks[k]["runaway_cut_change"]) for k in eq), default=None)
    out += ["", check_line("the equivalent layer runs as the thin layer resolved",
                           f"the same class, the runaway cut within {tol['runaway_cut']:.0%} and the front speed "
                           f"within {tol['speed']:.0%}", ok if eq else None,
                           f"runaway cut within {_pct(worst)}"), "", env_note(data)]
    return out
