"""How well predicted PST outcomes match the observed ones: confusion matrix, recall per class, balanced accuracy.

The observed classes are the field's (End, SF, Arr, written END, SF, ARR here); a prediction may also be a class
the field does not write (``NP``: the crack never ran away from the saw; ``running``: the run ended before the
crack's fate was decided; ``failed``). Every observed case counts: a prediction outside the observed classes is
a miss. The balanced accuracy is the mean recall over the observed classes present, so that always answering
the majority class scores 1/3 with three classes present, whatever their shares.

Baselines on the same cases (:func:`baseline_majority`, and the static rule of the batch) are scored by the same
function, so that the value of the dynamics is measured, not asserted.
"""

from __future__ import annotations

from collections import Counter

from ..scenes.pst.outcome import FIELD_CLASSES

__all__ = ["FIELD_CLASSES", "field_class", "confusion", "scores", "baseline_majority"]



def field_class(outcome: str | None) -> str | None:
    """The observer's outcome in the model's spelling: "End" -> "END", "Arr" -> "ARR", "SF" -> "SF"."""
    if outcome is None:
        return None
    up = outcome.strip().upper()
    return up if up in FIELD_CLASSES else None


def confusion(observed: list[str], predicted: list[str]) -> dict:
    """``{"rows": observed classes, "columns": predicted classes, "counts": [[n]]}`` (columns: the field classes,
    then any other prediction in sorted order)."""
    if len(observed) != len(predicted):
        raise ValueError(f"observed and predicted differ in length ({len(observed)} and {len(predicted)})")
    others = sorted({p for p in predicted if p not in FIELD_CLASSES})
    cols = list(FIELD_CLASSES) + others
    pairs = Counter(zip(observed, predicted, strict=True))
    return {"rows": list(FIELD_CLASSES), "columns": cols,
            "counts": [[pairs[(o, p)] for p in cols] for o in FIELD_CLASSES]}


def scores(observed: list[str], predicted: list[str]) -> dict:
    """Recall per observed class (None for a class with no case), balanced accuracy, accuracy, counts.

    Returns
    -------
    dict
        ``n``, ``recall`` {class: float or None}, ``balanced_accuracy`` (mean recall over the classes present;
        None without cases), ``accuracy``, ``confusion`` (:func:`confusion`).
    """
    n = len(observed)
    recall = {}
    for c in FIELD_CLASSES:
        idx = [i for i, o in enumerate(observed) if o == c]
        recall[c] = sum(predicted[i] == c for i in idx) / len(idx) if idx else None
    present = [r for r in recall.values() if r is not None]
    return {"n": n, "recall": recall,
            "balanced_accuracy": sum(present) / len(present) if present else None,
            "accuracy": sum(o == p for o, p in zip(observed, predicted, strict=True)) / n if n else None,
            "confusion": confusion(observed, predicted)}


def baseline_majority(observed: list[str]) -> list[str]:
    """Always the most frequent observed class (ties: the field's order END, SF, ARR)."""
    if not observed:
        return []
    counts = Counter(observed)
    best = max(FIELD_CLASSES, key=lambda c: (counts[c], -FIELD_CLASSES.index(c)))
    return [best] * len(observed)
