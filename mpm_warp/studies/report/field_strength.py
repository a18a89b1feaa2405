"""Field cases with their slab's tensile strength scaled, a what-if on its law (benchmarks/field/strength.py),
and with faceted layers at their in-situ strength (``--faceted``)."""

from __future__ import annotations

import math
import os
from statistics import median

from .core import section
from .field_closure import CLASSES, _balanced
from .field_rigid_base import _cut
from .fmt import check_line, count, env_note, fx, pct, spct, table


def _to_sf(cases: list, cls: str, side: str) -> tuple[int, int]:
    """Of the cases observed ``cls`` that ran: how many ``side`` predicted SF, of how many."""
    of = [c for c in cases if c["observed"] == cls]
    return sum(c[side]["predicted"] == "SF" for c in of), len(of)


#: the section's own run: the largest draw, at a quarter of the law's strength
MAIN = "field/results/strength/0.25_16/field_strength.json"
#: the same draw with only the faceted layers weakened, to their in-situ strength (Jamieson and Johnston 1990)
FACETED = "field/results/strength/faceted_0.5_16/field_strength.json"
#: smaller draws (8 a class, the same seed: a draw of its own) at both factors, summarised beside it
MORE = (FACETED, "field/results/strength/0.5_8/field_strength.json",
        "field/results/strength/0.25_8/field_strength.json")


def sf_verdict(a: int, n: int, b: int, m: int) -> tuple[float | None, bool | None]:
    """``(p, passed)`` of "SF in ``a`` of ``n`` SF records is a larger share than in ``b`` of ``m`` END records,
    beyond chance": one-sided Fisher p (None without both), a pass at p <= 0.05, a fail where the SF records' share
    is no larger at all, else open (None)."""
    p = fisher_greater(a, n, b, m) if n and m else None
    return p, None if p is None else True if p <= 0.05 else (False if a / n <= b / m else None)


def _check(label: str, row: list, p: float | None, passed: bool | None) -> str:
    """The pass line of one factor's row (:func:`sf_verdict`)."""
    return check_line(label, "a larger share of the SF records than of the END records predicted SF, beyond chance "
                             "(one-sided Fisher exact test, p <= 0.05)", passed,
                      f"SF records {row[3]}, END records {row[2]}, ARR records {row[4]}, the law's strength in "
                      f"brackets; p = {row[6]}" + {None: "; too few cases to tell", True: "",
                                                   False: "; no larger share of the SF records"}[passed])


def _faceted_lines(data: dict) -> list[str]:
    """What the faceted draw adds: the faceted share of the slabs per observed class and weac's static rule with
    the same strengths."""
    ran = [c for c in data["cases"] if c["scaled"].get("status") == "ok"]
    shares, static = [], []
    for cls in CLASSES:
        of = [c for c in ran if c["observed"] == cls]
        if of:
            share = median(c["faceted_share"] for c in of)
            anyf = sum(c["faceted_share"] > 0 for c in of)
            shares.append(f"{cls} {pct(share, 0)} ({anyf} of {len(of)} with any)")
            static.append(f"{cls} {sum(c['scaled']['static_class'] == 'SF' for c in of)} of {len(of)} "
                          f"({sum(c['law']['static_class'] == 'SF' for c in of)})")
    moved = sum(c["scaled"]["predicted"] != c["law"]["predicted"] for c in ran)
    return [f"- With only the faceted layers (primary grain {', '.join(data['faceted_grains'])}) at "
            f"{fx(data['faceted'], 2)} of the law's strength, {moved} of the {len(ran)} runs changed their class. "
            "The slab's faceted share of its thickness, median by "
            f"observed class, {'; '.join(shares)}. weac's static rule with the same strengths predicts SF in "
            f"{'; '.join(static)} records (at the law's strength in brackets).", ""]


def fisher_greater(a: int, n: int, b: int, m: int) -> float:
    """One-sided Fisher exact p-value that ``a`` of ``n`` is a larger share than ``b`` of ``m`` by chance alone
    (the hypergeometric tail: the chance of ``a`` or more of the ``a + b`` hits falling among the first ``n``)."""
    k = a + b
    total = math.comb(n + m, k)
    return sum(math.comb(n, i) * math.comb(m, k - i) for i in range(a, min(n, k) + 1)) / total


def _factor(data: dict) -> str:
    """The strength over the law's: ``"0.25"``, or ``"faceted layers 0.50"`` where only those were weakened."""
    f = data.get("faceted", 1.0)
    return fx(data["scale"], 2) if f == 1.0 else (
        f"faceted layers {fx(f, 2)}" + ("" if data["scale"] == 1.0 else f", all {fx(data['scale'], 2)}"))


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
    p, passed = sf_verdict(a, n, b, m)
    row = [_factor(data), str(data["per_class"]), *cells, fx(ba, 2), fx(p, 2)]
    return row, p, passed


