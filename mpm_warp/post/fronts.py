"""Crack fronts read from run files: the front as x per frame and the front-speed fit with the scene's window.

The fit itself is :func:`mpm_warp.scenes.fronts.steady_speed` (its one home); a PST's window is
the positions the PST's own mean speed is taken over (from one bin beyond the cut over
:data:`mpm_warp.scenes.pst.analysis.MEAN_SPEED_DISTANCE`, at most to the far end zone).
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidArgument, MPMError
from ..io import RunData
from ..loader import scene_params_from_dict
from ..scenes.front_speed import NUCLEATION
from ..scenes.fronts import fit_window, steady_speed
from ..scenes.pst import PSTParams, sawn
from ..scenes.pst.analysis import MEAN_SPEED_DISTANCE, end_zone, slab_p_wave_speed
from ..scenes.weak_layer import CalibratedWeakLayer

__all__ = ["scene_params", "sawn_params", "scene_calibration", "front_name", "fit_front_speed", "front_speed",
           "front_and_saw_x", "fronts_x"]


def scene_params(run: RunData):
    """The typed scene parameters of a run file (None without a scene, or when they cannot be read)."""
    table = (run.scenario or {}).get("scene")
    if not isinstance(table, dict) or table.get("kind", "blocks") == "blocks":
        return None
    try:
        return scene_params_from_dict({k: v for k, v in table.items() if k != "derived"}, run.path)
    except MPMError:                  # a file of another version: the generic analyses still work
        return None


def sawn_params(run: RunData):
    """:func:`scene_params`, for a PST whose saw stopped on the crack's runaway those of the cut made
    (:func:`~mpm_warp.scenes.pst.sawn`: ``saw.cut_length`` where it stopped, the run file's ``saw_stopped_at``)."""
    params = scene_params(run)
    if not isinstance(params, PSTParams):
        return params
    stopped = ((run.attrs.get("outcome") or {}).get("pst") or {}).get("saw_stopped_at")
    return sawn(params, float(stopped)) if isinstance(stopped, (int, float)) else params


def scene_calibration(run: RunData, params=None):
    """The weak layer's calibration a snow run stored with its scenario (:class:`~mpm_warp.scenes.weak_layer.
    CalibratedWeakLayer`), read, never rerun; a run file of an older release, which did not store it, has it
    derived from its parameters ``params`` once (None without them)."""
    stored = ((run.scenario or {}).get("calibration") or {}).get("weak_layer")
    if stored is not None:
        return CalibratedWeakLayer.from_dict(stored)
    return params.calibrated() if params is not None else None


def front_name(run: RunData) -> str | None:
    """The run's front series: ``front_position`` (x, m) or a PST's ``front`` (m from the cut end), or None."""
    return next((n for n in ("front_position", "front") if n in run.scalars), None)


def fit_front_speed(times, front, lo: float = 0.2, hi: float = 0.9, start: float | None = None,
                    end: float | None = None) -> dict:
    """Crack speed: least-squares line ``x = x0 + c t`` through the steady part of the front's travel.

    The steady part is the samples with positions between ``start + lo (end - start)`` and
    ``start + hi (end - start)``: this leaves out the saw phase and the start-up of the crack
    (below) and its arrival at the end of the column (above). The line is fitted by
    :func:`mpm_warp.scenes.fronts.steady_speed` (a repeated position keeps only its first time, so an
    arrested front does not bias the slope; fewer than 3 points give NaN).

    Parameters
    ----------
    times : array_like (n,)
        Times [s].
    front : array_like (n,)
        Front position [m]; NaN where there is no front.
    lo, hi : float
        Window, as fractions of the path from ``start`` to ``end``, ``0 <= lo < hi <= 1``.
    start, end : float, optional
        Ends of the path [m]; default the first finite position and the largest (for a PST the
        cut length and the column length).

    Returns
    -------
    dict
        ``speed`` [m/s], ``intercept`` [m] (position at t = 0), ``r2``, ``n_points``, ``window``
        (positions fitted, [m]) and ``t_start``, ``t_end`` (times of the first and last point
        fitted, [s]); NaN values when there is no steady part.
    """
    if not 0.0 <= lo < hi <= 1.0:
        raise InvalidArgument("(lo, hi)", (lo, hi), "0 <= lo < hi <= 1")
    t, x = np.asarray(times, dtype=float), np.asarray(front, dtype=float)
    if t.shape != x.shape or t.ndim != 1:
        raise InvalidArgument("front.shape", x.shape, f"the shape of times {t.shape}, one-dimensional")
    ok = np.isfinite(t) & np.isfinite(x)
    nan = float("nan")
    if not ok.any():
        return dict(speed=nan, intercept=nan, r2=nan, n_points=0, window=[nan, nan], t_start=nan, t_end=nan)
    a = float(x[ok][0]) if start is None else float(start)
    b = float(x[ok].max()) if end is None else float(end)
    w_lo, w_hi = fit_window(a, b, lo, hi)
    fit = steady_speed(t, x, w_lo, w_hi)
    return dict(speed=fit.speed, intercept=fit.intercept, r2=fit.r2, n_points=fit.n, window=[w_lo, w_hi],
                t_start=fit.t_start, t_end=fit.t_end)


def front_speed(run: RunData) -> dict:
    """:func:`fit_front_speed` of the run's front series, with a PST's window for a PST (see module docstring).

    For a PST, ``c_max`` is the slab's P-wave speed (m/s): a line faster than it, or no line, gives ``speed`` nan
    with the reason under ``speed_null`` (a front faster than sound connected to damage ahead of it).
    """
    name = front_name(run)
    if name is None:
        raise InvalidArgument("run", run.path, "a run with a front series (front_position or a PST's front)")
    t, xf = run.times, run.scalars[name]
    params = sawn_params(run)
    if name == "front" and isinstance(params, PSTParams):
        start = float(params.saw.cut_length) + params.bin_width      # beyond the cut: the saw's own path left out
        end = min(start - params.bin_width + MEAN_SPEED_DISTANCE, float(params.length) - end_zone(params))
        fit = fit_front_speed(t, xf, 0.0, 1.0, start=start, end=max(end, start + params.bin_width))
        fit["c_max"] = slab_p_wave_speed(params)
        if not fit["speed"] <= fit["c_max"]:         # faster than sound (or none): not a speed
            fit["speed_null"] = (f"{NUCLEATION}: the line's {fit['speed']:.4g} m/s exceeds the slab's c_p "
                                 f"{fit['c_max']:.4g} m/s" if fit["speed"] > fit["c_max"] else
                                 "fewer than 3 distinct front positions in the window: the front did not run")
            fit["speed"] = float("nan")
        return fit
    return fit_front_speed(t, xf)


def fronts_x(run: RunData) -> dict[str, np.ndarray | None]:
    """The damage front, the slab-deflection front and the saw blade as x [m] per frame (NaN: none yet).

    Keys ``damage``, ``deflection``, ``saw``; a value is None when the run stores no such series.
    ``front_position`` / ``saw_position`` are x already; a PST's ``front``, ``deflection_front`` and
    ``saw`` are distances from the saw's starting end (``saw.from_end``), 0 before there is any.
    """
    params = scene_params(run)
    out = {}
    for key, x_name, s_name in (("damage", "front_position", "front"), ("deflection", None, "deflection_front"),
                                ("saw", "saw_position", "saw")):
        if x_name in run.scalars:
            out[key] = run.scalars[x_name]
        elif s_name in run.scalars:
            s = np.where(run.scalars[s_name] > 0, run.scalars[s_name], np.nan)
            out[key] = params.distance_from_cut_end(s) if isinstance(params, PSTParams) else s
        else:
            out[key] = None
    return out


def front_and_saw_x(run: RunData) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Crack front and saw blade as x [m] per frame, NaN where there is none (see :func:`fronts_x`)."""
    f = fronts_x(run)
    return f["damage"], f["saw"]
