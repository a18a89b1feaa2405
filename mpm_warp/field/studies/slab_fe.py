"""A field column's slab stress over strength by a static FE that resolves every layer, beside weac's and the run's.

:func:`fe_ratios` solves a column statically at one cut by the 9-node FE of :mod:`mpm_warp.validation.column_fe`
(plane strain or plane stress) and reads the slab's largest principal stress over its layer's strength away from
the singular corners (:data:`CORNER_M`); :func:`weac_ratios` reads weac's over the cut and at the tip;
:func:`fe_row` sets a slab-stress study's case (:mod:`.slab_stress`) against both at its crack's onset.
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["CORNER_M", "MESHES", "fe_ratios", "weac_ratios", "compare", "run_layers_to", "run_peak_at_onset",
           "fe_row"]

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
    from ...validation.column_fe import solve_column

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
    """weac's static slab stress over strength at ``cut`` (m): over the cut, at the crack tip, its peak and the
    layer of its peak (0 the top)."""
    from ...scenes.weac_reference import slab_stress

    st = slab_stress(column, cut, strengths, dx=0.005, dz=0.002)
    over = st["ratio"][:, st["cracked"]]
    tip = st["ratio"][:, np.isclose(st["x"], cut, rtol=0.0, atol=1e-9)]
    return {"cut": cut, "over_cut": float(over.max()) if over.size else None, "tip": float(tip.max()),
            "peak": float(st["peak_ratio"]), "peak_layer": int(st["peak_ratio_layer"])}


def compare(column, strengths, cut: float, meshes=MESHES) -> dict:
    """The FE at each of ``meshes`` and weac at ``cut`` (m), and the FE's peak's change from the first mesh to the
    last (-)."""
    fe = [fe_ratios(column, strengths, cut, dx) for dx in meshes]
    change = fe[-1]["peak"] / fe[0]["peak"] - 1.0 if len(fe) > 1 else None
    return {"cut": cut, "fe": fe, "fe_refinement_change": change, "weac": weac_ratios(column, strengths, cut)}


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


def fe_row(case: dict, run_dir: str, meshes=MESHES) -> dict:
    """A slab-stress study's ``case`` (its frames; its run's checkpoint in ``run_dir``) against the FE and weac at
    its crack's onset: the column, the run's values to and at the onset, and ``at_onset`` (:func:`compare`)."""
    from ...scenes.pst.static import static_column
    from ..run_on import scenario_of

    p = scenario_of(run_dir, case["id"]).scene
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
