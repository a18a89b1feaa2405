"""The weak layer's along-slope scatter as what could stop the crack (ARR), on the development set's columns
(benchmarks/field/arrest_scatter.py)."""

from __future__ import annotations

import statistics

from ...field.scores import FIELD_CLASSES
from .core import section
from .fmt import env_note, fx, table


def _reading(key: str) -> str:
    if key == "g_at_10cm":
        return "weac's G 10 cm past the crack's start over w_f (slower rise: ARR)"
    if key == "g_min":
        return "the least of weac's G with touchdown past the start over w_f (lower: ARR)"
    return f"P(ARR), correlation length {key.removeprefix('p_arr_')} m"


#: a column's P(ARR) above this is counted as one the scatter can stop
STOPS = 0.05


def _without(why: dict) -> str:
    """How many columns have no reading, and why, in counts."""
    if not why:
        return "every one with a reading"
    starts = sum(w.startswith("the crack starts") for w in why.values())
    never = sum(w.startswith("no propagation") for w in why.values())
    parts = [f"{starts} where the crack starts too near the far end for one frame's side beyond it" if starts else "",
             f"{never} where weac's G never reaches w_f" if never else "",
             f"{len(why) - starts - never} for another reason" if len(why) > starts + never else ""]
    return f"{len(why)} without a reading: " + ", ".join(p for p in parts if p)


def _unsolved(cases: list) -> str:
    """Where weac's touchdown had no solution at some of the solved cuts (those take the free slab's G)."""
    n = [c.get("touchdown_unsolved", 0) for c in cases if "p_arr" in c]
    hit = sum(k > 0 for k in n)
    cols = f"{hit} column" + ("s" if hit > 1 else "")
    return (f" In {cols} weac's touchdown found no solution at {sum(n)} of the solved cuts in all; those "
            "cuts take the free slab's G.") if hit else ""


@section("field", "What could stop the crack: the weak layer's scatter along the column",
         "field/results/field_arrest_scatter.json",
         lambda d: f"python benchmarks/field/arrest_scatter.py --runs RUNDIR  # RUNDIR: {d['runs']}",
         question="A weak layer's strength scatters along a slope (CV 14-18 %). Beyond the cut where the crack "
                  "starts, can a tougher patch stop it, and more often where observers saw ARR? Nothing is fitted.",
         follows="Why thin, light slabs break: each candidate mechanism against the records", page="field_slab")
def render_arrest(data: dict, ctx) -> list[str]:
    n, r = data["counts"], data["readings"]
    rows = [[_reading(k), " / ".join(fx(v["median"][c], 3) for c in FIELD_CLASSES), fx(v["arr_vs_end"]["auc"], 3),
             fx(v["arr_vs_rest"]["auc"], 3)] for k, v in r.items()]
    out = [f"On the {sum(n.values())} scored columns of `{data['cases_from']}` (END {n['END']}, SF {n['SF']}, ARR "
           f"{n['ARR']}; {_without(data['without'])}). "
           f"The fracture energy scatters as the layer's strength squared, CV {data['strength_cv']:g}, in a "
           "spherical field conditioned on the layer the recorded cut read back, read every "
           f"{fx(100 * data['grid_m'], 1)} cm (the side of the 250 cm^2 shear frame the scatter was measured "
           f"with); {data['samples']:,} layers per column and length (`mpm_warp/field/arrest_scatter.py`)."
           + _unsolved(data["cases"]), ""]
    out += table(["reading", "median END / SF / ARR", "AUC ARR vs END", "AUC ARR vs rest"], rows)
    chk = data["spacing_check"]
    if chk["cases"]:
        spacings = list(chk["cases"][0]["p_arr"])
        med = [statistics.median(c["p_arr"][h] for c in chk["cases"]) for h in spacings]
        out += ["", f"- **Read finer than the frame** (correlation length {chk['correlation_length_m']:g} m, the "
                f"first {len(chk['cases'])} columns): median P(ARR) "
                + ", ".join(f"{fx(m, 2)} every {fx(100 * float(h), 1)} cm" for m, h in zip(med, spacings, strict=True))
                + ". The finer the field is read, the more cracks it stops (conditioned on the start, its variance "
                "grows linearly from there): below the frame the scatter is not documented, and such a number is the "
                "spacing's."]
    read = [c for c in data["cases"] if "p_arr" in c]
    some = [c for c in read if max(c["p_arr"].values()) > STOPS]
    top = max((max(c["p_arr"].values()) for c in read), default=None)
    lengths = ", ".join(f"{xi:g}" for xi in data["correlation_lengths_m"])
    where = "" if not some else " (observed " + ", ".join(f"{c['observed']} {fx(max(c['p_arr'].values()), 2)}"
                                                         for c in some) + ")"
    stops = data.get("static_arrests")
    if stops is not None:
        out += ["- **A uniform layer, no scatter** (Rosendahl et al. 2025): weac's G with touchdown falls below "
                "w_f at one of the points read past the start, a static balance that stops the crack, in "
                + ", ".join(f"{stops[c]} of the {n[c]} {c}" for c in FIELD_CLASSES) + " columns."]
    out += [f"- **At the frame's scale** P(ARR) exceeds {STOPS:g} at one of the correlation lengths ({lengths} m) "
            f"in {len(some)} of {len(read)} columns{where}; the largest is {fx(top, 3)}.", "",
            env_note(data)]
    return out
