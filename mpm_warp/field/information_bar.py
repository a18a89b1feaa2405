"""The information bar: what the pit records alone carry about a PST's outcome, measured by a statistical model.

A class-balanced logistic regression (scikit-learn) on four numbers every field case records (:data:`FEATURES`:
slab depth, mean slab density, slope, cut over column length), cross-validated with folds grouped by pit: the
cases of one pit are always predicted together by a model trained on the other pits, so a case never trains its
own prediction, nor does its pit neighbour. Its out-of-fold probabilities are averaged over repeated seeded
splits. It is a reference, not a physical model: the physics aims to reach it (docs/field.md).
"""

from __future__ import annotations

import numpy as np

from .scores import FIELD_CLASSES

__all__ = ["FEATURES", "CASE_FEATURES", "case_record_features", "case_features", "fold_count", "grouped_folds",
           "information_bar", "cross_validated"]

#: the recorded numbers the statistical model reads, and their units
FEATURES = {"slab_depth": "m", "slab_density": "kg/m^3", "slope_deg": "deg", "cut_share": "-"}


#: what a case record says of the observer's column: :data:`FEATURES` and the column's length
CASE_FEATURES = ("slab_depth", "slab_density", "slope_deg", "column_length", "cut_share")


def case_record_features(case) -> dict:
    """The field case's (:class:`~.cases.FieldCase`) bed-normal slab depth (m), mean slab density (kg/m^3), slope
    (deg), column length (m) and recorded cut over column length (-): :data:`CASE_FEATURES`."""
    p = case.params
    slab = p.slab_stack()
    depth = sum(ly.thickness for ly in slab)
    return {"slab_depth": float(depth), "slab_density": sum(ly.thickness * ly.density for ly in slab) / depth,
            "slope_deg": float(p.slope_angle), "column_length": float(p.length),
            "cut_share": float(case.record.cut_length) / float(p.length)}


def case_features(rec: dict) -> list[float] | None:
    """A record's :data:`FEATURES` in order, or None where one is missing or not finite."""
    vals = [rec.get(k) for k in FEATURES]
    if any(not isinstance(v, (int, float)) or v != v or abs(v) == float("inf") for v in vals):
        return None
    return [float(v) for v in vals]


def fold_count(observed: list[str], groups: list[str], folds: int) -> int:
    """The folds a split can have: at most ``folds``, the pits, and the cases of the largest class (below 2, the
    cases cannot be cross-validated)."""
    largest = max((observed.count(c) for c in set(observed)), default=0)
    return min(folds, len(set(groups)), largest)


def grouped_folds(observed: list[str], groups: list[str], folds: int, seed: int) -> list[tuple[np.ndarray, ...]]:
    """``(train, test)`` index pairs of a stratified split into ``folds`` folds that never splits a group (a pit)."""
    from sklearn.model_selection import StratifiedGroupKFold

    k = fold_count(observed, groups, folds)
    split = StratifiedGroupKFold(n_splits=k, shuffle=True, random_state=seed)
    return list(split.split(np.zeros(len(observed)), observed, groups))


def information_bar(features, observed: list[str], groups: list[str], *, folds: int = 5, repeats: int = 20,
                    seed: int = 0) -> np.ndarray:
    """Out-of-fold P(END), P(SF), P(ARR) of each case from a class-balanced logistic regression.

    Parameters
    ----------
    features : array_like (n, 4)
        Each case's :data:`FEATURES`.
    observed : list of str
        The observers' classes (END, SF, ARR).
    groups : list of str
        Each case's pit: the folds never split one.
    folds : int
        Folds of each split (at most the number of pits; at least 2 pits are needed).
    repeats : int
        Seeded splits averaged (seeds ``seed`` ... ``seed + repeats - 1``).

    Returns
    -------
    numpy.ndarray (n, 3)
        Each case's mean out-of-fold probabilities (a class absent from a fold's training cases gets 0 there).
    """
    from ..errors import InvalidArgument

    X = np.asarray(features, dtype=float)
    n = len(observed)
    if X.shape != (n, len(FEATURES)) or len(groups) != n:
        raise InvalidArgument("features", f"shape {X.shape} for {n} cases and {len(groups)} pits",
                              f"({n}, {len(FEATURES)}): {', '.join(FEATURES)}, one pit per case")
    if fold_count(list(observed), list(groups), folds) < 2 or repeats < 1:
        raise InvalidArgument("folds, repeats, pits", (folds, repeats, len(set(groups))),
                              "folds >= 2, repeats >= 1, and cases from at least 2 pits with 2 of one class")
    return cross_validated(X, observed, groups, folds=folds, repeats=repeats, seed=seed)


def cross_validated(X: np.ndarray, observed: list[str], groups: list[str], *, folds: int, repeats: int,
                    seed: int) -> np.ndarray:
    """Out-of-fold P(END), P(SF), P(ARR) (n, 3) of a class-balanced logistic regression on the standardised
    columns of ``X`` (n, k), averaged over ``repeats`` seeded splits of :func:`grouped_folds` (a pit is never
    split). A missing value (nan) takes the median of its column over the fold's training cases. A fold whose
    training cases hold one class gives that class; a class absent from a fold's training cases gets 0 there."""
    from sklearn.impute import SimpleImputer
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    n = len(observed)
    y = np.asarray(observed, dtype=object)
    prob = np.zeros((n, len(FIELD_CLASSES)))
    for r in range(repeats):
        for train, test in grouped_folds(observed, groups, folds, seed + r):
            if len(set(y[train])) < 2:
                prob[test] += np.array([1.0 if c == y[train][0] else 0.0 for c in FIELD_CLASSES])
                continue
            model = make_pipeline(SimpleImputer(strategy="median"), StandardScaler(),
                                  LogisticRegression(class_weight="balanced", max_iter=2000))
            model.fit(X[train], y[train])
            p = model.predict_proba(X[test])
            for j, c in enumerate(model.classes_):
                prob[test, FIELD_CLASSES.index(c)] += p[:, j]
    return prob / repeats
