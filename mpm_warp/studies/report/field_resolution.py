"""Field cases at 4 and at 6 cells across the weak layer (benchmarks/field/resolution.py): a what-if of the grid."""

from __future__ import annotations

import re
from statistics import median

from .core import section
from .field_what_if import CUT_SHARE, change, command, cut, failed_lines, labels, ran, render_what_if
from .fmt import fx


def _depth(test: str) -> float | None:
    """The weak layer's depth (cm) in a field line ``PST 30/100 (End) down 41 cm``."""
    m = re.search(r"down (\d+(?:\.\d+)?) cm", test)
    return float(m.group(1)) if m else None


def _recorded(test: str) -> float | None:
    """The recorded cut (m) of a field line ``PST 30/100 (End) down 41 cm``."""
    m = re.match(r"PST (\d+(?:\.\d+)?)/", test)
    return float(m.group(1)) / 100.0 if m else None


def _far(data: dict) -> list[str]:
    """Where the runaway cuts that moved beyond :data:`CUT_SHARE` went, against the recorded cut."""
    lo = data["switch"]["before"]
    far_cases = [c for c in ran(data["cases"]) if (ch := change(c)) is not None and abs(ch) > CUT_SHARE]
    if not far_cases:
        return []
    parts, closer = [], []
    for c in far_cases:
        a, b, rec, d = c["before"]["runaway_cut"], c["after"]["runaway_cut"], _recorded(c["test"]), _depth(c["test"])
        where = (f"the slab {fx(d, 0)} cm, about {fx(d / 100 / c['detail']['dx'][0], 0)} cells deep at {lo} cells "
                 "across the layer; " if d is not None else "")
        parts.append(f"`{c['test']}` ({where}{cut(a)} -> {cut(b)} m, recorded {cut(rec)} m)")
        if rec is not None:
            closer.append(abs(b - rec) < abs(a - rec))
    toward = ("" if not closer else " On the finer grid each came closer to the recorded cut." if all(closer) else
              " On the finer grid not every one came closer to the recorded cut.")
    return [f"- The runaway cuts that moved by more than {fx(100 * CUT_SHARE, 0)} %: {'; '.join(parts)} (depth "
            f"measured vertically, as the observer writes it).{toward}", ""]


def _cost(data: dict) -> list[str]:
    """The finer runs' wall time over the batch's, where both had the same threads."""
    lo, hi = data["switch"]["before"], data["switch"]["value"]
    cases = ran(data["cases"])
    same = [c["after"]["cost"]["wall_s"] / c["before"]["cost"]["wall_s"] for c in cases
            if c["before"]["cost"].get("wall_s") and c["before"]["cost"].get("threads") == c["after"]["cost"].get(
                "threads")]
    if not same:
        return []
    return [f"- Cost: over the {len(same)} cases whose {lo}-cell run (the batch's own) also had "
            f"{cases[0]['after']['cost'].get('threads') or 1} threads to itself, the {hi}-cell runs took "
            f"{fx(min(same), 2)} to {fx(max(same), 2)} times the wall time (median {fx(median(same), 2)}x; "
            f"({hi}/{lo})^3 = {fx((hi / lo) ** 3, 1)} in particle-steps).", ""]


def _intro(data: dict) -> str:
    lo, hi = data["switch"]["before"], data["switch"]["value"]
    b, a = labels(data)
    return (f"Cases: {data['chosen']}, each run again with the grid spacing times {lo}/{hi} ({hi} cells across the "
            f"weak layer), nothing else changed (the slab's crack band follows the grid). Each pair of values is {b} "
            f"/ {a}; the {lo}-cell run is the batch's own.")


@section("field", "The grid: the same columns at 6 cells across the weak layer", "field/results/field_resolution.json",
         command("resolution", lambda d: f" --cells {d['switch']['value']}"),
         follows="The pre-cut: the same columns started sawn",
         question="Does a field case keep its class, and its runaway cut, when its column runs on a finer grid "
                  "than the field protocol's 4 cells across the weak layer?")
def render_resolution(data: dict, ctx) -> list[str]:
    return render_what_if(data, ctx, intro=_intro, notes=(failed_lines, _far, _cost),
                          columns=("dx", "predicted", "runaway", "change", "broke", "particles", "steps", "wall"))
