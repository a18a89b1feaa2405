"""The summary of a sweep: one CSV row per case and a figure of a result against a parameter."""

from __future__ import annotations

import csv
import json
import math

import numpy as np

from .io import atomic_write

__all__ = ["RESULT_FIELDS", "summary_row", "write_summary", "plot_summary", "number", "jsonable"]

#: RunResult fields copied into each record and summary row
RESULT_FIELDS = ("steps", "frames", "sim_time", "wall_time", "particle_steps_per_s", "n_particles", "device",
                 "edge_hits")


def jsonable(o):
    """JSON form of NumPy values (lists, numbers), else ``str``."""
    return o.tolist() if isinstance(o, (np.generic, np.ndarray)) else str(o)


def summary_row(params: dict, rec: dict) -> dict:
    """One summary row: the case's parameters, its scene results, last-frame scalars and run figures."""
    row = {"id": rec["id"], "status": rec["status"], **params}
    for k, v in rec.get("scene_result", {}).items():
        row[k] = v if v is None or isinstance(v, (int, float, str)) else json.dumps(v, default=jsonable)
    row.update({f"final_{k}": v for k, v in rec.get("final", {}).items()})
    row.update({k: rec.get("result", {}).get(k) for k in RESULT_FIELDS})
    row.update(elapsed_s=rec.get("elapsed_s"), worker=rec.get("worker"),
               output=rec["output"] if rec["status"] == "ok" else None, error=rec.get("error"))
    return row


def write_summary(path: str, rows: list, first: list) -> None:
    """The rows as CSV (``first`` columns first), written aside and moved in place."""
    cols = list(dict.fromkeys([*first, *(k for r in rows for k in r)]))

    def write(tmp):
        with open(tmp, "w", newline="") as fh:
            w = csv.DictWriter(fh, cols, restval="")
            w.writeheader()
            for r in rows:
                w.writerow({k: "" if v is None else json.dumps(v) if isinstance(v, (list, dict)) else v
                            for k, v in r.items()})

    atomic_write(path, write, "the sweep summary")


def number(v) -> float | None:
    """``v`` as a finite float, or None."""
    try:
        f = math.nan if v is None or isinstance(v, bool) else float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def plot_summary(rows: list, x: str, y: str, path: str, params=()) -> str | None:
    """Plot column ``y`` against parameter ``x`` of the ok rows, one line per value of the other ``params``
    (those not co-varied with ``x``).

    Returns the PNG path, or None when no row has a numeric ``y``.
    """
    from matplotlib.figure import Figure

    ok = [r for r in rows if r["status"] == "ok" and number(r.get(y)) is not None]
    if not ok:
        return None
    numeric = all(number(r.get(x)) is not None for r in ok)
    cats = list(dict.fromkeys(str(r.get(x)) for r in ok))
    key = {k: [str(r.get(k)) for r in ok] for k in (*params, x)}
    # one line per value of the other parameters, but for those that change with x (co-varied with it)
    others = [k for k in params if k != x and len(set(zip(key[x], key[k], strict=True))) > len(set(key[x]))]
    groups = {}
    for i, r in enumerate(ok):
        groups.setdefault(tuple((k, key[k][i]) for k in others), []).append(r)
    fig = Figure(figsize=(6.4, 4.2), layout="constrained")
    ax = fig.add_subplot()
    for g, rs in groups.items():
        pts = sorted((number(r[x]) if numeric else cats.index(str(r.get(x))), number(r[y])) for r in rs)
        ax.plot(*zip(*pts, strict=True), "o-", label=", ".join(f"{k} = {v}" for k, v in g) or None)
    if not numeric:
        ax.set_xticks(range(len(cats)), cats, rotation=30, ha="right")
    n_bad = len(rows) - len(ok)
    ax.set(xlabel=x, ylabel=y, title=f"{y} against {x}" + (f" ({n_bad} run(s) not shown)" if n_bad else ""))
    ax.grid(alpha=0.3)
    if len(groups) > 1:
        ax.legend(fontsize="small")
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format="png", dpi=120), "the sweep figure")
