"""Does an equivalent weak layer run as the thin layer it stands for? One field column, resolved and equivalent.

A field column whose weak layer is too thin for the per-case budget runs with an equivalent layer: thicker, with the
real layer's fracture energy, shear strength, collapse height and stiffness per unit area (``mpm_warp.field.
equivalent_layer``, docs/field.md). This study runs one column of a table row (flat, a 25 cm slab of 200 kg/m^3
over a 2 cm weak layer, 1 m long) by the field protocol (rigid base, pre-cut half weac's critical cut, the saw
stopping at the runaway) three ways: (a) resolved, its own 2 cm layer at 4 cells (dx 5 mm, the default budget);
(b) under a budget that forces the equivalence at the protocol's 4 cells (the 4 cm layer, dx 10 mm); (c) the
same at 3 cells (the 3 cm layer, dx 10 mm); and, as a control that the comparison can tell layers apart, (d) the
layer plainly thickened to 4 cm (its own E and weac's collapse fit of 4 cm, so half the stiffness per unit area),
pre-cut as the real column. Per run: the outcome class, the runaway cut, the damage front's mean
speed, the particles and the wall time; and weac's critical cut of each column.

The checks are the snow ladders' for a grid change (docs/results/field.md, "The grid"; docs/results/convergence.md,
"the snow ladders"): the same class, and the runaway cut within 10 % (twice the ladder's critical-cut error at
6 cells); the front speed within 27 % (twice the ladder's crack-speed error at 6 cells, the same rule), beside the
ladder's own speed change over this very step of the grid (dx 10 mm to 5 mm: +10.7 %).

Usage: ``python benchmarks/field/equivalent_layer.py``; ``--quick``: the same on a 60 cm column with a 20 cm slab,
to a temporary folder (about 3 min; that column does not run away, NP in all four runs: it checks the script, not
the equivalence; None where a run has no runaway cut or speed).
Writes ``benchmarks/field/results/field_equivalent_layer.json``.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import time
import warnings

from mpm_warp.field.batch import case_scenario, gather
from mpm_warp.field.equivalent_layer import column_particles
from mpm_warp.field.protocol import FieldProtocol, protocol_column, protocol_equivalent, run_to_decision
from mpm_warp.field.static_view import static_view
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
HEAD = "id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends\n"
#: (column cm, slab cm, weak layer cm, fracture energy J/m^2): the study's column and the quick one
COLUMNS = {"full": (100, 25, 2, 0.3), "quick": (60, 20, 2, 0.3)}
#: the snow ladders' tolerances for a grid change (docs/results/field.md and convergence.md)
CUT_TOL, SPEED_TOL, LADDER_SPEED_STEP = 0.10, 2 * 0.134, 0.107


def _plain(case, thickness: float, proto: FieldProtocol):
    """The control: the column with its layer plainly thickened to ``thickness`` (m), E and the collapse fit its
    own, pre-cut as the real column (weac's critical cut of the real one): ``(scenario, note)``."""
    from mpm_warp.field.protocol import protocol_params
    from mpm_warp.scenes.pst import build

    thick = dataclasses.replace(case.params, weak_layer_thickness=thickness)
    p, tc, note = protocol_params(thick, proto, static_view(case.params).critical_cut)
    return build(p, tc, name="field"), f"plainly {thickness * 100:.2f} cm, {note}"


def _run(case, proto: FieldProtocol, work: str, label: str, device: str, plain: float | None = None) -> dict:
    scenario, note = case_scenario(case, proto) if plain is None else _plain(case, plain, proto)
    if scenario is None:
        return {"label": label, "status": "refused", "setup": note}
    p = scenario.scene
    t0 = time.perf_counter()
    res, _ = run_to_decision(scenario, os.path.join(work, f"{label}.h5"), device=device, n_threads=1)
    sr = res.scene_result
    eq = protocol_equivalent(case.params, proto) if plain is None else None
    row = {"label": label, "status": "ok", "setup": note, "weak_layer_thickness": p.weak_layer_thickness,
           "weak_layer_E": p.weak_layer.E, "dx": p.dx, "cells": round(p.weak_layer_thickness / p.dx),
           "equivalent": eq.key() if eq is not None else None, "max_particles": proto.max_particles,
           "predicted": sr.get("outcome", {}).get("class"), "runaway_cut": sr.get("runaway_cut"),
           "speed": sr.get("speed"), "collapse_height": sr.get("collapse_height"), "pre_cut": p.saw.pre_cut,
           "particles": res.n_particles, "steps": res.steps, "sim_time": res.sim_time,
           "wall_s": time.perf_counter() - t0,
           "weac_critical_cut": wr.critical_cut(static_column(p), case.params.weak_layer.w_f)}
    print(f"{label}: {row['predicted']}, runaway cut {row['runaway_cut']}, speed {row['speed']}, "
          f"{row['particles']} particles, {row['wall_s']:.0f} s ({note})", flush=True)
    return row


def _rel(a, b):
    """``(a - b) / b``; None where either is missing (no runaway: nan or None)."""
    ok = all(v is not None and v == v for v in (a, b)) and b
    return (a - b) / b if ok else None


def checks(runs: list[dict]) -> dict:
    """Each equivalent run against the resolved one, by the ladders' tolerances."""
    ref, out = runs[0], {}
    for r in runs[1:]:
        if r["status"] != "ok" or ref["status"] != "ok":
            out[r["label"]] = {"status": "not run"}
            continue
        cut, speed = _rel(r["runaway_cut"], ref["runaway_cut"]), _rel(r["speed"], ref["speed"])
        out[r["label"]] = {"same_class": r["predicted"] == ref["predicted"], "runaway_cut_change": cut,
                           "cut_within": None if cut is None else abs(cut) <= CUT_TOL, "speed_change": speed,
                           "speed_within": None if speed is None else abs(speed) <= SPEED_TOL,
                           "speed_within_ladder_step": None if speed is None else abs(speed) <= LADDER_SPEED_STEP,
                           "weac_cut_change": _rel(r["weac_critical_cut"], ref["weac_critical_cut"])}
    return out


def main(argv=None) -> int:
    p = parser(__doc__, "a 60 cm column with a 20 cm slab")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    col_cm, slab_cm, wl_cm, w_f = COLUMNS["quick" if args.quick else "full"]
    dest = out_dir(args, RESULTS, "field_equivalent_layer")
    with tempfile.TemporaryDirectory() as work:
        table = os.path.join(work, "column.csv")
        with open(table, "w") as fh:
            fh.write(HEAD + f"thin,End,0,{col_cm},{col_cm // 3},{slab_cm},200,{wl_cm},,{w_f},\n")
        (case,), _ = gather([table], calibrate=False)
        t = case.params.weak_layer_thickness
        rigid = protocol_column(case.params, FieldProtocol())     # budgets whose thinnest layers are 2 t and 1.5 t
        protos = {"resolved": FieldProtocol(),
                  "equivalent_4_cells": FieldProtocol(max_particles=column_particles(rigid, 2 * t, 4)),
                  "equivalent_3_cells": FieldProtocol(cells_across=3,
                                                      max_particles=column_particles(rigid, 1.5 * t, 3))}
        runs = [_run(case, proto, work, label, args.device or "cpu") for label, proto in protos.items()]
        runs.append(_run(case, FieldProtocol(), work, "control_plain_4_cells", args.device or "cpu", plain=2 * t))
    data = {"name": "field_equivalent_layer", "column": {"length_cm": col_cm, "slab_cm": slab_cm,
                                                         "weak_layer_cm": wl_cm, "w_f": w_f, "slope_deg": 0},
            "weac_critical_cut_real": static_view(case.params).critical_cut,
            "tolerances": {"runaway_cut": CUT_TOL, "speed": SPEED_TOL, "ladder_speed_step": LADDER_SPEED_STEP},
            "environment": environment(args.device or "cpu"), "runs": runs, "checks": checks(runs)}
    path = write_json("field_equivalent_layer", data, dest)
    for label, c in data["checks"].items():
        print(f"{label}: {c}")
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
