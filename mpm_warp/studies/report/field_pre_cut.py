"""Field cases with and without a pre-cut (benchmarks/field/pre_cut.py): a what-if of the pre-cut."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_what_if import command, cut, failed_lines, render_what_if
from .fmt import fx

#: m: a runaway cut this close to the pre-cut is the pre-cut's own: the crack ran from where the run started it
AT_PRE_CUT = 0.01


def _at_pre_cut(data: dict) -> list[str]:
    """A line on the cases whose crack ran away from the pre-cut itself, where the pre-cut floors the runaway cut."""
    cases = data["cases"]
    at = [c for c in cases if c["detail"].get("pre_cut") and c["after"]["runaway_cut"] is not None
          and c["after"]["runaway_cut"] <= c["detail"]["pre_cut"] + AT_PRE_CUT]
    if not at:
        return []
    what = "; ".join(f"`{c['test']}`: {cut(c['before']['runaway_cut'])} m without it, pre-cut "
                     f"{cut(c['detail']['pre_cut'])} m" for c in at)
    return [f"- In {len(at)} of {len(cases)} the crack ran away from the pre-cut itself, within "
            f"{fx(AT_PRE_CUT * 100, 0)} cm of it ({what}): where the crack runs at a cut no longer than the pre-cut, "
            "the run keeps its class but reports the pre-cut as its runaway cut."]


def _cost(data: dict) -> list[str]:
    """What the pre-cut saved: steps and wall time without over with it."""
    cases = data["cases"]
    steps = [c["before"]["cost"]["steps"] / c["after"]["cost"]["steps"] for c in cases]
    wall = [c["before"]["cost"]["wall_s"] / c["after"]["cost"]["wall_s"] for c in cases]
    return [f"- Cost: the pre-cut took {fx(min(steps), 2)} to {fx(max(steps), 2)} times fewer steps (median "
            f"{fx(median(steps), 2)}x) and {fx(median(wall), 2)}x less wall time (median; the runs without it are the "
            "batch's own, beside another case on the 2 cores; each run here shared them with one other job too).", ""]


def _notes(data: dict) -> list[str]:
    if data["switch"]["before"] != 0:         # a run that took the batch's pre-cut away: the default notes
        return failed_lines(data)
    return _at_pre_cut(data) + _cost(data)


@section("field", "The pre-cut: the same columns started sawn", "field/results/field_pre_cut.json",
         command("pre_cut", lambda d: f" --share {d['switch']['value']:g}"),
         follows="The rigid base: the same columns without their old snow",
         question="Does starting a field column sawn part of the way to weac's critical cut change its outcome, "
                  "and what does it save?")
def render_pre_cut(data: dict, ctx) -> list[str]:
    return render_what_if(data, ctx, notes=(_notes,),
                          columns=("critical_cut", "pre_cut", "predicted", "runaway", "change", "broke", "steps",
                                   "wall"))
