"""Convergence of a ladder of resolutions: observed orders, Richardson extrapolation, run time to an error.

The one home of this arithmetic for the reference problems' ladders, the snow ladders and the mesh
study. A ladder lists its levels coarse to fine: grid spacings ``h`` (halving, or any fixed ratio),
a measured value or an error per level, and each level's wall time.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["loglog_slope", "observed_order", "richardson", "time_to", "time_to_target", "ladder_summary"]


def loglog_slope(x, y) -> float:
    """Least-squares slope of ``ln y`` against ``ln x`` over the pairs where both are finite and > 0.

    nan when fewer than two such pairs remain.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0]) if ok.sum() >= 2 else math.nan


def observed_order(h, err) -> float:
    """Observed order of convergence: the slope of ``ln err`` against ``ln h`` (:func:`loglog_slope`)."""
    return loglog_slope(h, err)


def richardson(h, v) -> tuple[float, float]:
    """Richardson extrapolation of the three finest levels: ``(value, order)``.

    With ``a, b, c`` the values at the three finest spacings (ratio ``r = h[-2] / h[-1]``, the same for
    both steps), the order is ``p = ln|(b - a) / (c - b)| / ln r`` and the value ``c + (c - b) / (r^p - 1)``.
    ``(nan, nan)`` when the changes are not monotone (or a value is missing), ``(nan, p)`` when ``p``
    lies outside ``[0.5, 4]``, where the levels are not in the asymptotic range.
    """
    if len(v) < 3 or not all(np.isfinite(v[-3:])):
        return math.nan, math.nan
    h1, h2, h3 = (float(x) for x in h[-3:])
    r = h2 / h3
    if not (r > 1.0 and math.isclose(h1 / h2, r, rel_tol=1e-6)):
        raise ValueError(f"richardson: the three finest spacings {h1:g}, {h2:g}, {h3:g} need one ratio > 1")
    a, b, c = v[-3:]
    if (b - a) == 0 or (c - b) == 0 or (c - b) / (b - a) <= 0:
        return math.nan, math.nan
    p = math.log(abs((b - a) / (c - b))) / math.log(r)
    if not 0.5 <= p <= 4.0:
        return math.nan, p
    return c + (c - b) / (r**p - 1.0), p


def _loglog(a: float, b: float, s: float) -> float:
    """The point a fraction ``s`` of the way from ``a`` to ``b`` in log scale."""
    return math.exp(math.log(a) + s * (math.log(b) - math.log(a)))


def time_to(errors, walls, target: float) -> dict:
    """Wall time (s) to ``target`` error along the ladder (coarse to fine), interpolated in log-log.

    A level whose wall time is nan (run elsewhere, e.g. on a GPU) is left out unless its error is 0 (it
    is the reference); a level without a value (error nan: a PST whose crack did not run) has met no
    target. Returns ``{"status", ...}``: ``interpolated`` (``wall_time_s`` and ``between_levels``, the
    two levels of the ladder it lies between, and ``fraction``, where between them in log error),
    ``already at the coarsest``, ``first met where the quantity first exists``, ``met where the value
    first equals the finest's``, ``at the finest (the reference)``, ``not reached`` or ``no data``.
    """
    if not any(np.isfinite(e) for e in errors):
        return {"status": "no data"}
    pts = [(e if np.isfinite(e) else math.inf, w, k) for k, (e, w) in enumerate(zip(errors, walls, strict=True))
           if np.isfinite(w) or e == 0.0]
    if pts[0][0] <= target:
        return {"status": "already at the coarsest", "wall_time_s": pts[0][1]}
    for i, ((e1, w1, k1), (e2, w2, k2)) in enumerate(zip(pts, pts[1:], strict=False)):
        if math.isinf(e1) and target >= e2:
            return {"status": "first met where the quantity first exists", "wall_time_s": w2}
        if e1 > target >= e2 and e2 > 0:
            s = (math.log(target) - math.log(e1)) / (math.log(e2) - math.log(e1))
            return {"status": "interpolated", "wall_time_s": _loglog(w1, w2, s), "between_levels": [k1, k2],
                    "fraction": s}
        if e1 > target and e2 == 0.0:   # no log-log line to 0: the level that first has no error
            status = ("at the finest (the reference)" if i + 2 == len(pts)
                      else "met where the value first equals the finest's")
            return {"status": status, "wall_time_s": w2 if np.isfinite(w2) else None}
    return {"status": "not reached", "error_at_finest_compared": pts[-1][0]}


