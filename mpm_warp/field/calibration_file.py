"""A calibration of the model's readings trained on one field batch and applied to another, as a forecaster uses
model output statistics: trained on past cases, issued on new ones.

A batch fits the calibrated forecast's regression (:mod:`.calibrated`: a class-balanced logistic regression on the
standardised :data:`~.calibrated.MODEL_READINGS`) on all of its scored cases and writes it to ``calibration.json``
with the field protocol it ran under: the readings' names, their medians (a case's missing reading takes them),
the standardisation, the coefficients and intercepts, and the classes and cases it was trained on. Another batch
run under the same protocol applies it to its own cases, which never train it (``mpm-warp field --calibration
FILE``). A file of another protocol or other readings, or one that does not read back, is refused in one line
before anything runs (docs/field.md, "The model's readings, calibrated").
"""

from __future__ import annotations

import json
import math

import numpy as np

from .calibrated import MODEL_READINGS, reading_row
from .scores import FIELD_CLASSES

__all__ = ["FORMAT", "fit_calibration", "apply_calibration", "write_calibration", "read_calibration"]

#: what the file says it is
FORMAT = "mpm_warp field calibration 1"


def _protocol(key: dict) -> dict:
    """The protocol fields a calibration must share: all of its run key but how many columns step together."""
    return {k: v for k, v in key.items() if k != "columns"}


def fit_calibration(recs: list[dict], protocol_key: dict) -> dict | None:
    """The calibration fitted on every scored record of ``recs`` (status ok, an observed field class), under the
    protocol whose ``run_key()`` is ``protocol_key``; None with fewer than two observed classes or a reading no
    case has."""
    from sklearn.impute import SimpleImputer
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    ok = [r for r in recs if r.get("status") == "ok" and r.get("observed") in FIELD_CLASSES]
    y = [r["observed"] for r in ok]
    X = np.array([reading_row(r) for r in ok], dtype=float).reshape(len(ok), len(MODEL_READINGS))
    if len(set(y)) < 2 or np.isnan(X).all(axis=0).any():
        return None
    model = make_pipeline(SimpleImputer(strategy="median"), StandardScaler(),
                          LogisticRegression(class_weight="balanced", max_iter=2000)).fit(X, y)
    imp, std, reg = model.steps[0][1], model.steps[1][1], model.steps[2][1]
    return {"format": FORMAT, "protocol": _protocol(protocol_key), "readings": list(MODEL_READINGS),
            "medians": imp.statistics_.tolist(), "mean": std.mean_.tolist(), "scale": std.scale_.tolist(),
            "classes": [str(c) for c in reg.classes_], "coef": reg.coef_.tolist(),
            "intercept": reg.intercept_.tolist(), "trained_on": {c: y.count(c) for c in FIELD_CLASSES}}


def apply_calibration(cal: dict, recs: list[dict]) -> np.ndarray:
    """P(END), P(SF), P(ARR) (n, 3) of ``recs`` from the calibration ``cal`` (:func:`read_calibration`'s)."""
    X = np.array([reading_row(r) for r in recs], dtype=float).reshape(len(recs), len(MODEL_READINGS))
    X = np.where(np.isnan(X), np.asarray(cal["medians"]), X)
    z = (X - np.asarray(cal["mean"])) / np.asarray(cal["scale"])
    logit = z @ np.asarray(cal["coef"]).T + np.asarray(cal["intercept"])
    if logit.shape[1] == 1:                                      # two classes: one logit for the second
        logit = np.hstack([np.zeros_like(logit), logit])
    p = np.exp(logit - logit.max(axis=1, keepdims=True))
    p /= p.sum(axis=1, keepdims=True)
    out = np.zeros((len(recs), len(FIELD_CLASSES)))
    for j, c in enumerate(cal["classes"]):
        out[:, FIELD_CLASSES.index(c)] = p[:, j]
    return out


def write_calibration(path: str, cal: dict) -> None:
    """Write ``cal`` to ``path`` (JSON; the batch's own output, rewritten as its scores are)."""
    from .. import io

    io.write_record(path, cal, "a field calibration")


def read_calibration(path: str, protocol_key: dict) -> dict:
    """The calibration in ``path`` for a batch under the protocol whose ``run_key()`` is ``protocol_key``, or one
    line (InvalidArgument) naming the file and what is wrong with it."""
    from ..errors import InvalidArgument

    want = "a calibration.json a field batch wrote, under this batch's protocol"
    try:
        with open(path) as fh:
            cal = json.load(fh)
    except (OSError, ValueError) as e:
        raise InvalidArgument("calibration", path, f"{want} ({type(e).__name__}: {e})") from None
    k, n = len(MODEL_READINGS), None
    try:
        n = len(cal["classes"])
        ok = (cal["format"] == FORMAT and cal["readings"] == list(MODEL_READINGS)
              and all(len(cal[f]) == k for f in ("medians", "mean", "scale"))
              and set(cal["classes"]) <= set(FIELD_CLASSES) and 2 <= n
              and np.asarray(cal["coef"], dtype=float).shape == ((1 if n == 2 else n), k)
              and len(cal["intercept"]) == (1 if n == 2 else n)
              and all(math.isfinite(float(v)) and (f != "scale" or float(v) > 0.0)
                      for f in ("medians", "mean", "scale") for v in cal[f]))
    except (KeyError, TypeError, ValueError):
        ok = False
    if not ok:
        raise InvalidArgument("calibration", path, f"{want}: {FORMAT}, the readings {', '.join(MODEL_READINGS)}")
    if cal["protocol"] != _protocol(protocol_key):
        diff = sorted(f for f in set(cal["protocol"]) | set(_protocol(protocol_key))
                      if cal["protocol"].get(f) != _protocol(protocol_key).get(f))
        raise InvalidArgument("calibration", path, f"{want}: it was trained under another protocol "
                                                   f"({', '.join(diff)} differ)")
    return cal
