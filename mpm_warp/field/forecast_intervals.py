"""How far the forecast scores of a few field cases can be trusted: paired bootstrap intervals.

The cases are drawn again with replacement within each observed class (:func:`~.uncertainty.stratified_resamples`,
the same draws as the balanced accuracy's intervals), and every forecast is scored on the same draw, so that a
difference between the model and a baseline is paired. The climatology the skill is taken against keeps the whole
set's class shares, which a stratified draw does not change. docs/field.md says how to read the intervals.
"""

from __future__ import annotations

import numpy as np

from .forecast import FIELD_CLASSES, check_forecast, climatology, forecast_scores, most_probable, one_hot, rps_per_case
from .uncertainty import stratified_resamples

__all__ = ["forecast_intervals", "METRICS"]

#: the bootstrapped scores, and whether a higher value is better
METRICS = {"rpss": True, "brier_END": False, "brier_SF": False, "brier_ARR": False, "auc_SF": True, "auc_ARR": True,
           "balanced_accuracy": True}


def _draws(observed: list[str], prob: np.ndarray, rps_ref: np.ndarray, groups: list[np.ndarray]) -> dict:
    """Each metric of :data:`METRICS` on every resample (arrays of length resamples; nan where undefined)."""
    from sklearn.metrics import roc_auc_score

    idx = np.concatenate(groups, axis=1)                                    # (resamples, n)
    y = one_hot(observed)
    rps = rps_per_case(observed, prob)
    with np.errstate(divide="ignore", invalid="ignore"):       # a draw of one class: no skill to take (nan)
        ref = rps_ref[idx].mean(axis=1)
        out = {"rpss": np.where(ref > 0.0, 1.0 - rps[idx].mean(axis=1) / ref, np.nan)}
    for k, c in enumerate(FIELD_CLASSES):
        out[f"brier_{c}"] = ((prob[:, k] - y[:, k]) ** 2)[idx].mean(axis=1)
    for c in ("SF", "ARR"):
        k = FIELD_CLASSES.index(c)
        vals = []
        for row in idx:
            t = y[row, k]
            vals.append(roc_auc_score(t, prob[row, k]) if 0 < t.sum() < len(t) else np.nan)
        out[f"auc_{c}"] = np.array(vals)
    hits = np.asarray(most_probable(prob), dtype=object) == np.asarray(observed, dtype=object)
    out["balanced_accuracy"] = np.mean([hits[g].mean(axis=1) for g in groups], axis=0)
    return out


def _point(s: dict) -> dict:
    """The metrics of :data:`METRICS` from :func:`~.forecast.forecast_scores`' dict."""
    return {"rpss": s["rpss"], **{f"brier_{c}": s["brier"][c] for c in FIELD_CLASSES},
            "auc_SF": s["auc"]["SF"], "auc_ARR": s["auc"]["ARR"], "balanced_accuracy": s["balanced_accuracy"]}


def forecast_intervals(observed: list[str], forecasts: dict, *, reference: str, resamples: int = 2000,
                       level: float = 0.95, seed: int = 0) -> dict:
    """Bootstrap intervals of every forecast's scores and of ``reference`` against each other forecast.

    Parameters
    ----------
    observed : list of str
        The observers' classes.
    forecasts : dict
        Name -> (n, 3) probabilities P(END), P(SF), P(ARR) of the same cases.
    reference : str
        The forecast whose differences to the others are given (the model).
    resamples, level, seed
        As :func:`~.uncertainty.balanced_accuracy_intervals` (at least 100 resamples; level in (0, 1)).

    Returns
    -------
    dict
        ``level``, ``resamples``, ``seed``, ``intervals`` {name: {metric: [lo, hi]}} and ``differences`` {name:
        {metric: {"value", "interval", "share_better"}}}: ``reference`` minus ``name`` (for a Brier score, lower is
        better: ``share_better`` counts the draws where ``reference`` is better either way). A metric undefined on
        some draws (an AUC with one group drawn) is taken over the others; null where it never is defined.
    """
    from ..errors import InvalidArgument

    if reference not in forecasts:
        raise InvalidArgument("reference", reference, f"one of the forecasts {sorted(forecasts)}")
    if resamples < 100 or not 0.0 < level < 1.0:
        raise InvalidArgument("resamples, level", (resamples, level), "at least 100 resamples, a level in (0, 1)")
    out = {"level": level, "resamples": resamples, "seed": seed, "intervals": {}, "differences": {}}
    groups = stratified_resamples(observed, resamples, seed)
    if not groups:
        return out
    probs = {name: check_forecast(p, len(observed), name) for name, p in forecasts.items()}
    rps_ref = rps_per_case(observed, climatology(observed))
    draws = {name: _draws(observed, p, rps_ref, groups) for name, p in probs.items()}
    point = {name: _point(forecast_scores(observed, p)) for name, p in probs.items()}
    tail = 100.0 * (1.0 - level) / 2.0

    def interval(v):
        v = v[np.isfinite(v)]
        return [float(x) for x in np.percentile(v, [tail, 100.0 - tail])] if len(v) else None

    for name, d in draws.items():
        out["intervals"][name] = {m: interval(d[m]) for m in METRICS}
    for name in probs:
        if name == reference:
            continue
        diff = {}
        for m, higher in METRICS.items():
            d = draws[reference][m] - draws[name][m]
            d = d[np.isfinite(d)]
            a, b = point[reference][m], point[name][m]
            diff[m] = {"value": None if a is None or b is None else a - b, "interval": interval(d),
                       "share_better": float(np.mean(d > 0.0 if higher else d < 0.0)) if len(d) else None}
        out["differences"][name] = diff
    return out
