"""Results of a PST from its frame series (pure NumPy): crack speed, touchdown distance, collapse, initiation."""

from __future__ import annotations

import math

import numpy as np

from ..fronts import arrival_speed, line_fit, steady_speed, touchdown_distance
from .params import PSTParams

__all__ = ["pst_summary"]


def pst_summary(params: PSTParams, times, series: dict, arrival=None) -> dict:
    """Crack speed, touchdown distance and collapse from PST frame series.

    Speed: least-squares line through the front positions (or the bin arrival
    times when given) on the steady part, the middle of the self-propagation
    path (:meth:`PSTParams.speed_fit_window`: from ``cut + 0.3 (L - cut)`` to ``cut + 0.85 (L - cut)``).
    Touchdown: :func:`~mpm_warp.scenes.fronts.touchdown_distance` on the slab-base marker profiles at
    the frames where the front lies in that window. Collapse: the last frame's
    ``collapse_height``. Initiation (with ``arrival``): position and time of the
    first collapse beyond the cut (``s > cut + 2 bins``); ``initiated_at_saw`` when
    it lies within ``0.1 L`` of the cut (else the crack started elsewhere, e.g. at
    the far end of the column, and ``apparent_speed`` = ``1 / |slope|`` of the
    arrival times beyond the cut tells how fast it swept the column). The closed-form
    references of :meth:`PSTParams.references` are copied in.

    Parameters
    ----------
    params : PSTParams
    times : array (n,)
        Frame times (s).
    series : dict
        ``front`` (m), ``collapse_height`` (m), ``marker{k}_uy`` (m) per frame.
    arrival : (array, array), optional
        Bin centres (m from the cut end) and their first-collapse times (s, inf = never).
    """
    L = float(params.length)
    cut = float(params.saw.cut_length)
    lo, hi = params.speed_fit_window()
    bin_w = params.bin_width
    t = np.asarray(times, dtype=float)
    front = np.asarray(series["front"], dtype=float)
    after = t >= params.saw_end
    out = {"front_final": float(front[-1]) if len(front) else 0.0, "cut_length": cut, "column_length": L,
           "propagated": bool(len(front) and front[-1] >= cut + 0.5 * (L - cut)),
           "ran_to_end": bool(len(front) and front[-1] >= L - 2.0 * bin_w)}
    fit = steady_speed(t[after], front[after], lo, hi)
    out["speed_frames"] = fit.speed
    if arrival is not None:
        sb, tb = arrival
        fit_b = arrival_speed(sb, tb, lo, hi)
        out["speed_arrival"] = fit_b.speed
        out["speed_arrival_r2"] = fit_b.r2
        sb, tb = np.asarray(sb, dtype=float), np.asarray(tb, dtype=float)
        beyond = (sb > cut + 2.0 * bin_w) & np.isfinite(tb)
        if beyond.any():
            k = int(np.argmin(np.where(beyond, tb, np.inf)))
            out["initiation_position"] = float(sb[k])
            out["initiation_time"] = float(tb[k])
            out["initiated_at_saw"] = bool(sb[k] <= cut + 0.1 * L)
            a, _, _, n = line_fit(sb[beyond], tb[beyond])
            out["apparent_speed"] = abs(1.0 / a) if n >= 3 and np.isfinite(a) and a != 0 else math.nan
        else:
            out["initiated_at_saw"] = False
    out["speed"] = out.get("speed_arrival", fit.speed)
    out["speed_fit_window"] = [lo, hi]
    ch = np.asarray(series.get("collapse_height", [0.0]), dtype=float)
    out["collapse_height"] = float(ch[-1]) if len(ch) else 0.0
    markers = params.markers()
    uy = np.stack([np.asarray(series[f"marker{k}_uy"], dtype=float) for k in range(len(markers))], axis=1)
    s_markers = params.distance_from_cut_end(markers)
    i0 = min(int(np.searchsorted(t, params.saw_start)), len(t) - 1)
    w = -(uy - uy[i0])  # downward deflection of the slab base since the saw started (m)
    td = []
    for i in np.nonzero((front >= lo) & (front <= hi))[0]:
        val = touchdown_distance(s_markers, w[i], front[i], s_min=cut)
        if np.isfinite(val):
            td.append(val)
    out["touchdown"] = float(np.median(td)) if td else float("nan")
    out["slab_deflection_final"] = float(np.median(w[-1][s_markers < front[-1]])) if (s_markers < front[-1]).any() \
        else 0.0
    refs = params.references()
    for k in ("heierli_speed", "heierli_touchdown", "rayleigh_speed", "shear_wave_speed", "collapse_height_law"):
        out[k] = float(refs[k])
    return out
