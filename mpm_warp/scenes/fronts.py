"""Crack fronts in plain arrays (pure NumPy): front positions, the front-speed fit, touchdown, bisection.

Everything here works on plain arrays (from a live run or a run file), so each function can be
tested on synthetic data with a known answer. The PST monitor uses it while running and the
post-processing (:mod:`mpm_warp.post.fronts`) on run files: :func:`steady_speed` is the one
front-speed fit.

Conventions: ``s`` is the distance along the column from the end where the saw started (m); a
front position is such a distance; times in s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["collapse_fraction", "front_position", "front_from_arrival", "fit_window", "LineFit", "steady_speed",
           "arrival_speed", "front_trajectory", "speed_profile", "mean_speed", "lead_ahead_of_front",
           "touchdown_distance", "marker_displacements", "Bisection", "bisect_threshold", "critical_cut_length",
           "line_fit"]


def collapse_fraction(log_jp, log_jp_ref) -> np.ndarray:
    """Plastic volume collapse relative to a reference state, ``1 - exp(log_jp - log_jp_ref)`` (-).

    Positive for compaction, negative for dilation.
    """
    return 1.0 - np.exp(np.asarray(log_jp, dtype=float) - np.asarray(log_jp_ref, dtype=float))


def front_position(s, failed, bin_width: float, length: float | None = None) -> float:
    """Crack front from a per-particle failure flag (m from the cut end).

    Particles are binned by ``s`` into bins of ``bin_width``; a bin has failed
    when any of its particles has. The front is the far edge of the contiguous
    run of failed bins starting at ``s = 0`` (0 if the first bin is intact).
    ``length`` bounds the number of bins (default: the largest ``s``).
    """
    s = np.asarray(s, dtype=float)
    failed = np.asarray(failed, dtype=bool)
    if s.size == 0:
        return 0.0
    L = float(length) if length is not None else float(s.max()) + 1e-12
    n = max(1, int(math.ceil(L / bin_width - 1e-9)))
    b = np.floor(s[failed] / bin_width).astype(int)
    hit = np.zeros(n, dtype=bool)
    hit[b[(b >= 0) & (b < n)]] = True
    return _contiguous_edge(hit) * bin_width


def _contiguous_edge(hit: np.ndarray) -> int:
    """Number of leading True entries."""
    if hit.size == 0 or not hit[0]:
        return 0
    off = np.nonzero(~hit)[0]
    return int(off[0]) if off.size else int(hit.size)


def front_from_arrival(arrival, t: float, bin_width: float) -> float:
    """Front position (m) at time ``t`` from per-bin first-failure times (s, inf = not yet)."""
    return _contiguous_edge(np.asarray(arrival, dtype=float) <= t) * bin_width


def fit_window(start: float, end: float, lo: float, hi: float) -> tuple[float, float]:
    """Positions ``(start + lo (end - start), start + hi (end - start))`` (m): the steady part of a front's path."""
    return start + lo * (end - start), start + hi * (end - start)


@dataclass(frozen=True)
class LineFit:
    """Least-squares line fit.

    Attributes
    ----------
    speed : float
        Fitted front speed (m/s); nan when fewer than 3 points.
    intercept : float
        Front position at t = 0 (m) for :func:`steady_speed`, arrival time at s = 0 (s) for
        :func:`arrival_speed`.
    r2 : float
        Coefficient of determination of the fit.
    n : int
        Points used.
    t_start, t_end : float
        Times of the first and last point used (s); nan without points.
    """

    speed: float
    intercept: float
    r2: float
    n: int
    t_start: float = math.nan
    t_end: float = math.nan


def line_fit(x, y) -> tuple[float, float, float, int]:
    """Least-squares line ``y = a x + b``: ``(a, b, r2, n)``; nan values with fewer than 3 points or one ``x``."""
    if len(x) < 3 or np.ptp(x) == 0:
        return math.nan, math.nan, math.nan, len(x)
    a, b = np.polyfit(x, y, 1)
    res = y - (a * x + b)
    ss = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / ss if ss > 0 else 1.0
    return float(a), float(b), r2, len(x)


def _span(t) -> tuple[float, float]:
    return (float(np.min(t)), float(np.max(t))) if len(t) else (math.nan, math.nan)


def steady_speed(t, front, lo: float, hi: float) -> LineFit:
    """Front speed (m/s): line through the samples ``(t, front)`` with ``lo <= front <= hi`` (m).

    Repeated positions (a front that stopped, or frames sampling one bin twice)
    keep only their first time, so an arrested front does not bias the slope.
    Non-finite samples are left out.
    """
    t = np.asarray(t, dtype=float)
    f = np.asarray(front, dtype=float)
    m = np.isfinite(t) & np.isfinite(f) & (f >= lo) & (f <= hi)
    t, f = t[m], f[m]
    if f.size:
        _, first = np.unique(f, return_index=True)
        t, f = t[first], f[first]
    a, b, r2, n = line_fit(t, f)
    return LineFit(a, b, r2, n, *_span(t))


