"""Which quantity of the column tells the observers' SF records from their END records, and how well?

For every scored column of the development set's batches (``field_disagreements.json``, the runs' own readings)
set up again from its pit, each candidate's value: the records' own numbers (slab depth, mean density), the
run's (its slab's largest effective stress over strength), weac's static rule's (the slab's peak stress over
strength at the recorded cut) and closed forms from published laws (``mpm_warp.field.mechanisms``: Heierli's
touchdown distance against the column, the slab's brittleness). For each: the SF-against-END AUC (scikit-learn;
the direction each candidate's physics says: a shorter touchdown distance, a larger stress ratio mean SF), the
ARR-against-the-rest AUC, and the medians by observed class. A candidate's rule, where it has one (SF where the
slab touches down inside the column), is scored as classes too, and the information bar (the records' four numbers
in a logistic regression cross-validated by pit) is scored beside them. Nothing physical is fitted. Writes
``benchmarks/field/results/field_mechanisms.json``.

Usage: ``python benchmarks/field/mechanisms.py --data DIR`` (DIR: the unpacked pits); ``--quick``: 24 cases.
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import warnings

from mpm_warp.field.batch import gather
from mpm_warp.field.mechanisms import brittleness, touchdown_distance
from mpm_warp.field.scores import FIELD_CLASSES, scores
from mpm_warp.field.static_rule import weac_static_rule
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
DISAGREEMENTS = os.path.join(RESULTS, "field_disagreements.json")
FORECAST = os.path.join(RESULTS, "field_forecast.json")

#: candidate -> (what it is, +1: a larger value says SF; -1: a smaller one does)
CANDIDATES = {
    "slab_depth": ("the slab's bed-normal depth (m), recorded", -1),
    "slab_density": ("the slab's mean density (kg/m^3), recorded or from hardness and grain", -1),
    "run_slab_crack_ratio": ("the run's largest slab kappa over strength (-), 0 below strength", +1),
    "run_slab_stress_ratio": ("the run's largest stress the slab carried over its strength, to the call (-)", +1),
    "run_slab_crack_cover": ("the run's largest share of slab rows cracked through at one place (-)", +1),
    "run_slab_body_stress_ratio": ("the stress the run's slab body carried at the call over its strength (-)", +1),
    "run_slab_drop_at_call": ("the run's largest slab-base drop at the call over the collapse height (-)", +1),
    "run_slab_down_share": ("the run's share of the crack over which the slab had come down at the call (-)", +1),
    "static_peak_ratio": ("weac's slab peak stress over strength at the recorded cut (-)", +1),
    "touchdown_distance": ("Heierli's touchdown distance of the slab (m)", -1),
    "touchdown_over_column": ("the touchdown distance over the column's length (-)", -1),
    "brittleness": ("slab depth over its characteristic length K_Ic^2 (1 - nu^2) / sigma_t^2 (-)", +1),
}


def case_key(row: dict) -> tuple[str, str]:
    """(pit stem, field line) of a batch row: the pit's file is the id less its ``-<k>-<digest>`` tail."""
    return row["id"].rsplit("-", 2)[0], row["test"]


def describe(row: dict, case) -> dict:
    """One column's candidates (:data:`CANDIDATES`)."""
    p = case.params
    td = touchdown_distance(p)
    return {"id": row["id"], "observed": row["observed"], "predicted": row["predicted"],
            "slab_depth": row["slab_depth_m"], "slab_density": row["slab_density"],
            "run_slab_crack_ratio": row.get("slab_crack_ratio"),
            "run_slab_stress_ratio": row.get("slab_stress_ratio"), "run_slab_crack_cover": row.get("slab_crack_cover"),
            "run_slab_body_stress_ratio": row.get("slab_body_stress_ratio_at_call"),
            "run_slab_drop_at_call": row.get("slab_drop_at_call"), "run_slab_down_share": row.get("slab_down_share"),
            "static_peak_ratio": weac_static_rule(p)["peak_ratio"], "touchdown_distance": td,
            "touchdown_over_column": td / p.length, "brittleness": brittleness(p), "column_m": p.length}


