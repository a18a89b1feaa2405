"""Field cases with and without a pre-cut (benchmarks/field/pre_cut.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_rigid_base import CUT_SHARE, _cut
from .fmt import check_line, count, env_note, fx, spct, table


def _change(c: dict):
    a, b = c["without"]["runaway_cut"], c["with"]["runaway_cut"]
    return None if not a or not b else b / a - 1.0


#: m: a runaway cut this close to the pre-cut is the pre-cut's own: the crack ran from where the run started it
AT_PRE_CUT = 0.01


def _at_pre_cut(cases: list) -> list[str]:
    """A line on the cases whose crack ran away from the pre-cut itself, where the pre-cut floors the runaway cut."""
    at = [c for c in cases if c["pre_cut"] and c["with"]["runaway_cut"] is not None
          and c["with"]["runaway_cut"] <= c["pre_cut"] + AT_PRE_CUT]
    if not at:
        return []
    what = "; ".join(f"`{c['test']}`: {_cut(c['without']['runaway_cut'])} m without it, pre-cut {_cut(c['pre_cut'])} m"
                     for c in at)
    return [f"- In {len(at)} of {len(cases)} the crack ran away from the pre-cut itself, within "
            f"{fx(AT_PRE_CUT * 100, 0)} cm of it ({what}): where the crack runs at a cut no longer than the pre-cut, "
            "the run keeps its class but reports the pre-cut as its runaway cut."]


@section("field", "The pre-cut: the same columns started sawn", "field/results/field_pre_cut.json",
         lambda d: f"python benchmarks/field/pre_cut.py RUNDIR1 RUNDIR2 --share {d['share']:g}",
         question="Does starting a field column sawn part of the way to weac's critical cut change its outcome, "
                  "and what does it save?")
def render_pre_cut(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = []
    for c in cases:
        a, b, ch = c["without"], c["with"], _change(c)
        rows.append([f"`{c['test']}`", c["observed"], _cut(c["static_cut"]), _cut(c["pre_cut"]),
                     f"{a['predicted']} / {b['predicted']}", f"{_cut(a['runaway_cut'])} / {_cut(b['runaway_cut'])}",
                     "-" if ch is None else spct(ch), f"{_cut(a['slab_fracture_at'])} / {_cut(b['slab_fracture_at'])}",
                     f"{count(a['steps'])} / {count(b['steps'])}", f"{fx(a['wall_s'], 0)} / {fx(b['wall_s'], 0)}"])
    out = [f"Cases: {data['chosen']}, each run again from its checkpoint's scenario with the saw pre-cut "
           f"{fx(data['share'], 2)} times weac's critical cut of the column at its fracture energy (at most half the "
           "column; `scene.saw.pre_cut`), nothing else changed. Each pair of values is without / with the pre-cut.",
           ""]
    out += table(["record", "observed", "weac's critical cut (m)", "pre-cut (m)", "predicted", "runaway cut (m)",
                  "cut change", "slab broke at (m)", "steps", "wall time (s)"], rows)
    same = [c["without"]["predicted"] == c["with"]["predicted"] for c in cases]
    changes = [ch for ch in map(_change, cases) if ch is not None]
    far = [f"`{c['test']}` {spct(ch)}" for c in cases if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    steps = [c["without"]["steps"] / c["with"]["steps"] for c in cases]
    wall = [c["without"]["wall_s"] / c["with"]["wall_s"] for c in cases]
    out += ["", check_line("the predicted class with and without the pre-cut", "the same in every case", all(same),
                           f"{sum(same)} of {len(same)}"),
            check_line("the runaway cut with and without the pre-cut", f"within {fx(100 * CUT_SHARE, 0)} % (twice "
                       "the snow ladder's critical-cut error at 6 cells) in every case that ran away in both",
                       bool(changes) and not far, f"{len(changes) - len(far)} of {len(changes)}, from "
                       f"{spct(min(changes))} to {spct(max(changes))}" + (f"; apart: {', '.join(far)}" if far else "")
                       if changes else "no case ran away"), "",
            *_at_pre_cut(cases),
            f"- Cost: the pre-cut took {fx(min(steps), 2)} to {fx(max(steps), 2)} times fewer steps (median "
            f"{fx(median(steps), 2)}x) and {fx(median(wall), 2)}x less wall time (median; the runs without it are the "
            "batch's own, beside another case on the 2 cores; each run here shared them with one other job too).",
            "", env_note(data)]
    return out