def arrival_speed(s, t_arrival, lo: float, hi: float) -> LineFit:
    """Front speed (m/s) from first-failure times: ``1 / slope`` of ``t_arrival(s)`` on ``lo <= s <= hi``."""
    s = np.asarray(s, dtype=float)
    t = np.asarray(t_arrival, dtype=float)
    m = (s >= lo) & (s <= hi) & np.isfinite(t)
    a, b, r2, n = line_fit(s[m], t[m])
    speed = 1.0 / a if a and np.isfinite(a) and a > 0 else math.nan
    return LineFit(speed, b, r2, n, *_span(t[m]))


def front_trajectory(s, t_arrival) -> tuple[np.ndarray, np.ndarray]:
    """The contiguous front's path: the bins from the cut end and the times the front passed them.

    A front passes bin ``k`` once every bin up to it has arrived, at ``max(t_arrival[:k + 1])`` (s);
    returns the bin positions ``s`` (m) and those times up to the first bin not reached (the cumulative
    maximum stops being finite there).
    """
    s = np.asarray(s, dtype=float)
    T = np.maximum.accumulate(np.asarray(t_arrival, dtype=float))
    n = int(np.argmax(~np.isfinite(T))) if not np.isfinite(T).all() else len(T)
    return s[:n], T[:n]