def auc(rows: list[dict], key: str, sign: int, positive: str, negatives: tuple[str, ...]) -> dict:
    """AUC of ``sign * key`` for ``positive`` against ``negatives`` (None with one group empty)."""
    from sklearn.metrics import roc_auc_score

    use = [r for r in rows if r[key] is not None and r["observed"] in (positive, *negatives)]
    y = [r["observed"] == positive for r in use]
    return {"cases": len(use), "auc": float(roc_auc_score(y, [sign * r[key] for r in use]))
            if 0 < sum(y) < len(y) else None}


def table(rows: list[dict]) -> dict:
    """Per candidate: its AUCs and medians by observed class."""
    out = {}
    for key, (what, sign) in CANDIDATES.items():
        med = {c: statistics.median(v) if (v := [r[key] for r in rows if r["observed"] == c and r[key] is not None])
               else None for c in FIELD_CLASSES}
        out[key] = {"what": what, "direction": "larger: SF" if sign > 0 else "smaller: SF",
                    "sf_vs_end": auc(rows, key, sign, "SF", ("END",)),
                    "arr_vs_rest": auc(rows, key, sign, "ARR", ("END", "SF")), "median": med}
    return out


def touchdown_rule(rows: list[dict]) -> dict:
    """SF where the slab touches down inside its column (touchdown distance below the column's length), END
    otherwise, scored as classes."""
    obs = [r["observed"] for r in rows]
    pred = ["SF" if r["touchdown_over_column"] < 1.0 else "END" for r in rows]
    return {"rule": "SF where touchdown_over_column < 1, else END", **scores(obs, pred)}


def _forecast(obs: list[str], prob) -> dict:
    """A forecast's scores without its reliability table, and its SF-against-END AUC."""
    from sklearn.metrics import roc_auc_score

    from mpm_warp.field.forecast import forecast_scores

    sf_end = [i for i, o in enumerate(obs) if o in ("SF", "END")]
    sc = forecast_scores(obs, prob)
    sc.pop("reliability")
    return {"auc_sf_vs_end": float(roc_auc_score([obs[i] == "SF" for i in sf_end], prob[sf_end, 1])), **sc}


#: the same regression on parts of the readings, and on the records with them: what the dynamic run alone
#: carries, and whether the model's readings add to the records'
PARTS = {"run_readings": "the run's readings alone (`run_*`)",
         "static_readings": "weac's and the closed forms' readings alone (all but `run_*`)",
         "records_and_readings": "the records' four numbers and the model's readings together"}


