"""Every scored field column solved statically at its recorded cut in plane strain and in plane stress, the two limits
a 30 cm wide column lies between (benchmarks/field/plane_stress.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_what_if import CLASSES
from .fmt import check_line, env_note, fx, pct, spct, table

#: the largest change of the slab's peak stress between the two limits the check allows (-)
WITHIN = 0.10


def change(c: dict) -> float:
    """The slab's peak stress over strength in plane stress over that in plane strain, less 1."""
    return c["fe"]["stress"]["peak"] / c["fe"]["strain"]["peak"] - 1.0


def ranks_above(high: list[float], low: list[float]) -> float:
    """The share of pairs (one of ``high``, one of ``low``) in which the first is larger, ties counting half (the area
    under the ROC curve)."""
    wins = sum((h > lo) + 0.5 * (h == lo) for h in high for lo in low)
    return wins / (len(high) * len(low))


def _row(cases: list, cls: str) -> list[str]:
    of = [c for c in cases if c["observed"] == cls]
    ch = [change(c) for c in of]
    broke = [sum(c["fe"][plane]["peak"] >= 1.0 for c in of) for plane in ("strain", "stress")]
    return [cls, str(len(of)), fx(median(c["fe"]["strain"]["peak"] for c in of), 2),
            fx(median(c["fe"]["stress"]["peak"] for c in of), 2), spct(median(ch)),
            f"{spct(min(ch))} to {spct(max(ch))}",
            f"{broke[0]} / {broke[1]}",
            str(sum(c.get("static_class") == "SF" for c in of))]


@section("field", "Plane strain against a 30 cm wide column: the slab's stress at the recorded cut",
         "field/results/field_plane_stress.json",
         lambda d: f"python benchmarks/field/plane_stress.py DIR --dx {d['dx']:g}",
         question="The run and weac take a PST column as infinitely wide across the slope (plane strain); a field "
                  "column is 30 cm wide with free side walls. Does the slab's stress where the crack started change "
                  "between plane strain and plane stress, the two limits such a column lies between?",
         follows="The far end: the columns called END, run on past the call", page="field_slab")
def render_plane_stress(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    out = [f"Cases: every case the committed development-set batches scored ({len(cases)}), set up again from its "
           "pit as the batch set it up, solved statically at its recorded cut by the FE of \"A resolved slab\" "
           f"({fx(data['dx'] * 1000, 0)} mm elements, every layer resolved; the zones within 2 cm of the singular "
           "corners left out), once in plane strain and once in plane stress. No MPM runs. Every value is the "
           "slab's largest principal stress over its layer's tensile strength (Sigrist 2006, docs/model.md §9).", ""]
    out += table(["observed", "cases", "peak, plane strain (median)", "peak, plane stress (median)",
                  "stress over strain (median)", "stress over strain (range)", "peak >= 1: strain / stress",
                  "weac's static rule: SF"],
                 [_row(cases, cls) for cls in CLASSES if any(c["observed"] == cls for c in cases)])
    ch = [change(c) for c in cases]
    worst = max(cases, key=lambda c: abs(change(c)))
    passed = None if not cases else max(abs(x) for x in ch) <= WITHIN
    why = (f"{sum(abs(x) <= WITHIN for x in ch)} of {len(ch)}; median {spct(median(ch))}, from {spct(min(ch))} to "
           f"{spct(max(ch))}; the largest at `{worst['test']}` ({fx(worst['fe']['strain']['peak'], 2)} in plane "
           f"strain)")
    out += ["", check_line("plane strain against a 30 cm wide column",
                           f"the slab's peak stress at the recorded cut within {pct(WITHIN, 0)} between plane strain "
                           "and plane stress, in every column", passed, why), ""]
    beyond = [f"`{c['test']}` ({c['observed']}, slab {fx(c['slab_depth'] * 100, 0)} cm deep, {spct(change(c))})"
              for c in cases if abs(change(c)) > WITHIN]
    out += [f"- Plane stress raises the slab's peak by at most {spct(max(ch))} and lowers it in "
            f"{sum(x < 0.0 for x in ch)} of the {len(ch)} columns: a column narrower than plane strain's loads its "
            "slab less, not more." + (f" Beyond {pct(WITHIN, 0)}: {'; '.join(beyond)}." if beyond else ""), ""]
    sf = [c["fe"]["strain"]["peak"] for c in cases if c["observed"] == "SF"]
    end = [c["fe"]["strain"]["peak"] for c in cases if c["observed"] == "END"]
    arr = [c["fe"]["strain"]["peak"] for c in cases if c["observed"] == "ARR"]
    if sf and end:
        line = (f"- **SF against END:** the FE's slab peak at the recorded cut (plane strain) ranks an SF record above "
                f"an END record in {pct(ranks_above(sf, end), 0)} of the {len(sf) * len(end)} pairs")
        if arr:
            line += f", an ARR record above an END record in {pct(ranks_above(arr, end), 0)}"
        out += [line + " (50 % is chance). The cut is the observer's, so a long cut loads any slab: the FE sees the "
                       "static load where the crack started, not what the crack did next.", ""]
    out += [env_note(data, verb="computed")]
    return out
