"""Field cases the model called END, run on past the call: does the crack reach the column's end?
(benchmarks/field/far_end.py)."""

from __future__ import annotations

from .core import section
from .field_what_if import CLASSES
from .fmt import check_line, count, env_note, fx, table


def fate(c: dict) -> str:
    """What the crack did after the END call: "reached the end", "stopped short", or "still running" (the run's
    time ended first), or the run's failure."""
    if c.get("status") != "ok":
        return "failed"
    if c.get("call") != "END":
        return f"called {c.get('call')}"
    return "reached the end" if c.get("reached") else "stopped short" if c.get("stalled") else "still running"


def _m(x) -> str:
    return fx(x, 3) if x is not None else "-"


@section("field", "The far end: the columns called END, run on past the call", "field/results/field_far_end.json",
         lambda d: f"python benchmarks/field/far_end.py DIR --runs RUNDIR --per-class {d['per_class']} "
                   f"--seed {d['seed']} --max-wall {d['max_wall_s']:g} --workers {d['workers']}",
         question="The model calls END once the crack enters the far end zone, one slab thickness from the column's "
                  "end; an observer writes END only when the crack reaches the end. Does the crack the model calls "
                  "END reach it?",
         follows="The slab's strength by grain form: weac's static rule on every scored column")
def render_far_end(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = []
    for c in cases:
        b = c.get("batch") or {}
        rows.append([f"`{c['test']}`", c["observed"], _m(c.get("runaway_cut")), _m(c.get("length")),
                     _m(c["length"] - c["end_zone"] if c.get("length") is not None else None), _m(c.get("call_front")),
                     _m(c.get("last_front")), fate(c),
                     f"{count(b.get('steps'))} / {count(c.get('steps'))}", f"{fx(b.get('wall_s'), 0)} / "
                     f"{fx(c.get('wall_s'), 0)}"])
    out = [f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key) and run "
           "by the field protocol, nothing changed, past the END call: until the damage front is within "
           f"{data['end_bins']} bins of the column's end (reached the end), or has stood still for "
           f"{fx(data['stall_time'], 2)} s after the saw stopped (stopped short), or the run's time ends. Lengths "
           "are from the cut end (m); each pair is the batch's run / this one.", ""]
    out += table(["record", "observed", "runaway cut", "column", "far end zone from", "front at the END call",
                  "front at the end of the run", "then", "steps", "wall time (s)"], rows)
    ok = [c for c in cases if c.get("status") == "ok" and c.get("call") == "END"]
    short = [c for c in ok if not c.get("reached")]
    passed = None if not ok else not short
    why = (f"{len(ok) - len(short)} of {len(ok)} reached the end" + (
        "; stopped short or still running: " + "; ".join(
            f"`{c['test']}` ({c['observed']}) at {_m(c.get('last_front'))} of {_m(c['length'])} m" for c in short)
        if short else ""))
    out += ["", check_line("the crack the model calls END reaches the column's end",
                           f"every END call's damage front within {data['end_bins']} bins of the end", passed, why), ""]
    by = []
    for cls in CLASSES:
        of = [c for c in ok if c["observed"] == cls]
        if of:
            by.append(f"{cls} {sum(bool(c.get('reached')) for c in of)} of {len(of)}")
    soon = [c for c in ok if c.get("runaway_cut") is not None
            and c["runaway_cut"] + 2.0 * c["bin_width"] >= c["length"] - c["end_zone"]]
    out += [f"- Reached the end, by observed class: {'; '.join(by)}. In {len(soon)} of the {len(ok)} columns the "
            "crack ran away within two bins of the far end zone, so the call came as soon as it ran at all.", ""]
    out += [env_note(data)]
    return out
