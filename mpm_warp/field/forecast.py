"""PST outcome forecasts scored as forecasters score them: ranked probability score and its skill, Brier score
per class, one-vs-rest AUC, reliability, and the balanced accuracy of the most probable class.

A forecast gives each case a probability for every field class, in the order END, SF, ARR (:data:`FIELD_CLASSES`).
The ranked probability score reads that order as a decreasing extent of the weak layer's crack: it runs to the
column's end, it stops where the slab breaks, it stops in the weak layer (docs/field.md, "Scores a forecaster
would accept"). A deterministic class is the forecast that puts all of its probability on that class
(:func:`one_hot`). The Brier score and the AUC come from scikit-learn; the RPS, which scikit-learn lacks, is its
textbook sum of squared cumulative differences over K - 1 (Epstein 1969; Wilks 2011, Statistical Methods in the
Atmospheric Sciences, §8.4.8).
"""

from __future__ import annotations

import numpy as np

from .scores import FIELD_CLASSES, scores

__all__ = ["one_hot", "climatology", "check_forecast", "rps_per_case", "ranked_probability_score", "brier_per_class",
           "auc_one_vs_rest", "reliability", "most_probable", "forecast_scores"]

#: the reliability diagram's bins of forecast probability (equal widths over [0, 1])
RELIABILITY_BINS = 5


def one_hot(classes: list[str]) -> np.ndarray:
    """The forecast (n, 3) that gives each case's class probability 1 (a class outside the field's: all 0)."""
    return np.array([[1.0 if c == k else 0.0 for k in FIELD_CLASSES] for c in classes]).reshape(len(classes), 3)


def climatology(observed: list[str]) -> np.ndarray:
    """Every case forecast with the observed classes' shares in ``observed`` (in-sample), (n, 3)."""
    shares = one_hot(observed).mean(axis=0) if observed else np.zeros(3)
    return np.tile(shares, (len(observed), 1))


def check_forecast(prob, n: int, name: str = "forecast") -> np.ndarray:
    """``prob`` as an (n, 3) float array whose rows are probabilities summing to 1 (within 1e-6), or one line."""
    from ..errors import InvalidArgument

    p = np.asarray(prob, dtype=float)
    if p.shape != (n, 3):
        raise InvalidArgument(name, f"an array of shape {p.shape}", f"(cases, 3) = ({n}, 3): P(END), P(SF), P(ARR)")
    if not np.all(np.isfinite(p)) or (p < 0.0).any() or (p > 1.0).any() or not np.allclose(p.sum(axis=1), 1.0,
                                                                                             atol=1e-6):
        raise InvalidArgument(name, "rows that are not probabilities",
                              "finite values in [0, 1] whose sum is 1 in every row")
    return p


def rps_per_case(observed: list[str], prob) -> np.ndarray:
    """Each case's ranked probability score ``sum_k (F_k - O_k)^2 / (K - 1)`` over the cumulative forecast F and
    observation O in END, SF, ARR order (0: sure and right; 1: sure and two classes off)."""
    p = check_forecast(prob, len(observed))
    F, O = np.cumsum(p, axis=1)[:, :-1], np.cumsum(one_hot(observed), axis=1)[:, :-1]
    return ((F - O) ** 2).sum(axis=1) / (len(FIELD_CLASSES) - 1)


def ranked_probability_score(observed: list[str], prob) -> float | None:
    """The mean RPS over the cases (None without cases)."""
    return float(rps_per_case(observed, prob).mean()) if observed else None


def brier_per_class(observed: list[str], prob) -> dict:
    """The Brier score of each class's probability against its occurrence {class: float} (scikit-learn's)."""
    from sklearn.metrics import brier_score_loss

    p = check_forecast(prob, len(observed))
    y = one_hot(observed)
    return {c: float(brier_score_loss(y[:, k], p[:, k])) if len(observed) else None
            for k, c in enumerate(FIELD_CLASSES)}


def auc_one_vs_rest(observed: list[str], prob, cls: str) -> float | None:
    """The area under the ROC curve of P(``cls``) for ``cls`` against every other observed class (scikit-learn's);
    None when the cases hold only one of the two groups."""
    from sklearn.metrics import roc_auc_score

    p = check_forecast(prob, len(observed))
    y = np.array([o == cls for o in observed])
    if y.all() or not y.any():
        return None
    return float(roc_auc_score(y, p[:, FIELD_CLASSES.index(cls)]))


def reliability(observed: list[str], prob, bins: int = RELIABILITY_BINS) -> dict:
    """Each class's reliability table: in each bin of forecast probability (``bins`` equal widths on [0, 1], the
    last closed), the cases, their mean forecast and the share in which the class was observed.

    Returns
    -------
    dict
        ``edges`` and, per class, ``{"count": [...], "forecast": [...], "observed": [...]}`` (None in an empty bin).
    """
    p = check_forecast(prob, len(observed))
    y = one_hot(observed)
    edges = np.linspace(0.0, 1.0, bins + 1)
    out = {"edges": [float(e) for e in edges]}
    for k, c in enumerate(FIELD_CLASSES):
        b = np.clip(np.digitize(p[:, k], edges[1:-1], right=False), 0, bins - 1)
        rows = {"count": [], "forecast": [], "observed": []}
        for j in range(bins):
            m = b == j
            rows["count"].append(int(m.sum()))
            rows["forecast"].append(float(p[m, k].mean()) if m.any() else None)
            rows["observed"].append(float(y[m, k].mean()) if m.any() else None)
        out[c] = rows
    return out


def most_probable(prob) -> list[str]:
    """Each case's most probable class (ties: the field's order END, SF, ARR)."""
    p = np.asarray(prob, dtype=float)
    return [FIELD_CLASSES[int(np.argmax(row))] for row in p]


def forecast_scores(observed: list[str], prob, reference=None) -> dict:
    """The forecast scores of ``prob`` (n, 3) on the cases ``observed``.

    Parameters
    ----------
    observed : list of str
        The observers' classes (END, SF, ARR).
    prob : array_like (n, 3)
        P(END), P(SF), P(ARR) of each case.
    reference : array_like (n, 3), optional
        The forecast the skill is taken against (default :func:`climatology` of ``observed``).

    Returns
    -------
    dict
        ``rps`` (mean RPS), ``rpss`` (``1 - rps / rps_reference``: above 0, better than the reference),
        ``brier`` {class: score}, ``auc`` {"SF", "ARR": one-vs-rest AUC}, ``balanced_accuracy`` and ``recall`` of
        the most probable class, ``reliability``.
    """
    p = check_forecast(prob, len(observed))
    ref = climatology(observed) if reference is None else check_forecast(reference, len(observed), "reference")
    rps, rps_ref = ranked_probability_score(observed, p), ranked_probability_score(observed, ref)
    top = scores(observed, most_probable(p))
    return {"n": len(observed), "rps": rps,
            "rpss": 1.0 - rps / rps_ref if rps is not None and rps_ref else None,
            "brier": brier_per_class(observed, p),
            "auc": {c: auc_one_vs_rest(observed, p, c) for c in ("SF", "ARR")},
            "balanced_accuracy": top["balanced_accuracy"], "recall": top["recall"],
            "reliability": reliability(observed, p)}