def forecasts(rows: list[dict], described: list[dict], forecast_path: str) -> tuple[dict, dict, dict]:
    """The information bar (the records' four numbers) and the model's readings calibrated
    (``mpm_warp.field.calibrated``: the bar's regression and folds on :data:`~mpm_warp.field.calibrated.MODEL_READINGS`)
    on the same columns, with their scores, and the same regression on :data:`PARTS`; the calibration's paired
    bootstrap intervals against the bar, the climatology and the forecasts ``forecast_path`` (``field_forecast.json``)
    gives every one of these columns (the raw model, weac's rule, the majority class); the records and readings
    together against the bar."""
    import numpy as np

    from mpm_warp.field.calibrated import MODEL_READINGS, calibrated_forecast, reading_row
    from mpm_warp.field.forecast import climatology
    from mpm_warp.field.forecast_intervals import forecast_intervals
    from mpm_warp.field.information_bar import cross_validated, information_bar

    obs = [r["observed"] for r in described]
    pits = [case_key(r)[0] for r in rows]
    feats = [[r["slab_depth_m"], r["slab_density"], r["slope_deg"], r["cut_share"]] for r in rows]
    readings = np.array([reading_row(r) for r in described], dtype=float)
    run = [j for j, k in enumerate(MODEL_READINGS) if k.startswith("run_")]
    probs = {"calibrated": calibrated_forecast(readings, obs, pits),
             "information_bar": information_bar(feats, obs, pits), "climatology": climatology(obs)}
    static = [j for j in range(len(MODEL_READINGS)) if j not in run]
    parts = {"run_readings": readings[:, run], "static_readings": readings[:, static],
             "records_and_readings": np.hstack([np.array(feats), readings])}
    probs.update({k: cross_validated(X, obs, pits, folds=5, repeats=20, seed=0) for k, X in parts.items()})
    if os.path.exists(forecast_path):
        with open(forecast_path) as fh:
            given = {c["id"]: c for c in json.load(fh)["cases"]}
        for name in ("model", "weac_static", "majority"):
            if all(r["id"] in given and given[r["id"]].get(name) for r in described):
                probs[name] = np.array([given[r["id"]][name] for r in described], dtype=float)
    scored = {name: _forecast(obs, p) for name, p in probs.items()}
    calibrated = {"readings": MODEL_READINGS, "forecasts_from": os.path.basename(forecast_path), "scores": scored,
                  "uncertainty": forecast_intervals(obs, probs, reference="calibrated", resamples=4000),
                  "parts": PARTS, "records_and_readings_vs_bar": forecast_intervals(
                      obs, {k: probs[k] for k in ("records_and_readings", "information_bar")},
                      reference="records_and_readings", resamples=4000)["differences"]["information_bar"],
                  "missing_readings": dict(zip(MODEL_READINGS, map(int, np.isnan(readings).sum(axis=0)),
                                               strict=True))}
    return scored["information_bar"], calibrated, {k: p.tolist() for k, p in probs.items()}


def main(argv=None) -> int:
    p = parser(__doc__, "the first 24 cases")
    p.add_argument("--data", required=True, help="folder of CAAML files the batches read")
    p.add_argument("--cases", default=DISAGREEMENTS, help="the batches' scored cases (field_disagreements.json)")
    p.add_argument("--forecast", default=FORECAST, help="the same columns' forecasts (field_forecast.json)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    with open(args.cases) as fh:
        src = json.load(fh)
    rows = src["cases"][:24] if args.quick else src["cases"]
    files = sorted({os.path.join(args.data, case_key(r)[0] + ".xml") for r in rows})
    cases, _ = gather(files, calibrate=False)
    by = {(os.path.splitext(c.pit)[0], c.test): c for c in cases}
    missing = [r["id"] for r in rows if case_key(r) not in by]
    if missing:
        print(f"error: data: {len(missing)} scored cases have no record in their pit (e.g. {missing[0]})",
              file=sys.stderr)
        return 1
    described = [describe(r, by[case_key(r)]) for r in rows]
    bar, calibrated, probs = forecasts(rows, described, args.forecast)
    for k, r in enumerate(described):
        r["forecast"] = {name: p[k] for name, p in probs.items() if name != "climatology"}
    data = {"name": "field_mechanisms", "cases_from": os.path.basename(args.cases),
            "data": os.path.basename(os.path.normpath(args.data)), "environment": environment("cpu"),
            "counts": {c: sum(r["observed"] == c for r in described) for c in FIELD_CLASSES},
            "candidates": table(described), "touchdown_rule": touchdown_rule(described),
            "information_bar": bar, "calibrated": calibrated, "cases": described}
    path = write_json("field_mechanisms", data, out_dir(args, RESULTS, "field_mechanisms"))
    for key, v in data["candidates"].items():
        a, b = v["sf_vs_end"]["auc"], v["arr_vs_rest"]["auc"]
        print(f"{key:24s} SF/END AUC {a if a is None else round(a, 3)}  ARR/rest AUC {b if b is None else round(b, 3)}")
    for name, sc in calibrated["scores"].items():
        print(f"{name:16s} RPSS {sc['rpss']:.3f}  balanced accuracy {sc['balanced_accuracy']:.3f}  AUC SF "
              f"{sc['auc']['SF']:.3f} ARR {sc['auc']['ARR']:.3f}")
    print(f"{path}: {len(described)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
