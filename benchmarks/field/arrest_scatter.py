"""Could the weak layer's along-slope scatter stop the crack where observers saw ARR, and not where they saw END?

For every scored column of the development set's batch (``field_disagreements.json``; each column's scene set up
from its run file in ``--runs``), the first-order upper bound on P(ARR) of ``mpm_warp.field.arrest_scatter``:
weac's G beyond the start of the crack against a fracture energy that scatters along the column as the weak
layer's strength does (CV 0.18, a spherical covariance, conditioned on the layer the recorded cut read back), at
each correlation length of a bracket. Per case: where the crack starts, weac's G 10 cm past it over w_f (the
slower it rises, the likelier an arrest at any correlation length), and P(ARR) at each length. Summed: medians
by observed class, and the AUC of each for ARR against END and against the rest. Nothing is fitted. Writes
``benchmarks/field/results/field_arrest_scatter.json``.

Usage: ``python benchmarks/field/arrest_scatter.py --runs RUNDIR``; ``--quick``: the first 8 cases.
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import warnings

from mpm_warp.field.arrest_scatter import CORRELATION_LENGTHS, GRID_M, STRENGTH_CV, column_arrest
from mpm_warp.field.run_on import scenario_of
from mpm_warp.field.scores import FIELD_CLASSES
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
DISAGREEMENTS = os.path.join(RESULTS, "field_disagreements.json")
SAMPLES = 4000


def describe(row: dict, run_dir: str) -> dict:
    """One scored column's arrest bound (``why`` in place of numbers where it has none)."""
    sc = scenario_of(run_dir, row["id"])
    out = {"id": row["id"], "observed": row["observed"], "predicted": row["predicted"], "w_f": row["w_f"],
           "recorded_cut": row["recorded_cut"], "column_m": row["column_m"]}
    if sc is None:
        return {**out, "why": "no run file"}
    res = column_arrest(sc.scene, row["w_f"], row["recorded_cut"], samples=SAMPLES)
    if "p_arr" in res:
        res["p_arr"] = {f"{xi:g}": p for xi, p in res["p_arr"].items()}
    return {**out, **res}


def auc(rows: list[dict], value, negatives: tuple[str, ...]) -> dict:
    """AUC of ``value(row)`` for ARR against ``negatives`` (None with one group empty)."""
    from sklearn.metrics import roc_auc_score

    use = [r for r in rows if r["observed"] in ("ARR", *negatives)]
    y = [r["observed"] == "ARR" for r in use]
    return {"cases": len(use),
            "auc": float(roc_auc_score(y, [value(r) for r in use])) if 0 < sum(y) < len(y) else None}


def summary(rows: list[dict]) -> dict:
    """Per reading (the rise of G 10 cm past the start, slower: ARR; P(ARR) at each length): medians by observed
    class and the ARR AUCs, over the cases that have it."""
    read = [r for r in rows if "p_arr" in r]
    readings = {"g_at_10cm": (lambda r: r["g_at_10cm"], -1.0), "g_min": (lambda r: r.get("g_min"), -1.0)}
    readings.update({f"p_arr_{k}": (lambda r, k=k: r["p_arr"][k], 1.0) for k in (read[0]["p_arr"] if read else ())})
    out = {}
    for key, (value, sign) in readings.items():
        have = [r for r in read if value(r) is not None]

        def signed(r, f=value, s=sign):
            return s * f(r)
        out[key] = {"median": {c: statistics.median(v) if (v := [value(r) for r in have if r["observed"] == c])
                               else None for c in FIELD_CLASSES},
                    "arr_vs_end": auc(have, signed, ("END",)), "arr_vs_rest": auc(have, signed, ("END", "SF"))}
    return out


#: the spacings (m) and the correlation length (m) of the spacing check, on its first cases
SPACINGS, SPACING_XI, SPACING_CASES = (GRID_M, GRID_M / 4, GRID_M / 16), 0.3, 8


def spacing_check(rows: list[dict], run_dir: str) -> list[dict]:
    """P(ARR) at correlation length :data:`SPACING_XI` read at each of :data:`SPACINGS` on the first
    :data:`SPACING_CASES` cases with a reading: what the reading's spacing does to the bound."""
    out = []
    for r in [r for r in rows if "p_arr" in r][:SPACING_CASES]:
        sc = scenario_of(run_dir, r["id"])
        out.append({"id": r["id"], "observed": r["observed"], "p_arr": {
            f"{h:.4g}": column_arrest(sc.scene, r["w_f"], r["recorded_cut"], xis=(SPACING_XI,), grid=h,
                                      samples=SAMPLES)["p_arr"][SPACING_XI] for h in SPACINGS}})
    return out


def main(argv=None) -> int:
    p = parser(__doc__, "the first 8 cases")
    p.add_argument("--runs", required=True, help="the batch's runs folder (its cases' run files)")
    p.add_argument("--cases", default=DISAGREEMENTS, help="the batch's scored cases (field_disagreements.json)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    with open(args.cases) as fh:
        src = json.load(fh)
    rows = [r for r in src["cases"] if r["observed"] in FIELD_CLASSES][: 8 if args.quick else None]
    described = []
    for k, r in enumerate(rows):
        described.append(describe(r, args.runs))
        print(f"arrest_scatter: {k + 1}/{len(rows)} {r['id']}", flush=True)
    data = {"name": "field_arrest_scatter", "cases_from": os.path.basename(args.cases),
            "runs": os.path.basename(os.path.normpath(args.runs)), "environment": environment("cpu"),
            "strength_cv": STRENGTH_CV, "correlation_lengths_m": list(CORRELATION_LENGTHS), "grid_m": GRID_M,
            "samples": SAMPLES, "counts": {c: sum(r["observed"] == c for r in described) for c in FIELD_CLASSES},
            "without": {r["id"]: r["why"] for r in described if "why" in r},
            "readings": summary(described),
            "static_arrests": {c: sum(r.get("g_min", 2.0) < 1.0 for r in described if r["observed"] == c)
                               for c in FIELD_CLASSES},
            "spacing_check": {"correlation_length_m": SPACING_XI,
                                                              "cases": spacing_check(described, args.runs)},
            "cases": described}
    path = write_json("field_arrest_scatter", data, out_dir(args, RESULTS, "field_arrest_scatter"))
    for key, v in data["readings"].items():
        print(f"{key:14s} median END/SF/ARR {v['median']}  ARR/END AUC {v['arr_vs_end']['auc']}")
    print(f"{path}: {len(described)} cases, {len(data['without'])} without a reading")
    return 0


if __name__ == "__main__":
    sys.exit(main())
