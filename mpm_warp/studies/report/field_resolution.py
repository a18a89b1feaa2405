"""Field cases at 4 and at 6 cells across the weak layer (benchmarks/field/resolution.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_rigid_base import CUT_SHARE, _cut
from .fmt import check_line, count, env_note, fx, spct, table


def _change(c: dict):
    a, b = c["coarse"]["runaway_cut"], c["fine"]["runaway_cut"]
    return None if not a or not b else b / a - 1.0


@section("field", "The grid: the same columns at 6 cells across the weak layer", "field/results/field_resolution.json",
         lambda d: f"python benchmarks/field/resolution.py RUNDIR --per-class {d['per_class']} --seed {d['seed']} "
                   f"--max-wall {d['max_wall_s']:g}",
         question="Does a field case keep its class, and its runaway cut, when its column runs on a finer grid "
                  "than the field protocol's 4 cells across the weak layer?")
def render_resolution(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    lo, hi = data["cells"]
    rows = []
    for c in cases:
        a, b, ch = c["coarse"], c["fine"], _change(c)
        rows.append([f"`{c['test']}`", c["observed"], f"{fx(c['dx'][0], 2, 1e3)} / {fx(c['dx'][1], 2, 1e3)}",
                     f"{a['predicted']} / {b['predicted']}", f"{_cut(a['runaway_cut'])} / {_cut(b['runaway_cut'])}",
                     "-" if ch is None else spct(ch), f"{_cut(a['slab_fracture_at'])} / {_cut(b['slab_fracture_at'])}",
                     f"{count(a['particles'])} / {count(b['particles'])}", f"{count(a['steps'])} / {count(b['steps'])}",
                     f"{fx(a['wall_s'], 0)} / {fx(b['wall_s'], 0)}"])
    out = [f"Cases: {data['chosen']}, each run again from its checkpoint's scenario with the grid spacing times "
           f"{lo}/{hi} ({hi} cells across the weak layer), nothing else changed (the slab's crack band follows the "
           f"grid). Each pair of values is at {lo} / {hi} cells; the {lo}-cell run is the batch's own.", ""]
    out += table(["record", "observed", "dx (mm)", "predicted", "runaway cut (m)", "cut change", "slab broke at (m)",
                  "particles", "steps", "wall time (s)"], rows)
    same = [c["coarse"]["predicted"] == c["fine"]["predicted"] for c in cases]
    changes = [ch for ch in map(_change, cases) if ch is not None]
    far = [f"`{c['test']}` {spct(ch)}" for c in cases if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    moved = [f"`{c['test']}` ({c['observed']}): {c['coarse']['predicted']} -> {c['fine']['predicted']}"
             for c, s in zip(cases, same, strict=True) if not s]
    cost = [b["wall_s"] / a["wall_s"] for a, b in ((c["coarse"], c["fine"]) for c in cases) if a.get("wall_s")]
    out += ["", check_line(f"the predicted class at {lo} and at {hi} cells", "the same in every case", all(same),
                           f"{sum(same)} of {len(same)}" + (f"; changed: {'; '.join(moved)}" if moved else "")),
            check_line(f"the runaway cut at {lo} and at {hi} cells", f"within {fx(100 * CUT_SHARE, 0)} % in every case "
                       "that ran away at both", bool(changes) and not far,
                       f"{len(changes) - len(far)} of {len(changes)}, from {spct(min(changes))} to "
                       f"{spct(max(changes))}" + (f"; apart: {', '.join(far)}" if far else "")
                       if changes else "no case ran away at both"), ""]
    if cost:
        out += [f"- Cost: the {hi}-cell runs took {fx(min(cost), 2)} to {fx(max(cost), 2)} times the wall time of the "
                f"{lo}-cell ones (median {fx(median(cost), 2)}x; the {lo}-cell runs are the batch's own, the {hi}-cell "
                f"ones ran one at a time on {cases[0]['fine'].get('threads', 1)} threads).", ""]
    out += [env_note(data)]
    return out
