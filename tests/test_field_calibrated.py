"""The model's readings calibrated (mpm_warp.field.calibrated): the information bar's own regression and folds on
the model's readings; a case never trains its own prediction; a missing reading takes the training folds' value;
misuse is one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.field.calibrated import MODEL_READINGS, calibrated_forecast, reading_row
from mpm_warp.field.forecast import forecast_scores
from mpm_warp.field.information_bar import cross_validated, information_bar
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES

K = len(MODEL_READINGS)


def _set(n_pits=15, per_pit=2, seed=0, spread=0.05):
    """Made-up readings: the first says the class (0.2, 0.5, 0.8 for END, SF, ARR, plus noise of ``spread``), the
    others are noise."""
    rng = np.random.default_rng(seed)
    obs, pits, X = [], [], []
    for k in range(n_pits):
        for j in range(per_pit):
            c = FIELD_CLASSES[(k + j) % 3]
            obs.append(c)
            pits.append(f"pit{k}")
            X.append([0.2 + 0.3 * FIELD_CLASSES.index(c) + spread * rng.standard_normal(),
                      *rng.standard_normal(K - 1)])
    return np.array(X), obs, pits


def test_a_reading_that_says_the_class_is_found_out_of_fold():
    X, obs, pits = _set(n_pits=45)
    prob = calibrated_forecast(X, obs, pits, repeats=2)
    assert prob.shape == (len(obs), 3) and np.allclose(prob.sum(axis=1), 1.0)
    # the classes lie 6 noise widths apart on the first reading, beside 9 readings of noise: the regularised
    # regression (scikit-learn's C = 1) finds nearly every case's class (0.96 measured; 0.70 on 15 pits)
    assert forecast_scores(obs, prob)["balanced_accuracy"] > 0.9
    # with the class buried in noise 10 times the spacing, the calibration has nothing to read
    Xn, obs_n, pits_n = _set(n_pits=45, spread=3.0, seed=1)
    assert forecast_scores(obs_n, calibrated_forecast(Xn, obs_n, pits_n, repeats=2))["balanced_accuracy"] < 0.6


def test_it_is_the_information_bars_regression_on_other_inputs():
    X, obs, pits = _set()
    four = X[:, :4]
    assert np.array_equal(information_bar(four, obs, pits, repeats=2),
                          cross_validated(four, obs, pits, folds=5, repeats=2, seed=0))


def test_a_case_never_trains_its_own_prediction_or_its_pits():
    X, obs, pits = _set()
    base = calibrated_forecast(X, obs, pits, repeats=2)
    assert obs[0] != obs[1] and pits[0] == pits[1]
    obs2 = [obs[1], obs[0], *obs[2:]]          # the pit keeps its classes, so the stratified folds stay the same
    again = calibrated_forecast(X, obs2, pits, repeats=2)
    assert np.array_equal(again[:2], base[:2])
    assert not np.allclose(again, base)


def test_a_missing_reading_takes_the_training_folds_median():
    X, obs, pits = _set()
    gone = X.copy()
    gone[0, 0] = math.nan
    # the median of the other pits' first reading, put in by hand where the model would read case 0's
    by_hand = X.copy()
    p_gone = calibrated_forecast(gone, obs, pits, repeats=1)
    from mpm_warp.field.information_bar import grouped_folds

    (train, _), = [(tr, te) for tr, te in grouped_folds(obs, pits, 5, 0) if 0 in te]
    by_hand[0, 0] = float(np.median(X[train, 0]))
    p_hand = calibrated_forecast(by_hand, obs, pits, repeats=1)
    assert np.allclose(p_gone[0], p_hand[0], rtol=0, atol=1e-12)
    assert np.isfinite(p_gone).all()


def test_reading_row_reads_the_model_and_marks_what_is_missing():
    row = {k: 0.5 for k in MODEL_READINGS}
    row["run_slab_body_stress_ratio"] = None
    row["touchdown_distance"] = float("inf")
    row["slab_depth"] = 0.3                                # a record's own number: not read
    vals = reading_row(row)
    assert len(vals) == K and sum(math.isnan(v) for v in vals) == 2 and vals.count(0.5) == K - 2
    assert not {"slab_depth", "slab_density", "slope_deg", "cut_share"} & set(MODEL_READINGS)


def test_misuse_is_one_line():
    X, obs, pits = _set()
    with pytest.raises(InvalidArgument, match="readings"):
        calibrated_forecast(X[:, :3], obs, pits)
    empty = X.copy()
    empty[:, 2] = math.nan
    with pytest.raises(InvalidArgument, match=list(MODEL_READINGS)[2]):
        calibrated_forecast(empty, obs, pits)
    with pytest.raises(InvalidArgument, match="pits"):
        calibrated_forecast(X, obs, ["one"] * len(obs))
