"""Results of a PST from its fronts and frame series (pure NumPy): speeds as profiles, touchdown, collapse.

Everything is measured from the cut end (m) along the column, on the paths of the two fronts
(:func:`~mpm_warp.scenes.fronts.front_trajectory`): the damage front (the weak layer's bond) and the
slab-deflection front (the slab base coming down). No speed exceeds the slab's P-wave speed: a front that
seems faster connected to damage ahead of it, which is reported as such
(:mod:`mpm_warp.scenes.front_speed`). A value that does not exist (a crack that did not run has no speed) is
nan here with its reason under ``<key>_null``; the results files write it as null.

The parameters these functions take are those of the cut made (:func:`~.saw.sawn`): a saw that stopped on the
crack's runaway (``saw.stop = "runaway"``) is a saw set to cut where it stopped, and the blade's position is
recomputed from its speed and the time up to there (:func:`~.saw.blade_position`).
"""

from __future__ import annotations

import math

import numpy as np

from ..front_speed import JUMP_FRACTION, bounded_mean_speed, damage_ahead, path_jumps, window_speeds
from ..fronts import front_trajectory, lead_ahead_of_front
from ..references import heierli_speed, heierli_touchdown
from .params import PSTParams
from .saw import blade_position

__all__ = ["pst_summary", "front_speeds", "rederive_speeds", "end_zone", "runaway_cut", "slab_p_wave_speed",
           "crack_ran", "SPEED_WINDOW", "MEAN_SPEED_DISTANCE", "SPEED_LIMIT_DISTANCE"]

#: window of the local front speed (m)
SPEED_WINDOW = 0.5
#: the mean front speed is taken over this distance from the cut (m)
MEAN_SPEED_DISTANCE = 3.0
#: the largest local speed is reported within this distance from the cut (m)
SPEED_LIMIT_DISTANCE = 5.0


def end_zone(params: PSTParams) -> float:
    """Length of the far end zone (m): one slab thickness (at least two bins), whose free edge unloads the layer."""
    return max(float(params.slab_depth), 2.0 * params.bin_width)


def slab_p_wave_speed(params: PSTParams) -> float:
    """The fastest P-wave speed of the slab's layers (m/s), ``sqrt((lam + 2 mu) / rho)``: no front is faster."""
    return max(layer.slab().material().p_wave_speed for layer in params.slab_stack())


def crack_ran(params: PSTParams, reach):
    """Whether a damage front that reached ``reach`` (m; float or array) ran beyond the saw's cut by itself
    (by two bins); a bool array for an array."""
    return np.asarray(reach, dtype=float) >= float(params.saw.cut_length) + 2.0 * params.bin_width - 1e-12


def _null(out: dict, key: str, reason: str) -> None:
    """Put the reason for a missing value (nan) of ``out[key]`` under ``key + "_null"``."""
    v = out.get(key)
    if isinstance(v, float) and not math.isfinite(v):
        out[key + "_null"] = reason


def front_speeds(params: PSTParams, sp, T, prefix: str, ahead=()) -> dict:
    """Speeds of one front from its path ``(sp, T)`` (m, s) and the damage ahead found from its arrival times.

    Returns the ``{prefix}_`` keys of :func:`pst_summary` but ``front_final`` and ``path``; used on live runs
    and to re-derive the speeds of a stored path (``benchmarks/snow/pst.py --reanalyse``).
    """
    cut, L = float(params.saw.cut_length), float(params.length)
    c_p = slab_p_wave_speed(params)
    jumps = path_jumps(sp, T, c_p, JUMP_FRACTION * SPEED_WINDOW)
    blocks = [*ahead, *jumps]
    prof = window_speeds(sp, T, SPEED_WINDOW, cut, c_p, blocks)
    d1 = min(cut + MEAN_SPEED_DISTANCE, L - end_zone(params))
    mean, why = bounded_mean_speed(sp, T, cut, d1, c_p, blocks)
    out = {f"{prefix}_speed_mean": mean, f"{prefix}_speed_mean_over": [cut, d1],
           f"{prefix}_speed_max": prof.largest(cut + SPEED_LIMIT_DISTANCE),
           f"{prefix}_speed_profile": prof.to_dict(),
           f"{prefix}_ahead": [b.to_dict() for b in ahead], f"{prefix}_jumps": [b.to_dict() for b in jumps]}
    if why:
        out[f"{prefix}_speed_mean_null"] = why
    _null(out, f"{prefix}_speed_max", f"no window within {SPEED_LIMIT_DISTANCE:g} m of the cut crossed "
                                      "contiguously: no speed")
    return out