def time_to_target(runs: list[dict], target: float) -> dict:
    """:func:`time_to` over validation records (``error``, ``wall_time_s``, ``dx``; coarse to fine).

    Adds the spacing at the target (``dx``, log-log like the time) and the two runs it lies between
    (``between``) when interpolated, and the error, wall time and ``dx`` of the coarsest or finest run
    when the target is met at the first level or not reached.
    """
    rs = [r for r in runs if r.get("error") is not None and math.isfinite(r["error"]) and r["error"] > 0]
    if not rs:
        return {"status": "no valid runs"}
    out = time_to([r["error"] for r in rs], [r["wall_time_s"] for r in rs], target)
    if out["status"] == "interpolated":
        a, b = (rs[k] for k in out.pop("between_levels"))
        out["dx"] = _loglog(a["dx"], b["dx"], out.pop("fraction"))
        out["between"] = [{"dx": r["dx"], "error": r["error"], "wall_time_s": r["wall_time_s"]} for r in (a, b)]
    elif out["status"] in ("already at the coarsest", "not reached"):
        r = rs[0] if out["status"] != "not reached" else rs[-1]
        out.update(error=r["error"], wall_time_s=r["wall_time_s"], dx=r["dx"])
    return out


def ladder_summary(levels: list[dict], quantities, targets=(0.05, 0.01)) -> dict:
    """Per quantity: the errors of each level against the finest and against Richardson, and times to targets.

    ``levels`` are records (coarse to fine) with ``dx``, ``wall_time_s``, optionally ``device`` (a level
    not run on ``"cpu"`` gives no wall time here) and a value per quantity (None or nan when missing).
    The reference is the finest level that has the quantity. Returns per quantity ``values``,
    ``error_vs_finest``, ``richardson``, ``observed_order``, ``error_vs_richardson``, ``reference_level``,
    ``time_to`` (per target, as ``"5%"``; against Richardson when it exists, else the finest) and
    ``reference_used_for_time_to``.
    """
    out = {}
    if len(levels) < 2:
        return out
    walls = [lv["wall_time_s"] if lv.get("device", "cpu") == "cpu" else math.nan for lv in levels]
    h = [lv["dx"] for lv in levels]
    for q in quantities:
        v = np.array([lv[q] if lv[q] is not None else math.nan for lv in levels], float)
        finite = np.flatnonzero(np.isfinite(v))
        if len(finite):
            v = v[:finite[-1] + 1]
        ref = v[-1]
        err = np.abs(v / ref - 1.0) if np.isfinite(ref) and ref != 0 else np.full(len(v), math.nan)
        rich, p = richardson(h[:len(v)], v)
        err_r = np.abs(v / rich - 1.0) if np.isfinite(rich) else np.full(len(v), math.nan)
        use = err_r if np.isfinite(rich) else err
        out[q] = {"values": v.tolist(), "error_vs_finest": err.tolist(), "richardson": rich, "observed_order": p,
                  "error_vs_richardson": err_r.tolist(), "reference_level": len(v) - 1,
                  "time_to": {f"{round(100 * t)}%": time_to(list(use), walls[:len(v)], t) for t in targets},
                  "reference_used_for_time_to": "richardson" if np.isfinite(rich) else "finest level"}
    return out


def errors_against_reference(rec: dict, summary: dict, quantities) -> dict:
    """A level off the ladder (e.g. the field protocol's resolution) against the ladder's reference.

    The reference of each quantity is the one the ladder's ``time_to`` uses (:func:`ladder_summary`): the
    Richardson value where it exists, else the finest level's value. Returns per quantity ``value``,
    ``reference``, ``reference_is`` ("richardson" or "finest level") and ``error`` (relative; nan where a value
    is missing); where ``rec`` has a ``<quantity>_bracket`` (a bisection), also its ``half_width`` (relative):
    an error below the brackets' half widths is not resolved.
    """
    out = {}
    for q in quantities:
        s = summary.get(q)
        if not s:
            continue
        rich = s.get("richardson")
        use_r = s.get("reference_used_for_time_to") == "richardson" and rich is not None and math.isfinite(rich)
        ref = rich if use_r else s["values"][-1]
        v = rec.get(q)
        ok = v is not None and math.isfinite(v) and ref is not None and math.isfinite(ref) and ref != 0
        out[q] = {"value": v, "reference": ref, "reference_is": "richardson" if use_r else "finest level",
                  "error": abs(v / ref - 1.0) if ok else math.nan}
        if ok and rec.get(q + "_bracket"):
            lo, hi = rec[q + "_bracket"]
            out[q]["half_width"] = 0.5 * (hi - lo) / v
    return out
