"""What the snow studies share: the ladder PST, its levels and bisection grid, a level's parts, field values.

The ladder PST (:data:`LADDER_PST`) is ``pst_flat``'s production snow (slab, layer, saw) on a 2.2 m
column with a 0.3 m slab and a 6 cm weak layer, so that its coarsest level still has 3 cells across
the layer. The error ladder (``benchmarks/convergence/error_vs_runtime_snow.py``) halves its dx
(:data:`PST_DX`) and bisects its critical cut on :data:`PST_BRACKET`; the snow studies
(``benchmarks/snow/``) run it at its 6-cell level (:func:`ladder_pst`, dx 10 mm).
"""

from __future__ import annotations

import math

from ..errors import InvalidArgument

__all__ = ["LADDER_PST", "LADDER_WEAK_LAYER",
           "PST_DX", "PST_BRACKET", "SHEAR_CELLS", "FIELD_SPEED", "LONG_PST_SPEED", "DEM_STEADY_MAX",
           "SUPERSHEAR_MAX", "STEADY_FROM", "FIELD_CUT",
           "PST_CUT_FIELDS", "ladder_pst", "field_level_dx", "grid_bracket", "pst_part", "merge_pst_parts",
           "split_pst_parts"]

#: The ladder PST's weak layer (m).
LADDER_WEAK_LAYER = 0.06
#: Scenario overrides of ``pst_flat`` that make the ladder PST (module docstring).
LADDER_PST = ("scene.length=2.2", "scene.slab_thickness=0.3", f"scene.weak_layer_thickness={LADDER_WEAK_LAYER!r}",
              "scene.substratum_thickness=0.06", "scene.margin=0.05")
#: The PST ladder's grid spacings (m): 3, 6, 12, 24 cells across the 6 cm layer.
PST_DX = (0.02, 0.01, 0.005, 0.0025)
#: The critical cut's bisection at every PST level (m): the bracket and the width it stops at.
PST_BRACKET = {"lo": 0.1, "hi": 0.7, "tol": 0.02}
#: The shear-test ladder's cells across its 3 cm layer.
SHEAR_CELLS = (3, 6, 12, 24)
#: PST crack speeds in the field (m/s) over the first metres, in short PSTs (Bergfeld et al. 2021, docs/model.md §6).
FIELD_SPEED = (20.0, 30.0)
#: Crack speeds in long PSTs and slope-scale measurements (m/s; Bergfeld et al. 2022, docs/model.md §6).
LONG_PST_SPEED = (36.0, 49.0)
#: The largest steady speed of long flat DEM PSTs, as a fraction of the slab's c_s (Bobillier et al. 2024).
DEM_STEADY_MAX = 0.6
#: The fastest cracks on steep slopes, as a fraction of c_s (Trottet et al. 2022; Bobillier et al. 2025).
SUPERSHEAR_MAX = 1.6
#: Where a long column's crack is steady (m from the cut end): beyond about 5 m of propagation.
STEADY_FROM = 5.0
#: Critical cuts of a flat PST in the field (m): a few tens of centimetres.
FIELD_CUT = (0.15, 0.6)
#: What a narrowed critical-cut search adds to a level's base-run record (:func:`merge_pst_parts`).
PST_CUT_FIELDS = ("critical_cut", "critical_cut_bracket", "bracketed", "critical_cut_note", "trials",
                  "critical_cut_wall_s", "critical_cut_steps", "bisection")


def ladder_pst(dx: float | None = 0.01) -> list[str]:
    """Overrides of ``pst_flat`` for the ladder PST at grid spacing ``dx`` (m; None: the scenario's own)."""
    return list(LADDER_PST) + ([] if dx is None else [f"scene.dx={dx!r}"])


def field_level_dx() -> float:
    """The ladder PST's grid spacing at the field protocol's resolution (m): its weak layer over
    ``FieldProtocol.cells_across`` (4 cells: 15 mm), a level off the halving ladder."""
    from ..field.protocol import FieldProtocol

    return LADDER_WEAK_LAYER / FieldProtocol().cells_across


