"""Crack-front and shear-test diagnostics, and the analytical references (pure NumPy).

Everything here works on plain arrays (from a live run or a run file), so each
function can be tested on synthetic data with a known answer.

Conventions: ``s`` is the distance along the column from the end where the
saw started (m); a front position is such a distance; times in s; stresses
in Pa, compression positive.

References (MODEL.md 6-7):

- Heierli (2005), elastic slab on a collapsing layer, ``D_f = E h^3 / 12``:
  crack speed ``c = (g D_f / (2 h_f rho h))^(1/4)``, touchdown distance
  ``l = 2.331 (2 h_f D_f / (g rho h))^(1/4)``.
- Rayleigh speed ``c_R ~ c_s (0.862 + 1.14 nu) / (1 + nu)``, ``c_s = sqrt(mu/rho)``.
- Critical cut length on flat ground (Gaume et al. 2017):
  ``a_c = sqrt(2 tau_p E' D_wl / (G_wl rho g))``, ``E' = E / (1 - nu^2)``.
- Collapse under isotropic compression from ``p0_ini`` (MODEL.md 6):
  ``1 - J_P = 1 - exp(-(asinh(p/K) - asinh(p0_ini/K)) / xi)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "GRAVITY", "heierli_speed", "heierli_touchdown", "critical_cut_length_formula",
    "collapse_fraction", "front_position", "front_from_arrival", "LineFit",
    "steady_speed", "arrival_speed", "touchdown_distance", "marker_displacements", "pst_summary", "Bisection",
    "bisect_threshold", "critical_cut_length", "ShearSummary", "shear_summary",
]

GRAVITY = 9.81
"""Gravitational acceleration (m/s^2)."""


# ----------------------------------------------------------------------------- references
def heierli_speed(E: float, h: float, rho: float, h_f: float, g: float = GRAVITY) -> float:
    """Heierli's anticrack speed ``(g D_f / (2 h_f rho h))^(1/4)`` (m/s); inf for ``h_f <= 0``."""
    if h_f <= 0:
        return math.inf
    D_f = E * h**3 / 12.0
    return (g * D_f / (2.0 * h_f * rho * h)) ** 0.25


def heierli_touchdown(E: float, h: float, rho: float, h_f: float, g: float = GRAVITY) -> float:
    """Heierli's touchdown distance ``2.331 (2 h_f D_f / (g rho h))^(1/4)`` (m)."""
    D_f = E * h**3 / 12.0
    return 2.331 * (2.0 * max(h_f, 0.0) * D_f / (g * rho * h)) ** 0.25


def critical_cut_length_formula(tau_p: float, E: float, nu: float, D_wl: float, G_wl: float, rho: float,
                                g: float = GRAVITY) -> float:
    """Flat-ground critical cut length ``sqrt(2 tau_p E' D_wl / (G_wl rho g))`` (m), ``E' = E/(1-nu^2)``."""
    return math.sqrt(2.0 * tau_p * E / (1.0 - nu**2) * D_wl / (G_wl * rho * g))


