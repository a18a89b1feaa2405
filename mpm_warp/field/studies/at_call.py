"""What a finished field run's slab had done when the run called its outcome: how far it had come down, over how
much of the crack, and how close it came to breaking.

A field run stops at its call (END once the crack reaches the far end zone, SF once the slab cracks through, ARR
once the crack stops). Read from the run file's frame series (the PST monitor's; docs/field.md, "Why thin, light
slabs break"): the slab base's largest drop normal to the bed at the monitor's markers over the weak layer's
calibrated collapse height, the share of the cracked length behind which the slab base had come down by a tenth
of that height (the deflection front over the damage front), the slab's largest carried stress over its
strength, and the largest share of its particle rows cracked through at one place. Each is a candidate
mechanism's run reading. :func:`body_stress_ratio` reads, from the run's final checkpoint, the largest stress the
slab's body carries at the call: its particles whose grid stencils share no node with the weak layer's, where the
grid ties the slab's base rows to the collapsing layer and cracks them along the bed (docs/field.md).
"""

from __future__ import annotations

import math
import os

import numpy as np

from ...scenes.pst.outcome import TIE_CELLS

__all__ = ["AT_CALL_KEYS", "readings_at_call", "body_stress_ratio", "slab_crack_ratio", "case_readings",
           "body_at_call"]

#: the readings :func:`readings_at_call` returns, each with what it is
AT_CALL_KEYS = {
    "slab_drop_at_call": "the slab base's largest drop normal to the bed at its markers at the call, over the "
                         "weak layer's calibrated collapse height (-)",
    "slab_down_share": "the share of the cracked length over which the slab base came down by a tenth of the "
                       "collapse height at the call (-)",
    "slab_stress_ratio": "the largest stress the slab carried over its strength, up to the call (-; 1: cracked)",
    "slab_crack_cover": "the largest share of the slab's particle rows cracked through at one place (-)",
    "slab_body_stress_ratio_at_call": "the largest stress the slab's body (beyond the rows the grid ties to the weak "
                              "layer) carries at the call over its strength (-; 1: cracked there)",
}


def _last_finite(x: np.ndarray) -> float | None:
    x = x[np.isfinite(x)]
    return float(x[-1]) if x.size else None


def _peak(x: np.ndarray) -> float | None:
    x = x[np.isfinite(x)]
    return float(x.max()) if x.size else None


def readings_at_call(series: dict, collapse_height: float) -> dict:
    """The readings of :data:`AT_CALL_KEYS` from a run's frame series.

    Parameters
    ----------
    series : dict
        The monitor's frame series (arrays over frames): ``front`` and ``deflection_front`` (m from the cut end),
        ``marker{k}_uy`` (m, the slab base's displacement normal to the bed at marker ``k``), ``slab_stress_ratio``
        and ``slab_crack_cover`` (-); a missing one gives None.
    collapse_height : float
        The weak layer's calibrated collapse height (m, > 0).

    Returns
    -------
    dict
        One value (or None) per key of :data:`AT_CALL_KEYS`, read at the last frame (the call) or, for the slab's
        two, as the largest over the frames.
    """
    from ...errors import InvalidArgument

    if not (isinstance(collapse_height, (int, float)) and math.isfinite(collapse_height) and collapse_height > 0):
        raise InvalidArgument("collapse_height", collapse_height, "a finite height > 0 m")
    get = {k: np.asarray(series[k], dtype=float) for k in ("front", "deflection_front", "slab_stress_ratio",
                                                           "slab_crack_cover") if k in series}
    front = _last_finite(get["front"]) if "front" in get else None
    down = _last_finite(get["deflection_front"]) if "deflection_front" in get else None
    drops = [-v for k in series if k.startswith("marker") and k.endswith("_uy")
             if (v := _last_finite(np.asarray(series[k], dtype=float))) is not None]
    share = None
    if front is not None and down is not None and front > 0.0:
        share = min(max(down, 0.0), front) / front
    return {"slab_body_stress_ratio_at_call": None,
            "slab_drop_at_call": max(drops) / collapse_height if drops else None, "slab_down_share": share,
            "slab_stress_ratio": _peak(get["slab_stress_ratio"]) if "slab_stress_ratio" in get else None,
            "slab_crack_cover": _peak(get["slab_crack_cover"]) if "slab_crack_cover" in get else None}


