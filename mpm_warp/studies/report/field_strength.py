"""Field cases with their slab's tensile strength scaled, a what-if on its law (benchmarks/field/strength.py)."""

from __future__ import annotations

import math
import os
from statistics import median

from .core import section
from .field_closure import CLASSES, _balanced
from .field_rigid_base import _cut
from .fmt import check_line, count, env_note, fx, spct, table


def _to_sf(cases: list, cls: str, side: str) -> tuple[int, int]:
    """Of the cases observed ``cls`` that ran: how many ``side`` predicted SF, of how many."""
    of = [c for c in cases if c["observed"] == cls]
    return sum(c[side]["predicted"] == "SF" for c in of), len(of)


#: the section's own run: the largest draw, at a quarter of the law's strength
MAIN = "field/results/strength/0.25_16/field_strength.json"
#: smaller draws (8 a class, the same seed: a draw of its own) at both factors, summarised beside it
MORE = ("field/results/strength/0.5_8/field_strength.json", "field/results/strength/0.25_8/field_strength.json")


def fisher_greater(a: int, n: int, b: int, m: int) -> float:
    """One-sided Fisher exact p-value that ``a`` of ``n`` is a larger share than ``b`` of ``m`` by chance alone
    (the hypergeometric tail: the chance of ``a`` or more of the ``a + b`` hits falling among the first ``n``)."""
    k = a + b
    total = math.comb(n + m, k)
    return sum(math.comb(n, i) * math.comb(m, k - i) for i in range(a, min(n, k) + 1)) / total


def _summary(data: dict) -> list:
    """The row of one factor: SF predicted per observed class (new against the law's), the balanced accuracy,
    and Fisher's p of SF records against END records."""
    ran = [c for c in data["cases"] if c["scaled"].get("status") == "ok"]
    cells, got = [], {}
    for cls in CLASSES:
        k, n = _to_sf(ran, cls, "scaled")
        k0, _ = _to_sf(ran, cls, "law")
        got[cls] = (k, n)
        cells.append(f"{k} of {n} ({k0})")
    ba, _ = _balanced(ran, "scaled")
    (a, n), (b, m) = got["SF"], got["END"]
    p = fisher_greater(a, n, b, m) if n and m else None
    row = [fx(data["scale"], 2), str(data["per_class"]), *cells, fx(ba, 2), fx(p, 2)]
    return row, p, a / n if n else None, b / m if m else None


@section("field", "The slab's strength: the same columns with a weaker slab", MAIN,
         lambda d: f"python benchmarks/field/strength.py DIR --runs RUNDIR --scale {d['scale']:g} "
                   f"--per-class {d['per_class']} --seed {d['seed']} --max-wall {d['max_wall_s']:g} "
                   f"--workers {d['workers']} --threads {d['threads']} --out benchmarks/{os.path.dirname(MAIN)}",
         question="Is the slab's tensile strength the lever that would tell SF from END? The same columns, every slab "
                  "layer's strength scaled by a what-if factor (not a calibration: no default changes).",
         follows="The laminate closure: the slab's stress at the weak layer against the FE")
def render_strength(data: dict, ctx) -> list[str]:
    s = data["scale"]
    cases = data["cases"]
    rows = []
    for c in cases:
        a, b = c["law"], c["scaled"]
        rows.append([f"`{c['test']}`", c["observed"], f"{a['predicted']} / {b['predicted'] or b.get('status')}",
                     f"{_cut(a['runaway_cut'])} / {_cut(b['runaway_cut'])}", _cut(b["slab_fracture_at"]),
                     f"{count(a['steps'])} / {count(b['steps'])}",
                     f"{fx(a['wall_s'], 0)} ({a.get('threads') or '-'}) / "
                     f"{fx(b['wall_s'], 0)} ({b.get('threads') or '-'})"])
    out = [f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key: the same "
           f"parameters, the same protocol), every slab layer's tensile strength then set to {fx(s, 2)} times its "
           "density law's (Sigrist 2006, docs/model.md §9) and nothing else changed: the fracture energy stays the "
           f"density law's. Each pair of values is at the law's strength (the batch's run) / at {fx(s, 2)} of it.", ""]
    out += table(["record", "observed", "predicted", "runaway cut (m)", "slab broke at (m), weaker",
                  "steps", "wall time, s (threads)"], rows)
    ran = [c for c in cases if c["scaled"].get("status") == "ok"]
    row, p, share_sf, share_end = _summary(data)
    more = [f for f in MORE if ctx is not None and ctx.exists(f)]
    others = [ctx.load(f) for f in more]
    passed = None if p is None or p > 0.05 else share_sf > share_end
    out += ["", check_line(f"a slab {fx(s, 2)} times as strong breaks where the observer saw SF rather than END",
                           "a larger share of the SF records than of the END records predicted SF, beyond chance "
                           "(one-sided Fisher exact test, p <= 0.05)", passed,
                           f"SF records {row[3]}, END records {row[2]}, ARR records {row[4]}, the law's strength in "
                           f"brackets; p = {row[6]}" + ("; too few cases to tell" if passed is None else "")), ""]
    summary = [row] + [_summary(d)[0] for d in others]
    out += table(["strength over the law's", "cases a class", "END records predicted SF", "SF records predicted SF",
                  "ARR records predicted SF", "balanced accuracy", "p, SF against END"],
                 sorted(summary, key=lambda r: (-float(r[0]), int(r[1]))))
    out += ["", "Each count is of the records that ran, with the count at the law's strength in brackets."
            + (" The smaller draws: the same command with `--scale`, `--per-class 8` and `--out` ("
               + ", ".join(ctx.link(f) for f in more) + ")." if more else ""), ""]
    parts = []
    for side, name in (("law", "at the law's strength"), ("scaled", f"at {fx(s, 2)} of it")):
        ba, rec = _balanced(ran, side)
        parts.append(f"{name} {fx(ba, 2)} (recall " + ", ".join(f"{k} {fx(v, 2)}" for k, v in rec.items()) + ")")
    out += [f"- On these {len(ran)} cases (drawn by observed class, not a score of the development set): the "
            f"balanced accuracy {parts[0]}; {parts[1]}.", ""]
    failed = [c for c in cases if c["scaled"].get("status") != "ok"]
    if failed:
        out += ["- Failed with the weaker slab: " + "; ".join(
            f"`{c['test']}`: {(c['scaled'].get('error') or '').split(': ', 1)[-1].split(';')[0]}"
            for c in failed) + ".", ""]
    cuts = [c["scaled"]["runaway_cut"] / c["law"]["runaway_cut"] - 1.0 for c in ran
            if c["law"].get("runaway_cut") and c["scaled"].get("runaway_cut")]
    if cuts:
        out += [f"- The runaway cut, where both ran away ({len(cuts)} cases): {spct(min(cuts))} to {spct(max(cuts))} "
                f"(median {spct(median(cuts))}).", ""]
    out += [env_note(data)]
    return out