def _front(params: PSTParams, s, t_arrival, prefix: str) -> dict:
    L = float(params.length)
    sp, T = front_trajectory(s, t_arrival)
    reach = float(sp[-1] + 0.5 * params.bin_width) if len(sp) else 0.0
    ahead = damage_ahead(s, t_arrival, params.bin_width, JUMP_FRACTION * SPEED_WINDOW)
    return {f"{prefix}_front_final": min(reach, L), **front_speeds(params, sp, T, prefix, ahead),
            f"{prefix}_path": {"s": sp.tolist(), "t": T.tolist()}}


def runaway_cut(params: PSTParams, s, t_arrival) -> float:
    """Saw position (m) when the damage front first led the blade by ``front.runaway_lead``; nan if never.

    ``s`` are the bin centres (m from the cut end), ``t_arrival`` their damage times (s, inf: never); the blade's
    position is :func:`~.saw.blade_position` of ``params``, the cut made (:func:`~.saw.sawn`).
    """
    sp, T = front_trajectory(s, t_arrival)
    saw = blade_position(params, T)
    k = np.nonzero(sp - saw >= params.front.runaway_lead)[0]
    return float(saw[k[0]]) if len(k) else math.nan


def _reach_and_speed(params: PSTParams, out: dict) -> None:
    """``p_wave_speed``, ``propagated``, ``ran_to_end``, ``speed`` and ``front_agreement`` into ``out``, from its
    fronts' reach and mean speeds (:func:`pst_summary`)."""
    cut, L = float(params.saw.cut_length), float(params.length)
    out["p_wave_speed"] = slab_p_wave_speed(params)
    reach = out["damage_front_final"]
    ran = crack_ran(params, reach)
    out["propagated"] = bool(ran and reach >= min(cut + 2.0, L - end_zone(params)))
    out["ran_to_end"] = bool(ran and reach >= L - end_zone(params))
    out["speed"] = out["damage_speed_mean"]
    out.pop("speed_null", None)
    if "damage_speed_mean_null" in out:
        out["speed_null"] = out["damage_speed_mean_null"]
    v1, v2 = out["damage_speed_mean"], out["deflection_speed_mean"]
    out["front_agreement"] = v2 / v1 if np.isfinite(v1) and np.isfinite(v2) and v1 > 0 else math.nan
    out.pop("front_agreement_null", None)
    _null(out, "front_agreement", "no mean speed of both fronts")


def rederive_speeds(params: PSTParams, result: dict) -> dict:
    """A stored PST result (:func:`pst_summary`, as a results file holds it) with its speeds re-derived from its
    fronts' paths (``damage_path``, ``deflection_path``) by today's analysis.

    The paths are the contiguous fronts; the bins' own arrival times are not stored, so the damage ahead is
    what the paths show (``{prefix}_jumps``); ``{prefix}_ahead`` is None with the reason, and the run's
    ``max_damage_lead`` (from the arrival times) stays. Every other value is kept.
    """
    new = {}
    for prefix in ("damage", "deflection"):
        path = result[f"{prefix}_path"]
        sp = np.asarray([math.nan if v is None else v for v in path["s"]], dtype=float)
        T = np.asarray([math.nan if v is None else v for v in path["t"]], dtype=float)
        new[prefix] = {**front_speeds(params, sp, T, prefix), f"{prefix}_ahead": None,
                       f"{prefix}_ahead_null": ("the bins' arrival times were not stored: the damage ahead is what "
                                                f"the path shows ({prefix}_jumps; max_damage_lead from the run's "
                                                "arrival times)")}
    out = {}
    for key, value in result.items():                 # the stored order, the speeds in place of the old ones
        prefix = next((p for p in new if key.startswith(f"{p}_speed") or key in (f"{p}_ahead", f"{p}_jumps")),
                      None)
        if prefix is None:
            out[key] = value
        elif f"{prefix}_speed_mean" not in out:
            out.update(new[prefix])
    _reach_and_speed(params, out)
    return out


