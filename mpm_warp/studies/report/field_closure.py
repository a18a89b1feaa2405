"""Field cases without and with the laminate closure at their layer interfaces (benchmarks/field/closure.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_rigid_base import CUT_SHARE, _cut
from .fmt import check_line, count, env_note, fx, spct, table

CLASSES = ("END", "SF", "ARR")


def _change(c: dict):
    a, b = c["off"]["runaway_cut"], c["on"]["runaway_cut"]
    return None if not a or not b else b / a - 1.0


def _balanced(cases: list, side: str) -> tuple[float | None, dict]:
    """The balanced accuracy of ``side``'s predictions over the observed classes present, and the recalls."""
    recall = {}
    for cls in CLASSES:
        of = [c for c in cases if c["observed"] == cls]
        if of:
            recall[cls] = sum(c[side]["predicted"] == cls for c in of) / len(of)
    return (sum(recall.values()) / len(recall) if recall else None), recall


@section("field", "The laminate closure: the same columns without and with it", "field/results/field_closure.json",
         lambda d: f"python benchmarks/field/closure.py DIR --runs RUNDIR --per-class {d['per_class']} "
                   f"--seed {d['seed']} --max-wall {d['max_wall_s']:g} --workers {d['workers']} "
                   f"--threads {d['threads']}",
         question="Does a field case keep its class, and its runaway cut, when its column runs with the laminate "
                  "closure at its layer interfaces (docs/model.md §5b), which removes the grid's bimaterial artefact "
                  "at the weak layer?")
def render_closure(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = []
    for c in cases:
        a, b, ch = c["off"], c["on"], _change(c)
        rows.append([f"`{c['test']}`", c["observed"], f"{a['predicted']} / {b['predicted'] or b.get('status')}",
                     f"{_cut(a['runaway_cut'])} / {_cut(b['runaway_cut'])}", "-" if ch is None else spct(ch),
                     f"{_cut(a['slab_fracture_at'])} / {_cut(b['slab_fracture_at'])}",
                     f"{count(a['steps'])} / {count(b['steps'])}",
                     f"{fx(a['wall_s'], 0)} ({a.get('threads') or '-'}) / "
                     f"{fx(b['wall_s'], 0)} ({b.get('threads') or '-'})"])
    out = [f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key: the same "
           "parameters, the same protocol) and run with the closure on, nothing else changed. Each pair of values is "
           "without / with the closure; the run without it is the batch's own.", ""]
    out += table(["record", "observed", "predicted", "runaway cut (m)", "cut change", "slab broke at (m)", "steps",
                  "wall time, s (threads)"], rows)
    ran = [c for c in cases if c["on"].get("status") == "ok"]
    same = [c["off"]["predicted"] == c["on"]["predicted"] for c in ran]
    changes = [ch for ch in map(_change, ran) if ch is not None]
    far = [f"`{c['test']}` {spct(_change(c))}" for c in ran if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    moved = [f"`{c['test']}` ({c['observed']}): {c['off']['predicted']} -> {c['on']['predicted']}"
             for c, s in zip(ran, same, strict=True) if not s]
    out += ["", check_line("the predicted class without and with the closure", "the same in every case", all(same),
                           f"{sum(same)} of {len(same)}" + (f"; changed: {'; '.join(moved)}" if moved else "")),
            check_line("the runaway cut without and with the closure",
                       f"within {fx(100 * CUT_SHARE, 0)} % in every case that ran away in both",
                       bool(changes) and not far,
                       f"{len(changes) - len(far)} of {len(changes)}, from {spct(min(changes))} to {spct(max(changes))}"
                       + (f"; apart: {', '.join(far)}" if far else "") if changes else "no case ran away in both"), ""]
    parts = []
    for side, name in (("off", "without"), ("on", "with")):
        ba, rec = _balanced(ran, side)
        parts.append(f"{name} the closure {fx(ba, 2)} (recall " + ", ".join(f"{k} {fx(v, 2)}" for k, v in rec.items())
                     + ")")
    out += [f"- On these {len(ran)} cases (drawn by observed class, not a score of the development set): the "
            f"balanced accuracy {parts[0]}; {parts[1]}.", ""]
    same_threads = [c["on"]["wall_s"] / c["off"]["wall_s"] for c in ran
                    if c["off"].get("wall_s") and c["off"].get("threads") == c["on"].get("threads")
                    and c["off"].get("workers") == c["on"].get("workers")]
    steps = [c["on"]["steps"] / c["off"]["steps"] for c in ran if c["off"].get("steps") and c["on"].get("steps")]
    if steps:
        out += [f"- Cost: steps with over without the closure {fx(min(steps), 2)} to {fx(max(steps), 2)} (median "
                f"{fx(median(steps), 2)}; a run stops at the first frame its outcome is decided)"
                + (f"; wall time, where both ran on the same threads and workers ({len(same_threads)} cases), "
                   f"{fx(min(same_threads), 2)} to {fx(max(same_threads), 2)} times (median "
                   f"{fx(median(same_threads), 2)})" if same_threads else
                   "; no case ran on the same threads and workers both times, so their wall times are not compared")
                + ".", ""]
    out += [env_note(data)]
    return out
