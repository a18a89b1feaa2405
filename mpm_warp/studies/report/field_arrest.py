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
    return f"P(ARR), correlation length {key.removeprefix('p_arr_')} m"


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
           f"{n['ARR']}; {len(data['without'])} without a reading: no propagation in weac, or no room to stop). "
           f"The fracture energy scatters as the layer's strength squared, CV {data['strength_cv']:g}, in a "
           "spherical field conditioned on the layer the recorded cut read back, read every "
           f"{fx(100 * data['grid_m'], 1)} cm (the side of the 250 cm^2 shear frame the scatter was measured "
           f"with); {data['samples']:,} layers per column and length (`mpm_warp/field/arrest_scatter.py`).", ""]
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
    top = max((max(c["p_arr"].values()) for c in data["cases"] if "p_arr" in c), default=None)
    lengths = ", ".join(f"{xi:g}" for xi in data["correlation_lengths_m"])
    verdict = ("weac's G past the start grows faster than a tougher patch of the documented scatter makes up, so "
               "the scatter alone does not give the model ARR at any of these lengths" if top is not None
               and top < 0.05 else "the scatter stops some cracks at the frame's scale")
    out += [f"- **At the frame's scale** the largest P(ARR) over every column and correlation length ({lengths} m) "
            f"is {fx(top, 3)}: {verdict}.", "", env_note(data)]
    return out