# ----------------------------------------------------------------------------- collapse and front
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
    """

    speed: float
    intercept: float
    r2: float
    n: int


def _fit(x, y) -> tuple[float, float, float, int]:
    if len(x) < 3 or np.ptp(x) == 0:
        return math.nan, math.nan, math.nan, len(x)
    a, b = np.polyfit(x, y, 1)
    res = y - (a * x + b)
    ss = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / ss if ss > 0 else 1.0
    return float(a), float(b), r2, len(x)


def steady_speed(t, front, lo: float, hi: float) -> LineFit:
    """Front speed (m/s): line through the samples ``(t, front)`` with ``lo <= front <= hi`` (m).

    Repeated positions (a front that stopped, or frames sampling one bin twice)
    keep only their first time, so an arrested front does not bias the slope.
    """
    t = np.asarray(t, dtype=float)
    f = np.asarray(front, dtype=float)
    m = (f >= lo) & (f <= hi)
    t, f = t[m], f[m]
    if f.size:
        _, first = np.unique(f, return_index=True)
        t, f = t[first], f[first]
    a, b, r2, n = _fit(t, f)
    return LineFit(a, b, r2, n)


def arrival_speed(s, t_arrival, lo: float, hi: float) -> LineFit:
    """Front speed (m/s) from first-failure times: ``1 / slope`` of ``t_arrival(s)`` on ``lo <= s <= hi``."""
    s = np.asarray(s, dtype=float)
    t = np.asarray(t_arrival, dtype=float)
    m = (s >= lo) & (s <= hi) & np.isfinite(t)
    a, b, r2, n = _fit(s[m], t[m])
    speed = 1.0 / a if a and np.isfinite(a) and a > 0 else math.nan
    return LineFit(speed, b, r2, n)


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


# ----------------------------------------------------------------------------- PST summary
def pst_summary(scene: dict, times, series: dict, arrival=None) -> dict:
    """Crack speed, touchdown distance and collapse from PST frame series.

    Speed: least-squares line through the front positions (or the bin arrival
    times when given) on the steady part, the middle of the self-propagation
    path: from ``cut + 0.3 (L - cut)`` to ``cut + 0.85 (L - cut)``.
    Touchdown: :func:`touchdown_distance` on the slab-base marker profiles at
    the frames where the front lies in that window. Collapse: the last frame's
    ``collapse_height``. Initiation (with ``arrival``): position and time of the
    first collapse beyond the cut (``s > cut + 2 bins``); ``initiated_at_saw`` when
    it lies within ``0.1 L`` of the cut (else the crack started elsewhere, e.g. at
    the far end of the column, and ``apparent_speed`` = ``1 / |slope|`` of the
    arrival times beyond the cut tells how fast it swept the column).
    """
    d = scene["derived"]
    L = float(scene["length"])
    cut = float(scene["saw"]["cut_length"])
    lo, hi = cut + 0.3 * (L - cut), cut + 0.85 * (L - cut)
    t = np.asarray(times, dtype=float)
    front = np.asarray(series["front"], dtype=float)
    after = t >= float(d["saw_end"])
    out = {"front_final": float(front[-1]) if len(front) else 0.0, "cut_length": cut, "column_length": L,
           "propagated": bool(len(front) and front[-1] >= cut + 0.5 * (L - cut)),
           "ran_to_end": bool(len(front) and front[-1] >= L - 2.0 * float(d["bin"]))}
    fit = steady_speed(t[after], front[after], lo, hi)
    out["speed_frames"] = fit.speed
    if arrival is not None:
        sb, tb = arrival
        fit_b = arrival_speed(sb, tb, lo, hi)
        out["speed_arrival"] = fit_b.speed
        out["speed_arrival_r2"] = fit_b.r2
        sb, tb = np.asarray(sb, dtype=float), np.asarray(tb, dtype=float)
        beyond = (sb > cut + 2.0 * float(d["bin"])) & np.isfinite(tb)
        if beyond.any():
            k = int(np.argmin(np.where(beyond, tb, np.inf)))
            out["initiation_position"] = float(sb[k])
            out["initiation_time"] = float(tb[k])
            out["initiated_at_saw"] = bool(sb[k] <= cut + 0.1 * L)
            a, _, _, n = _fit(sb[beyond], tb[beyond])
            out["apparent_speed"] = abs(1.0 / a) if n >= 3 and np.isfinite(a) and a != 0 else math.nan
        else:
            out["initiated_at_saw"] = False
    out["speed"] = out.get("speed_arrival", fit.speed)
    out["speed_fit_window"] = [lo, hi]
    ch = np.asarray(series.get("collapse_height", [0.0]), dtype=float)
    out["collapse_height"] = float(ch[-1]) if len(ch) else 0.0
    markers = np.asarray(d["markers"], dtype=float)
    uy = np.stack([np.asarray(series[f"marker{k}_uy"], dtype=float) for k in range(len(markers))], axis=1)
    s_markers = markers if scene["saw"]["from_end"] == "left" else L - markers
    i0 = int(np.searchsorted(t, float(d["saw_start"])))
    i0 = min(i0, len(t) - 1)
    w = -(uy - uy[i0])  # downward deflection of the slab base since the saw started (m)
    td = []
    for i in np.nonzero((front >= lo) & (front <= hi))[0]:
        val = touchdown_distance(s_markers, w[i], front[i], s_min=cut)
        if np.isfinite(val):
            td.append(val)
    out["touchdown"] = float(np.median(td)) if td else float("nan")
    out["slab_deflection_final"] = float(np.median(w[-1][s_markers < front[-1]])) if (s_markers < front[-1]).any() \
        else 0.0
    for k in ("heierli_speed", "heierli_touchdown", "rayleigh_speed", "shear_wave_speed", "collapse_height_law"):
        out[k] = float(d[k])
    return out


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
    crack ran by itself past the cut (e.g. ``run_pst(..., {"scene.saw.cut_length": a})``
    and ``extra["propagated"]``). Longer cuts propagate when shorter ones do.
    """
    return bisect_threshold(propagates, lo, hi, tol, max_evaluations=max_runs)