def grid_bracket(lo: float, hi: float) -> dict:
    """A bracket inside :data:`PST_BRACKET` on its bisection grid, for a level whose cut the coarser levels bound.

    ``lo`` and ``hi`` (m) must be points the full search can visit (``PST_BRACKET``'s ``lo`` plus a
    multiple of its width over a power of two), so that the bisection ends in one of the full search's
    final brackets: the level's critical cut reads as at the other levels, at the cost of the trials
    inside ``[lo, hi]`` only. A cut outside ``[lo, hi]`` is reported as not bracketed.

    Raises
    ------
    InvalidArgument
        ``lo`` or ``hi`` off the grid, or ``lo >= hi``.
    """
    b = PST_BRACKET
    w = b["hi"] - b["lo"]
    n = 0
    while w / 2 ** n > b["tol"]:
        n += 1
    step = w / 2 ** n
    for name, x in (("lo", lo), ("hi", hi)):
        k = (x - b["lo"]) / step
        if not (b["lo"] <= x <= b["hi"] and abs(k - round(k)) < 1e-6):
            raise InvalidArgument(f"bracket {name}", x, f"a point of the bisection grid {b['lo']} + k * {step:g} m "
                                                        f"inside [{b['lo']}, {b['hi']}] m")
    if not lo < hi:
        raise InvalidArgument("bracket", (lo, hi), "lo < hi")
    return dict(lo=lo, hi=hi, tol=b["tol"])


def pst_part(rec: dict) -> str:
    """Which runs of a PST level a record holds: ``both``, ``base_run`` or ``critical_cut``."""
    return rec.get("part") or ("base_run" if rec.get("note", "").startswith("base run only") else "both")


def split_pst_parts(rec: dict) -> dict:
    """The parts of a PST level's record, by name: the inverse of :func:`merge_pst_parts` for a ``both``.

    A record of both parts run apart gives back its base run (its own wall time, steps and commit)
    and its critical-cut search; any other record is the one part it holds.
    """
    if pst_part(rec) != "both" or "git_commit_base_run" not in rec:
        return {pst_part(rec): rec}
    base = {k: v for k, v in rec.items() if k not in PST_CUT_FIELDS and k != "git_commit_base_run"}
    base.update(part="base_run", git_commit=rec["git_commit_base_run"], critical_cut=math.nan,
                wall_time_s=rec["wall_time_s"] - rec["critical_cut_wall_s"],
                steps=rec["steps"] - rec["critical_cut_steps"], note="base run only (critical cut not bisected)")
    cut = {**{k: rec[k] for k in PST_CUT_FIELDS if k in rec}, "part": "critical_cut", "git_commit": rec["git_commit"]}
    return {"base_run": base, "critical_cut": cut}


def merge_pst_parts(new: dict, old: dict | None) -> dict:
    """One level's record from its base run and its narrowed critical-cut search, run apart in either order.

    ``new`` is the part just run, ``old`` what the results hold for the level (or None). Once both are
    there the level's wall time and steps are both runs' (``part``: ``both``); until then the record
    says which part it holds, and the other part's quantities are nan.
    """
    parts = {pst_part(new): new}
    if old is not None and pst_part(new) != "both":
        parts = {**split_pst_parts(old), **parts}         # a part run again replaces that part only
    if len(parts) == 1:
        return {**new, "part": pst_part(new)}
    base, cut = parts["base_run"], parts["critical_cut"]
    out = {**base, **{k: cut[k] for k in PST_CUT_FIELDS}, "part": "both",
           "note": "base run (speed, touchdown, collapse height) and critical-cut search (narrowed bracket) run "
                   "apart: the level's wall time and steps are both runs'",
           "git_commit_base_run": base.get("git_commit"), "git_commit": cut.get("git_commit"),
           "wall_time_s": base["wall_time_s"] + cut["critical_cut_wall_s"],
           "steps": base["steps"] + cut["critical_cut_steps"]}
    out["particle_steps_per_s"] = out["n_particles"] * out["steps"] / out["wall_time_s"]
    return out