def pst_summary(params: PSTParams, calibration, times, series: dict, s_bins, t_damage, t_deflection) -> dict:
    """Crack fronts, speeds, touchdown and collapse of a PST.

    Parameters
    ----------
    params : PSTParams
        The parameters of the cut made (:func:`~.saw.sawn`); ``cut_length`` in the result is its cut (m).
    calibration : CalibratedWeakLayer
        The weak layer's calibration (the scenario's stored one), for the references.
    times : array (n,)
        Frame times (s).
    series : dict
        Frame series of :class:`~mpm_warp.scenes.pst.PSTMonitor` (``front``, ``deflection_front``,
        ``touchdown``, ``collapse_height``, ...).
    s_bins : array
        Bin centres (m from the cut end).
    t_damage, t_deflection : array
        Arrival time of the damage and deflection fronts in every bin (s, inf: never).

    Returns
    -------
    dict
        Per front (``damage_``/``deflection_``): ``front_final`` (m), ``speed_mean`` (m/s, from the cut
        over :data:`MEAN_SPEED_DISTANCE` or to the end zone (:func:`end_zone`), nan if not reached),
        ``speed_max`` (m/s, the largest local speed within :data:`SPEED_LIMIT_DISTANCE`), ``speed_profile`` (local
        speeds over
        :data:`SPEED_WINDOW` windows: ``s``, ``speed`` (None where the front did not advance contiguously or
        seemed faster than the slab's P-wave speed), ``status``), ``ahead`` (blocks damaged while not connected
        to the front, from the arrival times), ``jumps`` (stretches of the path crossed faster than c_p), ``path``.
        A nan value has its reason under ``<key>_null``; ``p_wave_speed`` is the bound (m/s).
        Then ``propagated`` (the damage front ran by itself beyond the cut (:func:`crack_ran`) and at least
        2 m, or to the end zone: within one slab thickness of the far end, whose free edge
        unloads the layer under it), ``ran_to_end`` (into the end zone, having run beyond the cut),
        ``speed`` (the damage front's mean speed), ``front_agreement`` (deflection over damage mean speed),
        ``runaway_cut`` (m: the saw position when the crack ran away from it, the one-run estimate of the critical
        cut), ``max_damage_lead``/``max_damage_lead_at`` (m: how far ahead of the contiguous front a
        bin was damaged, and where: the crack started at the saw when small), ``touchdown`` (m, the
        median over the frames with the deflection front in the middle of its free run),
        ``collapse_height`` (m, last frame) and the closed-form references of
        :meth:`PSTParams.references` (with ``heierli_speed_run``/``heierli_touchdown_run``: Heierli's
        values with the run's own collapse height).
    """
    cut, L = float(params.saw.cut_length), float(params.length)
    out = {"cut_length": cut, "column_length": L}
    out.update(_front(params, s_bins, t_damage, "damage"))
    out.update(_front(params, s_bins, t_deflection, "deflection"))
    _reach_and_speed(params, out)
    out["runaway_cut"] = runaway_cut(params, s_bins, t_damage)
    _null(out, "runaway_cut", f"the damage front never led the blade by {params.front.runaway_lead:g} m")
    out["max_damage_lead"], out["max_damage_lead_at"] = lead_ahead_of_front(s_bins, t_damage)
    _null(out, "max_damage_lead_at", "no bin was damaged ahead of the contiguous front")
    t = np.asarray(times, dtype=float)
    df = np.asarray(series.get("deflection_front", np.zeros(len(t))), dtype=float)
    td = np.asarray(series.get("touchdown", np.full(len(t), np.nan)), dtype=float)
    steady = (df >= cut + 0.3 * (L - cut)) & (df <= cut + 0.85 * (L - cut)) & np.isfinite(td)
    out["touchdown"] = float(np.median(td[steady])) if steady.any() else math.nan
    _null(out, "touchdown", "the deflection front did not run 30-85 % of the free column with a touchdown")
    ch = np.asarray(series.get("collapse_height", [0.0]), dtype=float)
    out["collapse_height"] = float(ch[-1]) if len(ch) else 0.0
    refs = params.references(calibration)
    out.update({k: float(v) for k, v in refs.items()})
    slab, D = params.equivalent_slab(), params.slab_depth
    h = out["collapse_height"]
    out["heierli_speed_run"] = heierli_speed(slab.E, D, slab.density, h) if h > 0 else math.nan
    out["heierli_touchdown_run"] = heierli_touchdown(slab.E, D, slab.density, h) if h > 0 else math.nan
    for key in ("heierli_speed_run", "heierli_touchdown_run"):
        _null(out, key, "no collapse in the run (Heierli's value needs a collapse height)")
    return out
