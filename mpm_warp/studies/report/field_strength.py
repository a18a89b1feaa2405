"""Field cases with their slab's tensile strength scaled, a what-if on its law (benchmarks/field/strength.py),
and with faceted layers at their in-situ strength (``--faceted``)."""

from __future__ import annotations

import math
import os
from statistics import median

from .core import section
from .field_what_if import CLASSES, COLUMNS, balanced, balanced_line, command, failed_lines, ran, render_what_if
from .fmt import check_line, env_note, fx, pct, spct, table


def sf_counts(cases: list, cls: str, side: str, key: str = "predicted") -> tuple[int, int]:
    """Of the cases observed ``cls``: how many ``side`` (``before`` or ``after``) says SF under ``key``, of how
    many."""
    of = [c for c in cases if c["observed"] == cls]
    return sum(c[side][key] == "SF" for c in of), len(of)


#: the section's own run: the largest draw, at a quarter of the law's strength
MAIN = "field/results/strength/0.25_16/field_strength.json"
#: the same draw with only the faceted layers weakened, to their in-situ strength (Jamieson and Johnston 1990)
FACETED = "field/results/strength/faceted_0.5_16/field_strength.json"
#: smaller draws (8 a class, the same seed: a draw of its own) at both factors, summarised beside it
MORE = (FACETED, "field/results/strength/0.5_8/field_strength.json",
        "field/results/strength/0.25_8/field_strength.json")
_VERDICT = {None: "; too few cases to tell", True: "", False: "; no larger share of the SF records"}
_CRITERION = ("a larger share of the SF records than of the END records predicted SF, beyond chance (one-sided "
              "Fisher exact test, p <= 0.05)")


def sf_verdict(a: int, n: int, b: int, m: int) -> tuple[float | None, bool | None]:
    """``(p, passed)`` of "SF in ``a`` of ``n`` SF records is a larger share than in ``b`` of ``m`` END records,
    beyond chance": one-sided Fisher p (None without both), a pass at p <= 0.05, a fail where the SF records' share
    is no larger at all, else open (None)."""
    p = fisher_greater(a, n, b, m) if n and m else None
    return p, None if p is None else True if p <= 0.05 else (False if a / n <= b / m else None)


def sf_check(data: dict, label: str, was: str) -> str:
    """The check that the what-if sends a larger share of the SF records than of the END records to SF, beyond
    chance, over the cases run both ways: each class's count after, before in brackets (``was`` says what that
    is)."""
    cases = ran(data["cases"])
    got = {cls: sf_counts(cases, cls, "after") for cls in CLASSES}
    before = {cls: sf_counts(cases, cls, "before") for cls in CLASSES}
    (a, n), (b, m) = got["SF"], got["END"]
    p, passed = sf_verdict(a, n, b, m)
    return check_line(label, _CRITERION, passed,
                      ", ".join(f"{cls} records {got[cls][0]} of {got[cls][1]} ({before[cls][0]})" for cls in CLASSES)
                      + f", {was} in brackets; p = {fx(p, 2)}" + _VERDICT[passed])