# ----------------------------------------------------------------------------- shear test
@dataclass(frozen=True)
class ShearSummary:
    """Shear test results (SI Note 2).

    Attributes
    ----------
    peak_stress, residual_stress : float
        Peak (intact) and residual shear stress (Pa). The peak is the maximum before the
        stress first falls below half of its running maximum (the failure); the residual
        may exceed it when the collapsed layer hardens.
    peak_displacement : float
        Shear displacement at the peak (m).
    softening_displacement : float
        Critical sliding displacement (m): from the peak to the end of the softening
        zone, the first point where the stress is within ``(1 - drop) max(peak - residual,
        residual - minimum)`` of the residual, searched after the post-peak minimum when
        the stress undershoots the residual (the layer slides at a low stress while it
        collapses, then recovers to the residual friction); nan if never.
    drop_displacement : float
        Displacement (m) from the peak to the first point where the stress has fallen
        by ``drop`` of ``peak - residual`` (how abrupt the loss of strength is); nan if never.
    collapse_fraction : float
        Final weak-layer thickness change over its thickness (-), positive for compaction.
    peak_index, softened_index : int
        Sample indices of the peak and of the end of softening (-1 if none).
    """

    peak_stress: float
    residual_stress: float
    peak_displacement: float
    softening_displacement: float
    drop_displacement: float
    collapse_fraction: float
    peak_index: int
    softened_index: int


def _crossing(u, tau, ip: int, cond) -> tuple[int, float]:
    """First index after ``ip`` where ``cond(tau)`` holds and the displacement from the peak there."""
    idx = np.nonzero((np.arange(len(u)) > ip) & cond(tau))[0]
    if idx.size == 0:
        return -1, math.nan
    j = int(idx[0])
    return j, float(u[j] - u[ip])


def shear_summary(u, tau, axial, residual_window: float = 0.2, drop: float = 0.9) -> ShearSummary:
    """Peak, residual, softening displacement and collapse from shear-test curves.

    Parameters
    ----------
    u : array
        Shear (sliding) displacement of the loaded top relative to the base (m), increasing.
    tau : array
        Shear stress (Pa).
    axial : array
        Weak-layer thickness change over its thickness (-), positive for compaction.
    residual_window : float
        The residual stress is the mean over the last ``residual_window`` of the displacement range.
    drop : float
        Fraction of ``peak - residual`` defining the end of the stress drop and, as its
        complement, the band around the residual that ends the softening zone.
    """
    u = np.asarray(u, dtype=float)
    tau = np.asarray(tau, dtype=float)
    axial = np.asarray(axial, dtype=float)
    # the peak is the intact layer's strength: the maximum before the first failure, i.e. before
    # the stress first falls below half its running maximum (a collapsed layer may later harden
    # to a frictional strength above it); without such a drop, the global maximum
    run_max = np.maximum.accumulate(tau)
    fail = np.nonzero((run_max > 0) & (tau < 0.5 * run_max))[0]
    ip = int(np.argmax(tau[: fail[0]])) if fail.size else int(np.argmax(tau))
    tp = float(tau[ip])
    u_end = float(u[-1])
    tail = u >= u_end - residual_window * (u_end - float(u[0]))
    tail &= np.arange(len(u)) > ip
    tr = float(np.mean(tau[tail])) if tail.any() else float(tau[-1])
    delta = tp - tr
    if ip + 1 < len(tau) and (delta > 0 or float(np.min(tau[ip + 1:])) < 0.5 * tp):
        lowest = min(tr, float(np.min(tau[ip + 1:])))
        _, d_drop = _crossing(u, tau, ip, lambda x: x <= tp - drop * (tp - lowest))
        jmin = ip + 1 + int(np.argmin(tau[ip + 1:]))
        band = (1.0 - drop) * max(delta, tr - float(tau[jmin]))
        start = jmin if tau[jmin] < tr - band else ip
        js, _ = _crossing(u, tau, start, lambda x: np.abs(x - tr) <= band)
        d_soft = float(u[js] - u[ip]) if js >= 0 else math.nan
    else:
        d_drop, js, d_soft = math.nan, -1, math.nan
    return ShearSummary(tp, tr, float(u[ip]), d_soft, d_drop, float(axial[-1]), ip, js)