@section("field", "The slab's strength: the same columns with a weaker slab", MAIN,
         lambda d: f"python benchmarks/field/strength.py DIR --runs RUNDIR --scale {d['scale']:g} "
                   f"--per-class {d['per_class']} --seed {d['seed']} --max-wall {d['max_wall_s']:g} "
                   f"--workers {d['workers']} --threads {d['threads']} --out benchmarks/{os.path.dirname(MAIN)}",
         question="Is the slab's tensile strength the lever that would tell SF from END? The same columns, every slab "
                  "layer's strength scaled by a what-if factor (not a calibration: no default changes).",
         follows="The laminate closure: the slab's stress at the weak layer against the FE", page="field_slab")
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
    row, p, passed = _summary(data)
    more = [f for f in MORE if ctx is not None and ctx.exists(f)]
    others = [ctx.load(f) for f in more]
    out += ["", _check(f"a slab {fx(s, 2)} times as strong breaks where the observer saw SF rather than END", row, p,
                       passed)]
    if FACETED in more:
        fac = others[more.index(FACETED)]
        frow, *rest = _summary(fac)
        out += [_check(f"faceted slab layers at {fx(fac['faceted'], 2)} of the law's strength (in situ, Jamieson and "
                       "Johnston 1990) break where the observer saw SF rather than END", frow, *rest)]
    out += [""]
    summary = [row] + [_summary(d)[0] for d in others]
    out += table(["strength over the law's", "cases a class", "END records predicted SF", "SF records predicted SF",
                  "ARR records predicted SF", "balanced accuracy", "p, SF against END"], summary)
    out += ["", "Each count is of the records that ran, with the count at the law's strength in brackets."
            + (" The other rows: the same command with `--scale`, `--faceted`, `--per-class` and `--out` ("
               + ", ".join(ctx.link(f) for f in more) + ")." if more else ""), ""]
    if FACETED in more:
        out += _faceted_lines(others[more.index(FACETED)])
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


def _static_row(cases: list, cls: str) -> list:
    """One observed class of the static study: cases, faceted share, and weac's static SF at both strengths."""
    of = [c for c in cases if c["observed"] == cls]
    return [cls, str(len(of)), pct(median(c["faceted_share"] for c in of), 0),
            pct(sum(c["faceted_share"] for c in of) / len(of), 0), str(sum(c["faceted_share"] > 0 for c in of)),
            str(sum(c["static_law"] == "SF" for c in of)), str(sum(c["static_grain"] == "SF" for c in of))]


def _static_balanced(cases: list, key: str) -> tuple[float, dict]:
    """weac's static rule's balanced accuracy under ``key`` (its classes are SF and END) and its recalls."""
    return _balanced([{"observed": c["observed"], "x": {"predicted": c[key]}} for c in cases], "x")


@section("field", "The slab's strength by grain form: weac's static rule on every scored column",
         "field/results/field_static_strength.json",
         lambda d: f"python benchmarks/field/static_strength.py DIR --faceted {d['faceted']:g}",
         question="Does the grain form of the slab's snow tell SF from END? Faceted snow is about half as strong in "
                  "tension as rounded snow of the same density in situ (Jamieson and Johnston 1990), which the "
                  "density law leaves out.",
         follows="The slab's strength: the same columns with a weaker slab", page="field_slab")
def render_static_strength(data: dict, ctx) -> list[str]:
    cases = [c for c in data["cases"] if c["static_law"] is not None]
    f = data["faceted"]
    out = [f"Cases: every case the committed development-set batches scored ({len(cases)}), set up again from its "
           "pit as the batch set it up. No MPM runs: weac's static rule (SF where the slab's largest tensile stress "
           "at the recorded cut reaches its strength, docs/field.md) at the density law's strength (Sigrist 2006) "
           f"and with every slab layer of faceted snow (primary grain {', '.join(data['faceted_grains'])}) at "
           f"{fx(f, 2)} of it, nothing else changed. The faceted share is of the slab's thickness.", ""]
    out += table(["observed", "cases", "faceted share, median", "faceted share, mean", "slabs with a faceted layer",
                  "static SF, the law's strength", f"static SF, faceted at {fx(f, 2)}"],
                 [_static_row(cases, cls) for cls in CLASSES if any(c["observed"] == cls for c in cases)])
    turned = {cls: (sum(c["static_law"] != "SF" and c["static_grain"] == "SF" for c in cases if c["observed"] == cls),
                    sum(c["static_law"] != "SF" for c in cases if c["observed"] == cls)) for cls in ("SF", "END")}
    (a, n), (b, m) = turned["SF"], turned["END"]
    p, passed = sf_verdict(a, n, b, m)
    why = (f"turned to SF: {a} of the {n} SF records and {b} of the {m} END records the law's strength left END; "
           f"p = {fx(p, 2)}" + ("; weakening the faceted layers sends the END records to SF as often or more"
                                if passed is False else "; too few cases to tell" if passed is None else ""))
    out += ["", check_line("the grain form's strength tells SF from END in weac's static rule",
                           "a larger share of the SF records than of the END records turned to SF by the faceted "
                           "layers' strength, beyond chance (one-sided Fisher exact test, p <= 0.05)", passed, why), ""]
    parts = []
    for key, name in (("static_law", "at the law's strength"), ("static_grain", f"with faceted layers at {fx(f, 2)}")):
        ba, rec = _static_balanced(cases, key)
        parts.append(f"{name}: {fx(ba, 2)} (recall " + ", ".join(f"{k} {fx(v, 2)}" for k, v in rec.items()) + ")")
    same = sum(c["static_law"] == c["static_batch"] for c in cases)
    out += [f"- weac's static rule's balanced accuracy on these cases: {parts[0]}; {parts[1]}. At the law's strength "
            f"it is the batch's baseline: the same class in {same} of {len(cases)} cases.", ""]
    out += [env_note(data, verb="computed")]
    return out
