"""Field cases at 4 and at 6 cells across the weak layer (benchmarks/field/resolution.py)."""

from __future__ import annotations

import re
from statistics import median

from .core import section
from .field_rigid_base import CUT_SHARE, _cut
from .fmt import check_line, count, env_note, fx, spct, table


def _depth(test: str) -> float | None:
    """The weak layer's depth (cm) in a field line ``PST 30/100 (End) down 41 cm``."""
    m = re.search(r"down (\d+(?:\.\d+)?) cm", test)
    return float(m.group(1)) if m else None


def _recorded(test: str) -> float | None:
    """The recorded cut (m) of a field line ``PST 30/100 (End) down 41 cm``."""
    m = re.match(r"PST (\d+(?:\.\d+)?)/", test)
    return float(m.group(1)) / 100.0 if m else None


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
    far_cases = [c for c in cases if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    far = [f"`{c['test']}` {spct(_change(c))}" for c in far_cases]
    moved = [f"`{c['test']}` ({c['observed']}): {c['coarse']['predicted']} -> {c['fine']['predicted']}"
             for c, s in zip(cases, same, strict=True) if not s]
    same_threads = [c["fine"]["wall_s"] / c["coarse"]["wall_s"] for c in cases
                    if c["coarse"].get("wall_s") and c["coarse"].get("threads") == c["fine"].get("threads")]
    out += ["", check_line(f"the predicted class at {lo} and at {hi} cells", "the same in every case", all(same),
                           f"{sum(same)} of {len(same)}" + (f"; changed: {'; '.join(moved)}" if moved else "")),
            check_line(f"the runaway cut at {lo} and at {hi} cells", f"within {fx(100 * CUT_SHARE, 0)} % in every case "
                       "that ran away at both", bool(changes) and not far,
                       f"{len(changes) - len(far)} of {len(changes)}, from {spct(min(changes))} to "
                       f"{spct(max(changes))}" + (f"; apart: {', '.join(far)}" if far else "")
                       if changes else "no case ran away at both"), ""]
    if far_cases:
        parts, closer = [], []
        for c in far_cases:
            a, b, rec, d = c["coarse"]["runaway_cut"], c["fine"]["runaway_cut"], _recorded(c["test"]), _depth(c["test"])
            where = (f"the slab {fx(d, 0)} cm, about {fx(d / 100 / c['dx'][0], 0)} cells deep at {lo} cells across "
                     "the layer; " if d is not None else "")
            parts.append(f"`{c['test']}` ({where}{_cut(a)} -> {_cut(b)} m, recorded {_cut(rec)} m)")
            if rec is not None:
                closer.append(abs(b - rec) < abs(a - rec))
        toward = ("" if not closer else " On the finer grid each came closer to the recorded cut." if all(closer) else
                  " On the finer grid not every one came closer to the recorded cut.")
        out += [f"- The runaway cuts that moved by more than {fx(100 * CUT_SHARE, 0)} %: {'; '.join(parts)} (depth "
                f"measured vertically, as the observer writes it).{toward}", ""]
    if same_threads:
        out += [f"- Cost: over the {len(same_threads)} cases whose {lo}-cell run (the batch's own) also had "
                f"{cases[0]['fine'].get('threads', 1)} threads to itself, the {hi}-cell runs took "
                f"{fx(min(same_threads), 2)} to {fx(max(same_threads), 2)} times the wall time (median "
                f"{fx(median(same_threads), 2)}x; (6/4)^3 = 3.4 in particle-steps).", ""]
    out += [env_note(data)]
    return out