def speed_profile(s, T, window: float, start: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Local front speed (m/s) along its path ``(s, T)`` from :func:`front_trajectory`, from ``start`` (m) on.

    A line ``T(s)`` is fitted over windows of ``window`` (m) sliding by half a window; the speed is
    ``1 / slope``. Returns the window centres (m) and the speeds (nan where the fit is undefined).
    """
    s, T = np.asarray(s, dtype=float), np.asarray(T, dtype=float)
    mids, speeds = [], []
    a = float(start)
    while len(s) and a + window <= s[-1] + 1e-12:
        m = (s >= a) & (s <= a + window)
        slope, _, _, n = line_fit(s[m], T[m])
        mids.append(a + 0.5 * window)
        speeds.append(1.0 / slope if n >= 3 and np.isfinite(slope) and slope > 0 else math.nan)
        a += 0.5 * window
    return np.asarray(mids), np.asarray(speeds)


def mean_speed(s, T, s0: float, s1: float) -> float:
    """Mean front speed (m/s) from ``s0`` to ``s1`` (m) on the path ``(s, T)``; nan if the front did not reach ``s1``.

    Measured from the first station at or beyond ``s0`` (the bins before it, e.g. the saw's, do not
    enter): ``(s1 - s_a) / (T(s1) - T(s_a))``, ``T(s1)`` interpolated.
    """
    s, T = np.asarray(s, dtype=float), np.asarray(T, dtype=float)
    if not len(s) or s[-1] < s1 or s[0] > s0:
        return math.nan
    a = int(np.searchsorted(s, s0 - 1e-12))
    if a >= len(s) or s[a] >= s1:
        return math.nan
    dt = float(np.interp(s1, s[a:], T[a:]) - T[a])
    return (s1 - float(s[a])) / dt if dt > 0 else math.inf


def lead_ahead_of_front(s, t_arrival) -> tuple[float, float]:
    """How far ahead of the contiguous front a bin arrived: ``(largest lead (m), the bin's position (m))``.

    For every arrived bin, the front's position at its arrival time is subtracted from its own. A
    crack that starts at the saw and runs from there leads by a process zone at most; damage at the
    far end before the front arrives shows as a lead of metres.
    """
    s, t = np.asarray(s, dtype=float), np.asarray(t_arrival, dtype=float)
    sp, T = front_trajectory(s, t)
    k = np.nonzero(np.isfinite(t))[0]
    if not len(k):
        return 0.0, math.nan
    half = 0.5 * (s[1] - s[0]) if len(s) > 1 else 0.0
    passed = np.searchsorted(T, t[k], side="right")           # bins the front had passed (T is non-decreasing)
    front = np.where(passed > 0, sp[np.maximum(passed - 1, 0)] + half, 0.0)
    lead = s[k] - front
    j = int(np.argmax(lead))
    return (float(lead[j]), float(s[k[j]])) if lead[j] > 0 else (0.0, math.nan)


def touchdown_distance(s, w, front: float, w_collapsed: float | None = None, level: float = 0.95,
                       s_min: float = 0.0) -> float:
    """Distance (m) behind the front at which the slab touches down on the collapsed layer.

    ``w(s)`` is the downward deflection of the slab base at stations ``s``. Behind
    the front the deflection grows from ~0 to the collapse height ``w_collapsed``
    (default: the 90th percentile of ``w`` over ``s_min <= s < front``). The
    touchdown point is the station nearest the front, behind it, where ``w``
    first reaches ``level * w_collapsed`` (linear interpolation between stations);
    the result is ``front - s_td``; nan if none (or no deflection).
    """
    s = np.asarray(s, dtype=float)
    w = np.asarray(w, dtype=float)
    order = np.argsort(s)
    s, w = s[order], w[order]
    m = (s >= s_min) & (s < front)
    if m.sum() < 2:
        return math.nan
    sb, wb = s[m], w[m]
    wc = float(np.percentile(wb, 90)) if w_collapsed is None else float(w_collapsed)
    if not wc > 0:
        return math.nan
    target = level * wc
    above = np.nonzero(wb >= target)[0]
    if above.size == 0:
        return math.nan
    j = int(above[-1])  # last station behind the front at or above the target
    s_td = sb[j]
    if j + 1 < sb.size and wb[j + 1] < target:  # interpolate towards the front
        f = (wb[j] - target) / (wb[j] - wb[j + 1])
        s_td = sb[j] + f * (sb[j + 1] - sb[j])
    return float(front - s_td)


def marker_displacements(x_frames, x0, markers_xy) -> np.ndarray:
    """Displacements (n_frames, n_markers, 3) (m) of the particles nearest to marker points at t = 0.

    ``x_frames`` (n_frames, N, 3) positions, ``x0`` (N, 3) initial positions,
    ``markers_xy`` (n_markers, 2) marker (x, y) positions (m).
    """
    x0 = np.asarray(x0, dtype=float)
    mk = np.asarray(markers_xy, dtype=float)
    d2 = (x0[None, :, 0] - mk[:, None, 0]) ** 2 + (x0[None, :, 1] - mk[:, None, 1]) ** 2
    idx = np.argmin(d2, axis=1)
    return np.asarray(x_frames, dtype=float)[:, idx, :] - x0[idx][None]


# ----------------------------------------------------------------------------- bisection
@dataclass(frozen=True)
class Bisection:
    """Result of :func:`bisect_threshold`.

    Attributes
    ----------
    value : float
        Midpoint of the final bracket (the threshold estimate).
    lo, hi : float
        Final bracket: ``predicate(lo)`` False, ``predicate(hi)`` True.
    evaluations : list of (float, bool)
        Every point tried and its outcome, in order.
    """

    value: float
    lo: float
    hi: float
    evaluations: list


def bisect_threshold(predicate: Callable[[float], bool], lo: float, hi: float, tol: float,
                     max_evaluations: int = 50, check_ends: bool = True) -> Bisection:
    """Smallest ``a`` in ``[lo, hi]`` with ``predicate(a)`` True, for a monotone predicate (False then True).

    Bisects until the bracket is below ``tol``. With ``check_ends`` the ends are
    evaluated first; ``ValueError`` if ``predicate(hi)`` is False or
    ``predicate(lo)`` True (the threshold is outside the bracket).
    """
    if not hi > lo or not tol > 0:
        raise ValueError(f"need lo < hi and tol > 0 (got lo={lo}, hi={hi}, tol={tol})")
    ev = []
    if check_ends:
        for a, want in ((hi, True), (lo, False)):
            r = bool(predicate(a))
            ev.append((a, r))
            if r != want:
                raise ValueError(f"threshold not bracketed: predicate({a:g}) = {r}")
    while hi - lo > tol and len(ev) < max_evaluations:
        mid = 0.5 * (lo + hi)
        r = bool(predicate(mid))
        ev.append((mid, r))
        if r:
            hi = mid
        else:
            lo = mid
    return Bisection(0.5 * (lo + hi), lo, hi, ev)


def critical_cut_length(propagates: Callable[[float], bool], lo: float, hi: float, tol: float = 0.05,
                        max_runs: int = 12) -> Bisection:
    """Critical cut length (m) by bisection over runs.

    ``propagates(a)`` runs a PST with cut length ``a`` (m) and says whether the
    crack ran by itself past the cut (e.g. ``mw.run("pst_demo", overrides=[f"scene.saw.cut_length={a}"])``
    and ``scene_result["propagated"]``). Longer cuts propagate when shorter ones do.
    """
    return bisect_threshold(propagates, lo, hi, tol, max_evaluations=max_runs)
