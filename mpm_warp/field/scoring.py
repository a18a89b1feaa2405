"""A field batch's scores: the model against three references on the same cases, as classes and as probabilities.

The cases scored are those that ran (``status`` ok) and carry an observed class; a failed run has no prediction
and is counted apart (``failed``), never as a miss. On them:

- classes (:mod:`.scores`): the model, the majority class and weac's static rule, with paired bootstrap intervals
  of the balanced accuracy (:mod:`.uncertainty`);
- probabilities (:mod:`.forecast`, :mod:`.forecast_intervals`): the model's first-order reading of its run
  (:mod:`.probability`), the set's climatology, the majority class and weac's rule as sure forecasts, and the
  information bar (:mod:`.information_bar`), a cross-validated statistical model of the records' own numbers,
  and the model's readings calibrated by the same regression and folds (:mod:`.calibrated`).
"""

from __future__ import annotations

import statistics

import numpy as np

from .calibrated import MODEL_READINGS, calibrated_forecast, reading_row
from .calibration_file import apply_calibration
from .forecast import climatology, forecast_scores, one_hot
from .forecast_intervals import forecast_intervals
from .information_bar import case_features, fold_count, information_bar
from .probability import outcome_probability, slab_reading
from .scores import baseline_majority, scores
from .uncertainty import balanced_accuracy_intervals

#: folds of the information bar's cross-validation
FOLDS = 5

__all__ = ["scored", "score_records", "model_forecast", "forecasts", "wall_by_config"]


def scored(recs: list) -> list[dict]:
    """The records a batch scores: runs that finished (``status`` ok) with an observed class."""
    return [r for r in recs if r.get("status") == "ok" and r.get("observed")]


def model_forecast(recs: list) -> np.ndarray | None:
    """The model's (n, 3) probabilities of ``recs`` (:func:`~.probability.outcome_probability`; a run still
    "running" when it ended says nothing: 1/3 each), or None where a record predates the slab's stress reading."""
    rows = []
    for r in recs:
        if r.get("predicted") == "running":
            rows.append((1.0 / 3.0,) * 3)
            continue
        p = outcome_probability(r.get("predicted"), slab_reading(r)[0])
        if p is None:
            return None
        rows.append(p)
    return np.array(rows, dtype=float).reshape(len(recs), 3)


def forecasts(recs: list, *, info_repeats: int = 20, calibration: dict | None = None) -> tuple[dict, dict]:
    """Every forecast that can be made on the scored ``recs`` (name -> (n, 3)) and why any other cannot
    (name -> one line); ``calibration``: one trained on another batch (:mod:`.calibration_file`), applied to
    these cases as ``calibrated_from_file``."""
    obs = [r["observed"] for r in recs]
    out, why = {}, {}
    model = model_forecast(recs)
    if model is None:
        why["model"] = "a record has no slab_peak_stress_ratio (a run from before the stress reading)"
    else:
        out["model"] = model
    out["climatology"] = climatology(obs)
    out["majority"] = one_hot(baseline_majority(obs))
    if all(r.get("static_class") in ("END", "SF") for r in recs):
        out["weac_static"] = one_hot([r["static_class"] for r in recs])
    else:
        why["weac_static"] = "weac's rule is missing for some case (weac not installed when it was set up)"
    feats = [case_features(r) for r in recs]
    pits = [r.get("pit") or r["id"] for r in recs]
    if any(f is None for f in feats):
        why["information_bar"] = "a record lacks slab depth, density, slope or cut share (an older record)"
    elif fold_count(obs, pits, FOLDS) < 2:
        why["information_bar"] = ("too few cases to cross-validate: it needs 2 pits and 2 cases of one class "
                                  "at least")
    else:
        out["information_bar"] = information_bar(feats, obs, pits, folds=FOLDS, repeats=info_repeats)
    readings = np.array([reading_row(r) for r in recs], dtype=float).reshape(len(recs), len(MODEL_READINGS))
    absent = [k for k, gone in zip(MODEL_READINGS, np.isnan(readings).all(axis=0), strict=True) if gone]
    if absent:
        why["calibrated"] = (f"no record has the model's {', '.join(absent)} (records from before the model's "
                             "readings, scored without their runs folder)")
    elif fold_count(obs, pits, FOLDS) < 2:
        why["calibrated"] = "too few cases to cross-validate: it needs 2 pits and 2 cases of one class at least"
    else:
        out["calibrated"] = calibrated_forecast(readings, obs, pits, folds=FOLDS, repeats=info_repeats)
    if calibration is not None:
        out["calibrated_from_file"] = apply_calibration(calibration, recs)
    return out, why


def score_records(recs: list, *, resamples: int = 2000, probs: tuple[dict, dict] | None = None,
                  calibration: dict | None = None) -> dict:
    """Scores of the model and of the references on the scored records (module docstring).

    Returns
    -------
    dict
        ``cases``, ``failed``; per class predictor (``model``, ``majority``, ``weac_static``) its
        :func:`~.scores.scores`; ``uncertainty`` (balanced accuracies); ``forecast`` {name: :func:`~.forecast.
        forecast_scores`}, ``forecast_missing`` {name: why}, ``forecast_uncertainty`` (paired intervals against the
        model, when it has a forecast); the wall times. ``probs``: :func:`forecasts` of the scored records, when
        the caller has it already. ``calibration``: as :func:`forecasts`.
    """
    ok = scored(recs)
    obs = [r["observed"] for r in ok]
    pred = {"model": [r["predicted"] for r in ok], "majority": baseline_majority(obs),
            "weac_static": [r.get("static_class") or "none" for r in ok]}
    probs, missing = probs or (forecasts(ok, calibration=calibration) if ok else ({}, {"model": "no case was scored"}))
    out = {"cases": len(ok), "failed": sum(r.get("status") != "ok" for r in recs),
           **{name: scores(obs, p) for name, p in pred.items()},
           "uncertainty": balanced_accuracy_intervals(obs, pred, reference="model"),
           "forecast": {name: forecast_scores(obs, p) for name, p in probs.items()},
           "forecast_missing": missing,
           "forecast_uncertainty": (forecast_intervals(obs, probs, reference="model", resamples=resamples)
                                    if "model" in probs else None),
           "wall_s": {"median": statistics.median(walls) if (walls := [r["wall_s"] for r in ok]) else None,
                      "total": sum(r["wall_s"] for r in ok)},
           "wall_s_by_config": wall_by_config(ok)}
    return out


def wall_by_config(recs: list) -> list[dict]:
    """The median wall time (s) of the cases by how they ran: threads per case and Dask workers side by side
    (None where a record from before this was kept does not say)."""
    groups = {}
    for r in recs:
        groups.setdefault((r.get("threads"), r.get("workers")), []).append(r["wall_s"])
    return [{"threads": t, "workers": w, "cases": len(v), "median": statistics.median(v)}
            for (t, w), v in sorted(groups.items(), key=lambda kv: (kv[0][0] or 0, kv[0][1] or 0))]