def body_stress_ratio(run_dir: str, case_id: str, scenario, tie_cells: float = TIE_CELLS) -> float | None:
    """The largest tensile stress the slab's body carries at the call over its strength (-; 1 where a body
    particle cracked), from the case's final checkpoint: the slab particles more than ``tie_cells`` grid cells
    above the weak layer's top particles (initial positions). None without a checkpoint, a run file, or a body."""
    import h5py

    from ...model import Model
    from ...scenes.pst.outcome import carried_over_strength

    ck, run = (os.path.join(run_dir, case_id + ext) for ext in (".ckpt.h5", ".h5"))
    if scenario is None or not (os.path.exists(ck) and os.path.exists(run)):
        return None
    model = Model(scenario, "cpu")
    with h5py.File(ck, "r") as f:
        H, kappa = f["H"][:], f["kappa"][:]
    with h5py.File(run, "r") as f:
        x0 = f["static"]["x0"][:]
    weak = [g for g in model.groups if g.name == "weak_layer"]
    slab = [g for g in model.groups if g.name.startswith("slab") and g.material.model == "tensile_cracking"]
    if not weak or not slab:
        return None
    top = float(x0[weak[0].start:weak[0].end, 1].max())
    best = None
    for g in slab:
        body = x0[g.start:g.end, 1] - top > tie_cells * model.dx
        if body.any():
            r = carried_over_strength(H[g.start:g.end], kappa[g.kappa_start:g.kappa_start + g.count], g.material)
            best = max(best or 0.0, float(r[body].max()))
    return best


def slab_crack_ratio(run_dir: str, case_id: str, scenario) -> float | None:
    """The slab's largest ``kappa`` over its tensile strength in the case's final checkpoint (-; >= 1: it cracked
    somewhere; the effective, unsoftened stress's history, docs/field.md); None without a checkpoint, a scenario
    or a cracking slab."""
    import h5py

    from ...model import Model

    ck = os.path.join(run_dir, case_id + ".ckpt.h5")
    if scenario is None or not os.path.exists(ck):
        return None
    with h5py.File(ck, "r") as f:
        kappa = f["kappa"][:] if "kappa" in f else None
    groups = [g for g in Model(scenario, "cpu").groups if g.material.model == "tensile_cracking"]
    if kappa is None or not groups:
        return None
    return max(float(kappa[g.kappa_start:g.kappa_start + g.count].max()) / g.material.tensile_strength
               for g in groups)


def case_readings(run_dir: str, case_id: str, scenario) -> dict:
    """:func:`readings_at_call` of the field case ``case_id`` in the runs folder ``run_dir``, its collapse height
    the calibration ``scenario`` stored (the case's scenario, :func:`mpm_warp.field.run_on.scenario_of`), and
    :func:`body_stress_ratio`; all None without a run file or a scenario."""
    import h5py

    from ...scenes.weak_layer import stored_calibration

    path = os.path.join(run_dir, case_id + ".h5")
    if scenario is None or not os.path.exists(path):
        return dict.fromkeys(AT_CALL_KEYS)
    with h5py.File(path, "r") as f:
        series = {k: f["scalars"][k][:] for k in f["scalars"]} if "scalars" in f else {}
    out = readings_at_call(series, stored_calibration(scenario).h_c)
    out["slab_body_stress_ratio_at_call"] = body_stress_ratio(run_dir, case_id, scenario)
    return out


def body_at_call(recs: list[dict], runs: str) -> None:
    """Give each finished record of ``recs`` (runs folder ``runs``) without the body's series its slab body's stress
    at the call, from its final checkpoint (``slab_body_stress_ratio_at_call``, the reading the model's probability
    then takes: :func:`mpm_warp.field.probability.slab_reading`), and its probabilities (``p_end``, ``p_sf``,
    ``p_arr``) from it."""
    from ..probability import record_probabilities
    from ..run_on import scenario_of

    for r in recs:
        if r.get("status") == "ok" and r.get("slab_peak_body_stress_ratio") is None:
            r["slab_body_stress_ratio_at_call"] = body_stress_ratio(runs, r["id"], scenario_of(runs, r["id"]))
            record_probabilities(r)
