"""Is a field run's slab stress, or weac's, nearer a resolved continuum? A static plane-strain FE of the same columns.

For every case of the slab-stress studies (``slab_stress.py``'s JSONs: the SF records the model called END, a
sample of END records), the column the run used (its checkpoint's scenario, as weac sees it: each layer's E, the
weak layer's E, the slope, the ends) is solved statically at the crack's onset cut by a 9-node plane-strain FE
(``mpm_warp.validation.column_fe``) that resolves every slab layer, at two meshes (1 cm and 5 mm elements, two
at least through every layer). Per case: the slab's largest principal stress over its layer's strength, away
from the corner where the sawn weak layer ends and from the end faces (within ``CORNER_M`` of them linear
elasticity is singular; that zone's value is given apart), where it sits, and beside it weac's
(over the cut and at the tip) and the run's up to the onset (its whole slab, edges included). The homogeneous
control (20 cm of 120 kg/m^3, flat) is solved at the same cuts as ``slab_stress.py``'s. Static: no saw, no
dynamics, no damage. Writes ``benchmarks/field/results/field_slab_fe.json``.

Usage: ``python benchmarks/field/slab_fe.py RUNDIR [RUNDIR ...] [--studies JSON ...]``; ``--quick``: the control
at one cut and the first case, coarse, to a temporary folder. Seconds to a minute a case.
"""

from __future__ import annotations

import json
import os
import sys
import time
import warnings

import numpy as np

from mpm_warp.field.batch import run_records
from mpm_warp.io.checkpoint import read_checkpoint_meta
from mpm_warp.loader import resolved_scenario
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.scenes.weac_reference import slab_stress
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.validation.column_fe import solve_column

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
STUDIES = (os.path.join(RESULTS, "field_slab_stress.json"), os.path.join(RESULTS, "end", "field_slab_stress.json"))

#: m: stresses this close to the corner where the sawn weak layer ends (the crack tip at the slab's base) or to
#: the column's end faces (where layer interfaces and the weak layer meet a free face) are reported apart: there
#: linear elasticity is singular, the value grows with refinement, and a run's grid (5-8 mm) smears the same zone
CORNER_M = 0.02
#: element widths (m): the solution and its refinement
MESHES = (0.01, 0.005)


def fe_ratios(column, strengths, cut: float, dx: float, plane: str = "strain") -> dict:
    """The FE's slab stress over strength at ``cut`` (m) on elements of ``dx`` (m), in plane strain or plane stress:
    the peak away from the crack tip's corner and the end faces (and where: x from the cut end, depth, layer,
    sigma_xx, sigma_zz, sigma_xz), per layer, and in those edge zones (``edges``)."""
    t0 = time.perf_counter()
    r = solve_column(column.slab, (column.weak_layer_thickness, column.weak_layer_E, column.weak_layer_nu),
                     column.length, cut, slope_angle=column.slope_angle, cut_from=column.cut_from,
                     column_ends=column.column_ends, dx=dx, plane=plane)
    slab = r.layer >= 0
    ratio = np.where(slab, r.sigma_1 / np.asarray(strengths)[np.maximum(r.layer, 0)], -np.inf)
    slab_depth = sum(ly[0] for ly in column.slab)
    near = ((np.hypot(r.x - cut, r.depth - slab_depth) < CORNER_M) | (r.from_end_face < CORNER_M)
            | (r.from_end_face > column.length - CORNER_M))
    far = slab & ~near
    i = int(np.argmax(np.where(far, ratio, -np.inf)))
    return {"dx": dx, "dofs": int(r.dofs), "peak": float(ratio[i]),
            "peak_at": {"x": float(r.x[i]), "depth": float(r.depth[i]), "layer": int(r.layer[i]),
                        "sigma": [float(v) for v in r.sigma[i]]},
            "over_cut": float(ratio[far & (r.x < cut)].max()) if np.any(far & (r.x < cut)) else None,
            "layers": [float(ratio[far & (r.layer == k)].max()) for k in range(len(column.slab))],
            "edges": float(ratio[slab & near].max()), "wall_s": time.perf_counter() - t0}


def weac_ratios(column, strengths, cut: float) -> dict:
    """weac's static slab stress over strength at ``cut``: over the cut and at the tip (as ``slab_stress.py``)."""
    st = slab_stress(column, cut, strengths, dx=0.005, dz=0.002)
    over = st["ratio"][:, st["cracked"]]
    tip = st["ratio"][:, np.isclose(st["x"], cut, rtol=0.0, atol=1e-9)]
    return {"over_cut": float(over.max()) if over.size else None, "tip": float(tip.max()),
            "peak": float(st["peak_ratio"]), "peak_layer": int(st["peak_ratio_layer"])}


def compare(column, strengths, cut: float, meshes=MESHES) -> dict:
    fe = [fe_ratios(column, strengths, cut, dx) for dx in meshes]
    change = fe[-1]["peak"] / fe[0]["peak"] - 1.0 if len(fe) > 1 else None
    return {"cut": cut, "fe": fe, "fe_refinement_change": change, "weac": weac_ratios(column, strengths, cut)}


def control(study: dict, meshes) -> dict:
    """The homogeneous control of ``slab_stress.py`` (its cuts and its run's values) solved by the FE."""
    from mpm_warp.scenes.pst import PSTParams
    from mpm_warp.scenes.pst.saw import Saw
    from mpm_warp.scenes.snowpack import SnowLayer

    p = PSTParams(length=2.0, slab_layers=(SnowLayer(0.2, 120.0),), slab_fracture=True,
                  saw=Saw(cut_length=0.36, speed=1.0))
    col, strengths = static_column(p), [ly.strength for ly in p.slab_stack()]
    rows = []
    for row in study["control"]["rows"]:
        c = compare(col, strengths, row["cut"], meshes)
        rows.append({**c, "run": row["run"]})
    return {"what": study["control"]["what"], "slab_depth_m": study["control"]["slab_depth_m"], "rows": rows}


