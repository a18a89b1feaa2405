"""How far a balanced accuracy on a few field cases can be trusted: bootstrap intervals, and paired differences.

A balanced accuracy over ten cases a class moves by a tenth with one case. The cases are resampled with
replacement within each observed class (the classes keep their counts, as the stratified selection drew
them), and each predictor is scored on the same resample, so that the difference between the model and a
baseline is paired: the cases both get right or both get wrong cancel. The interval is the central
``level`` share of the resampled values (percentile bootstrap, seeded: the same cases give the same
interval). docs/field.md says how to read it.
"""

from __future__ import annotations

import numpy as np

from .scores import FIELD_CLASSES, scores

__all__ = ["balanced_accuracy_intervals", "stratified_resamples"]


def stratified_resamples(observed: list[str], resamples: int, seed: int) -> list[np.ndarray]:
    """Per observed class present, an index array (resamples, n_class) of its cases drawn with replacement (seeded):
    every resample keeps each class's count."""
    obs = np.asarray(observed, dtype=object)
    members = [m for m in (np.flatnonzero(obs == c) for c in FIELD_CLASSES) if len(m)]
    rng = np.random.default_rng(seed)
    return [m[rng.integers(0, len(m), size=(resamples, len(m)))] for m in members]


def _balanced(hits: np.ndarray, groups: list[np.ndarray]) -> np.ndarray:
    """Mean recall over the classes of ``groups`` (index arrays of shape (resamples, n_class)) from ``hits``
    (bool, (cases,)): one value per resample."""
    return np.mean([hits[g].mean(axis=1) for g in groups], axis=0)


def balanced_accuracy_intervals(observed: list[str], predictions: dict[str, list[str]], *, reference: str,
                                resamples: int = 4000, level: float = 0.95, seed: int = 0) -> dict:
    """Bootstrap intervals of each predictor's balanced accuracy and of ``reference`` minus each other one.

    Parameters
    ----------
    observed : list of str
        The observer's classes (END, SF, ARR; others are not scored).
    predictions : dict
        Predictor name -> its classes for the same cases.
    reference : str
        The predictor whose differences to the others are given (the model).
    resamples : int
        Bootstrap resamples (at least 100).
    level : float
        Share of the resampled values inside an interval, in (0, 1).
    seed : int
        Seed of the resampling.

    Returns
    -------
    dict
        ``level``, ``resamples``, ``seed``, ``intervals`` {name: [lo, hi]} and ``differences`` {name: {"value",
        "interval", "share_above"}} (``reference`` minus ``name``; ``share_above``: the resamples where
        ``reference`` scores higher); empty dicts without cases. A class with one case keeps it in every
        resample, and says nothing of its spread.
    """
    if reference not in predictions:
        raise ValueError(f"reference {reference!r} is not one of the predictors {sorted(predictions)}")
    if resamples < 100 or not 0.0 < level < 1.0:
        raise ValueError(f"resamples = {resamples} (at least 100) and level = {level} (in (0, 1))")
    out = {"level": level, "resamples": resamples, "seed": seed, "intervals": {}, "differences": {}}
    obs = np.asarray(observed, dtype=object)
    groups = stratified_resamples(observed, resamples, seed)
    if not groups:
        return out
    tail = 100.0 * (1.0 - level) / 2.0
    values = {}
    for name, pred in predictions.items():
        if len(pred) != len(observed):
            raise ValueError(f"{name}: {len(pred)} predictions for {len(observed)} cases")
        hits = obs == np.asarray(pred, dtype=object)
        values[name] = _balanced(hits, groups)
        out["intervals"][name] = [float(v) for v in np.percentile(values[name], [tail, 100.0 - tail])]
    ref = values[reference]
    point = {name: scores(observed, p)["balanced_accuracy"] for name, p in predictions.items()}
    for name in predictions:
        if name == reference:
            continue
        d = ref - values[name]
        out["differences"][name] = {"value": point[reference] - point[name],
                                    "interval": [float(v) for v in np.percentile(d, [tail, 100.0 - tail])],
                                    "share_above": float(np.mean(d > 0.0))}
    return out