def _faceted_lines(data: dict) -> list[str]:
    """What the faceted draw adds: the faceted share of the slabs per observed class and weac's static rule with
    the same strengths."""
    cases = ran(data["cases"])
    shares, static = [], []
    for cls in CLASSES:
        of = [c for c in cases if c["observed"] == cls]
        if of:
            share = median(c["detail"]["faceted_share"] for c in of)
            anyf = sum(c["detail"]["faceted_share"] > 0 for c in of)
            shares.append(f"{cls} {pct(share, 0)} ({anyf} of {len(of)} with any)")
            static.append(f"{cls} {sf_counts(of, cls, 'after', 'static_class')[0]} of {len(of)} "
                          f"({sf_counts(of, cls, 'before', 'static_class')[0]})")
    moved = sum(c["after"]["predicted"] != c["before"]["predicted"] for c in cases)
    return [f"- With only the faceted layers (primary grain {', '.join(data['faceted_grains'])}) at "
            f"{fx(data['switch']['value'], 2)} of the law's strength, {moved} of the {len(cases)} runs changed their "
            "class. The slab's faceted share of its thickness, median by "
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
    s = data["switch"]
    return fx(s["value"], 2) if s["name"] == "slab_strength" else f"faceted layers {fx(s['value'], 2)}"


def _summary(data: dict) -> list:
    """The row of one factor: SF predicted per observed class (new against the law's), the balanced accuracy,
    and Fisher's p of SF records against END records."""
    cases = ran(data["cases"])
    got = {cls: sf_counts(cases, cls, "after") for cls in CLASSES}
    cells = [f"{got[cls][0]} of {got[cls][1]} ({sf_counts(cases, cls, 'before')[0]})" for cls in CLASSES]
    (a, n), (b, m) = got["SF"], got["END"]
    p, passed = sf_verdict(a, n, b, m)
    return [_factor(data), str(data["per_class"]), *cells, fx(balanced(cases, "after")[0], 2), fx(p, 2)], p, passed


def _check(label: str, row: list, p: float | None, passed: bool | None) -> str:
    """The pass line of one factor's row (:func:`_summary`)."""
    return check_line(label, _CRITERION, passed, f"SF records {row[3]}, END records {row[2]}, ARR records {row[4]}, "
                      f"the law's strength in brackets; p = {row[6]}" + _VERDICT[passed])


def _factors(data: dict, ctx) -> list[str]:
    """This factor's check, the faceted draw's, and the table of every factor's draw beside it."""
    row, p, passed = _summary(data)
    more = [f for f in MORE if ctx is not None and ctx.exists(f)]
    others = [ctx.load(f) for f in more]
    out = [_check(f"a slab {fx(data['switch']['value'], 2)} times as strong breaks where the observer saw SF rather "
                  "than END", row, p, passed)]
    if FACETED in more:
        fac = others[more.index(FACETED)]
        out += [_check(f"faceted slab layers at {fx(fac['switch']['value'], 2)} of the law's strength (in situ, "
                       "Jamieson and Johnston 1990) break where the observer saw SF rather than END", *_summary(fac))]
    out += [""] + table(["strength over the law's", "cases a class", "END records predicted SF",
                         "SF records predicted SF", "ARR records predicted SF", "balanced accuracy",
                         "p, SF against END"], [row] + [_summary(d)[0] for d in others])
    out += ["", "Each count is of the records that ran, with the count at the law's strength in brackets."
            + (" The other rows: the same command with `--scale`, `--faceted`, `--per-class` and `--out` ("
               + ", ".join(ctx.link(f) for f in more) + ")." if more else ""), ""]
    return out + (_faceted_lines(others[more.index(FACETED)]) if FACETED in more else [])


def _cuts(data: dict) -> list[str]:
    """The runaway cut's change where both ran away."""
    cases = ran(data["cases"])
    cuts = [c["after"]["runaway_cut"] / c["before"]["runaway_cut"] - 1.0 for c in cases
            if c["before"].get("runaway_cut") and c["after"].get("runaway_cut")]
    return [f"- The runaway cut, where both ran away ({len(cuts)} cases): {spct(min(cuts))} to {spct(max(cuts))} "
            f"(median {spct(median(cuts))}).", ""] if cuts else []


def _intro(data: dict) -> str:
    s = fx(data["switch"]["value"], 2)
    return (f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key: the same "
            f"parameters, the same protocol), every slab layer's tensile strength then set to {s} times its "
            "density law's (Sigrist 2006, docs/model.md §9) and nothing else changed: the fracture energy stays the "
            f"density law's. Each pair of values is at the law's strength (the batch's run) / at {s} of it.")


@section("field", "The slab's strength: the same columns with a weaker slab", MAIN,
         command("strength", lambda d: f" --scale {d['switch']['value']:g} --out benchmarks/{os.path.dirname(MAIN)}"),
         question="Is the slab's tensile strength the lever that would tell SF from END? The same columns, every slab "
                  "layer's strength scaled by a what-if factor (not a calibration: no default changes).",
         follows="The laminate closure: the slab's stress at the weak layer against the FE", page="field_slab")
def render_strength(data: dict, ctx) -> list[str]:
    return render_what_if(data, ctx, intro=_intro, checks=(), notes=(_factors, balanced_line, failed_lines, _cuts),
                          columns=("predicted", "runaway", ("slab broke at (m), weaker", COLUMNS["broke_after"][1]),
                                   "steps", "wall_threads"))


def _static_row(cases: list, cls: str) -> list:
    """One observed class of the static study: cases, faceted share, and weac's static SF at both strengths."""
    of = [c for c in cases if c["observed"] == cls]
    return [cls, str(len(of)), pct(median(c["faceted_share"] for c in of), 0),
            pct(sum(c["faceted_share"] for c in of) / len(of), 0), str(sum(c["faceted_share"] > 0 for c in of)),
            str(sum(c["static_law"] == "SF" for c in of)), str(sum(c["static_grain"] == "SF" for c in of))]


def _static_balanced(cases: list, key: str) -> tuple[float, dict]:
    """weac's static rule's balanced accuracy under ``key`` (its classes are SF and END) and its recalls."""
    return balanced([{"observed": c["observed"], "x": {"predicted": c[key]}} for c in cases], "x")


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