def run_layers_to(case: dict, cut: float | None, last: bool = False) -> list | None:
    """The run's largest stress over strength in each slab layer (top to bottom) while the blade had cut at most
    ``cut`` (m), from the slab-stress study's frames; ``last``: in the last such frame only."""
    s = case["series"]
    rows = [r for saw, r in zip(s["saw"], s["ratio"], strict=True) if cut is not None and saw <= cut + 1e-9]
    if not rows:
        return None
    return [float(v) for v in (rows[-1] if last else np.max(rows, axis=0))]


def run_peak_at_onset(case: dict, column, cut: float | None) -> dict | None:
    """Where the run's slab peak sat in the onset frame (the slab-stress study's ``peak_at``): along the column from
    the cut end's face at its depth (m), depth (m), the stresses (Pa), and its zone: ``blade`` (within
    :data:`CORNER_M` of the blade along the column), ``end face`` (of either end face), else ``inside``."""
    s = case["series"]
    if cut is None or not s.get("peak_at"):
        return None
    k = max(i for i, saw in enumerate(s["saw"]) if saw <= cut + 1e-9)
    x0, depth, sxx, syy, sxy = s["peak_at"][k]
    h = sum(ly[0] for ly in column.slab)
    shear = -np.tan(np.radians(column.slope_angle)) if column.column_ends == "vertical" else 0.0
    from_face = x0 - shear * (h - depth)                    # from the upslope end's face at that depth
    if column.cut_from == "downslope":
        from_face = column.length - from_face
    zone = ("blade" if abs(from_face - s["saw"][k]) <= CORNER_M else
            "end face" if min(from_face, column.length - from_face) <= CORNER_M else "inside")
    return {"from_end_face": float(from_face), "depth": float(depth), "sigma": [sxx, syy, sxy], "zone": zone,
            "blade": float(s["saw"][k])}


def case_row(case: dict, run_dir: str, meshes) -> dict:
    ck = os.path.join(run_dir, case["id"] + ".ckpt.h5")
    p = resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck).scene
    col, strengths = static_column(p), [ly.strength for ly in p.slab_stack()]
    row = {"id": case["id"], "test": case["test"], "observed": case["observed"], "slope_deg": p.slope_angle,
           "column_ends": col.column_ends, "length_m": col.length, "slab_depth_m": p.slab_depth, "run_dx": p.dx,
           "layer_cells": [ly["cells"] for ly in case["layers"]], "onset_cut": case["onset_cut"],
           "run_to_onset": case["mpm_ratio_to_onset"], "run_layers_to_onset": run_layers_to(case, case["onset_cut"]),
           "run_layers_at_onset": run_layers_to(case, case["onset_cut"], last=True),
           "run_peak_at": case.get("peak_at"), "run_peak_at_onset": run_peak_at_onset(case, col, case["onset_cut"])}
    if case["onset_cut"]:
        row["at_onset"] = compare(col, strengths, case["onset_cut"], meshes)
    return row


def main(argv=None) -> int:
    p = parser(__doc__, "the control at one cut and the first case, coarse")
    p.add_argument("runs", nargs="+", help="field batches' runs folders (field_batch.py --runs)")
    p.add_argument("--studies", nargs="+", default=list(STUDIES), help="slab_stress.py JSONs (default: both committed)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    meshes = MESHES[:1] if args.quick else MESHES
    dest = out_dir(args, RESULTS, "field_slab_fe")
    where = {r["id"]: d for r, d in run_records(args.runs)}
    studies = [json.load(open(s)) for s in args.studies]
    data = {"name": "field_slab_fe", "studies": [os.path.relpath(s, HERE) for s in args.studies],
            "corner_m": CORNER_M, "meshes_m": list(meshes), "environment": environment("cpu")}
    ctl = next((s for s in studies if "control" in s), None)
    if ctl is not None:
        if args.quick:
            ctl = {**ctl, "control": {**ctl["control"], "rows": ctl["control"]["rows"][-1:]}}
        data["control"] = control(ctl, meshes)
        print("control: " + ", ".join(f"{r['cut']:g} m: FE {r['fe'][-1]['peak']:.3f}, weac {r['weac']['peak']:.3f}, "
                                      f"run {r['run']:.3f}" for r in data["control"]["rows"]), flush=True)
    cases = [(c, s.get("selection", {"observed": "SF", "predicted": "END"})) for s in studies for c in s["cases"]]
    missing = [c["id"] for c, _ in cases if c["id"] not in where]
    if missing:
        print(f"error: runs: the runs of {len(missing)} cases are not in {args.runs} (e.g. {missing[0]})",
              file=sys.stderr)
        return 2
    data["cases"] = []
    for c, sel in cases[:1] if args.quick else cases:
        row = {**case_row(c, where[c["id"]], meshes), "selection": sel}
        data["cases"].append(row)
        path = write_json("field_slab_fe", data, dest)
        o = row.get("at_onset")
        print(f"{row['test']} ({row['observed']}): at the onset {row['onset_cut']} m FE "
              f"{o['fe'][-1]['peak']:.2f}, weac {o['weac']['peak']:.2f}, run {row['run_to_onset']:.2f}"
              if o else f"{row['test']}: no onset", flush=True)
    path = write_json("field_slab_fe", data, dest)
    print(f"{path}: {len(data['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
