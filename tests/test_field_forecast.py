"""Forecast scores of field outcomes (mpm_warp.field.forecast, forecast_intervals, probability, information_bar,
scoring): each score against a hand computation on a made-up set; the information bar never trains a case's
prediction on its own row or its own pit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.field.calibrated import MODEL_READINGS
from mpm_warp.field.forecast import (
    brier_per_class,
    climatology,
    forecast_scores,
    one_hot,
    ranked_probability_score,
    reliability,
    rps_per_case,
)
from mpm_warp.field.forecast_intervals import forecast_intervals
from mpm_warp.field.information_bar import grouped_folds, information_bar
from mpm_warp.field.probability import outcome_probability, weibull_break_probability
from mpm_warp.field.scoring import score_records
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES

OBS = ["END", "END", "SF", "ARR"]
PROB = np.array([[0.6, 0.3, 0.1],
                 [0.2, 0.5, 0.3],
                 [0.1, 0.8, 0.1],
                 [0.5, 0.0, 0.5]])


def test_ranked_probability_score_by_hand():
    # cumulative forecast (END, END+SF) against the observation's, squared, summed over 2, halved
    hand = [((0.6 - 1) ** 2 + (0.9 - 1) ** 2) / 2,
            ((0.2 - 1) ** 2 + (0.7 - 1) ** 2) / 2,
            ((0.1 - 0) ** 2 + (0.9 - 1) ** 2) / 2,
            ((0.5 - 0) ** 2 + (0.5 - 0) ** 2) / 2]
    assert rps_per_case(OBS, PROB) == pytest.approx(hand)
    assert ranked_probability_score(OBS, PROB) == pytest.approx(np.mean(hand))
    # a sure forecast two classes off scores 1, a sure right one 0
    assert rps_per_case(["ARR", "END"], one_hot(["END", "END"])) == pytest.approx([1.0, 0.0])


def test_skill_against_climatology_brier_and_auc_by_hand():
    clim = climatology(OBS)
    assert clim[0] == pytest.approx([0.5, 0.25, 0.25])
    rps_clim = np.mean([((0.5 - 1) ** 2 + (0.75 - 1) ** 2) / 2] * 2
                       + [((0.5 - 0) ** 2 + (0.75 - 1) ** 2) / 2, ((0.5 - 0) ** 2 + (0.75 - 0) ** 2) / 2])
    s = forecast_scores(OBS, PROB)
    assert s["rps"] == pytest.approx((0.085 + 0.365 + 0.01 + 0.25) / 4)
    assert s["rpss"] == pytest.approx(1 - 0.1775 / rps_clim)
    # Brier of SF: (0.3-0)^2 + (0.5-0)^2 + (0.8-1)^2 + (0-0)^2 over 4
    assert s["brier"]["SF"] == pytest.approx((0.09 + 0.25 + 0.04 + 0.0) / 4)
    assert brier_per_class(OBS, PROB)["END"] == pytest.approx((0.16 + 0.64 + 0.01 + 0.25) / 4)
    # AUC of SF: the SF case's 0.8 beats all three others' (0.3, 0.5, 0.0): 1; of ARR: 0.5 beats 0.1, 0.3, 0.1: 1
    assert s["auc"] == {"SF": pytest.approx(1.0), "ARR": pytest.approx(1.0)}
    # most probable: END, SF, SF, END (a tie of END and ARR goes to END): recall END 1/2, SF 1, ARR 0
    assert s["recall"] == {"END": 0.5, "SF": 1.0, "ARR": 0.0}
    assert s["balanced_accuracy"] == pytest.approx(0.5)


def test_reliability_table_by_hand():
    r = reliability(OBS, PROB, bins=2)
    assert r["edges"] == [0.0, 0.5, 1.0]
    # P(END): 0.2 and 0.1 in [0, 0.5) (observed END once of 2), 0.6 and 0.5 in [0.5, 1] (END once of 2)
    assert r["END"]["count"] == [2, 2]
    assert r["END"]["forecast"] == pytest.approx([0.15, 0.55])
    assert r["END"]["observed"] == pytest.approx([0.5, 0.5])


def test_a_forecast_that_is_not_probabilities_is_one_line():
    with pytest.raises(InvalidArgument, match=r"\(cases, 3\) = \(4, 3\)"):
        forecast_scores(OBS, PROB[:, :2])
    with pytest.raises(InvalidArgument, match="sum is 1"):
        forecast_scores(OBS, PROB * 2)


@pytest.mark.slow
def test_paired_intervals_hold_the_point_values_and_a_forecast_equal_to_itself_differs_by_nothing():
    obs = ["END"] * 6 + ["SF"] * 5 + ["ARR"] * 5
    rng = np.random.default_rng(1)
    p = rng.dirichlet([1, 1, 1], size=len(obs))
    iv = forecast_intervals(obs, {"model": p, "same": p.copy(), "clim": climatology(obs)}, reference="model",
                            resamples=300)
    point = forecast_scores(obs, p)
    lo, hi = iv["intervals"]["model"]["rpss"]
    assert lo <= point["rpss"] <= hi
    d = iv["differences"]["same"]["rpss"]
    assert d["value"] == 0.0 and d["interval"] == [0.0, 0.0] and d["share_better"] == 0.0
    assert iv["intervals"]["clim"]["rpss"] == pytest.approx([0.0, 0.0])   # the reference of the skill itself


def test_weibull_reading_of_one_run():
    # the law as the Weibull mean: F(1) = 1 - exp(-Gamma(5/3)^1.5)
    assert weibull_break_probability(1.0) == pytest.approx(1 - math.exp(-math.gamma(5 / 3) ** 1.5))
    assert weibull_break_probability(0.0) == 0.0
    p_end, p_sf, p_arr = outcome_probability("END", 0.5)
    assert p_sf == pytest.approx(1 - math.exp(-(0.5 * math.gamma(5 / 3)) ** 1.5)) and p_arr == 0.0
    assert p_end + p_sf == pytest.approx(1.0)
    # a slab that cracked: capped at its strength; the rest goes on to the end
    assert outcome_probability("SF", 40.0) == pytest.approx((1 - weibull_break_probability(1.0),
                                                              weibull_break_probability(1.0), 0.0))
    assert outcome_probability("NP", 0.2)[0] == 0.0
    assert outcome_probability("running", 0.2) is None and outcome_probability("END", None) is None


def _set(n_pits=12, per_pit=2, seed=0):
    rng = np.random.default_rng(seed)
    classes = FIELD_CLASSES
    obs, pits, X = [], [], []
    for k in range(n_pits):
        for j in range(per_pit):
            c = classes[(k + j) % 3]
            obs.append(c)
            pits.append(f"pit{k}")
            X.append([0.3 + 0.2 * classes.index(c) + 0.05 * rng.standard_normal(), 150 + 30 * rng.standard_normal(),
                      30.0, 0.3])
    return np.array(X), obs, pits


def test_information_bar_folds_never_split_a_pit():
    X, obs, pits = _set()
    for train, test in grouped_folds(obs, pits, 5, seed=3):
        assert not {pits[i] for i in train} & {pits[i] for i in test}


def test_information_bar_never_trains_a_case_on_its_own_row_or_pit():
    X, obs, pits = _set()
    base = information_bar(X, obs, pits, repeats=3)
    assert base.shape == (len(obs), 3) and np.allclose(base.sum(axis=1), 1.0)
    # swap the classes of the two cases of pit 0 (the pit keeps its classes, so the stratified folds stay as they
    # were): their own predictions do not move, every other pit's does, since those models trained on them
    assert obs[0] != obs[1] and pits[0] == pits[1]
    obs2 = [obs[1], obs[0], *obs[2:]]
    again = information_bar(X, obs2, pits, repeats=3)
    same_pit = [i for i, p in enumerate(pits) if p == pits[0]]
    assert np.array_equal(again[same_pit], base[same_pit])
    assert not np.allclose(again, base)                     # other pits' models did train on it


@pytest.mark.slow
def test_score_records_drops_failed_runs_and_scores_every_forecast():
    recs = []
    X, obs, pits = _set(n_pits=9, per_pit=2)
    for i, (x, o, p) in enumerate(zip(X, obs, pits, strict=True)):
        recs.append({"id": f"c{i}", "pit": p, "status": "ok", "observed": o, "predicted": "END",
                     "static_class": "SF" if i % 2 else "END", "slab_peak_stress_ratio": 0.1 * (i % 5),
                     "slab_depth": x[0], "slab_density": x[1], "slope_deg": x[2], "cut_share": x[3], "wall_s": 1.0})
    recs.append({"id": "broken", "pit": "pit0", "status": "failed", "observed": "SF", "error": "boom"})
    sc = score_records(recs, resamples=200)
    assert sc["cases"] == 18 and sc["failed"] == 1
    assert set(sc["forecast"]) == {"model", "climatology", "majority", "weac_static", "information_bar"}
    assert "run_slab_crack_ratio" in sc["forecast_missing"]["calibrated"]        # records without the readings
    # with the model's readings (here the bar's first number, then noise), the calibration is scored too
    rng = np.random.default_rng(1)
    for r, x in zip(recs, X, strict=False):
        r.update({k: float(x[0]) if j == 0 else float(rng.standard_normal()) for j, k in enumerate(MODEL_READINGS)})
    sc = score_records(recs, resamples=200)
    assert set(sc["forecast"]) == {"model", "climatology", "majority", "weac_static", "information_bar",
                                   "calibrated"}
    assert sc["forecast"]["climatology"]["rpss"] == pytest.approx(0.0)
    assert set(sc["forecast_uncertainty"]["differences"]) == {"climatology", "majority", "weac_static",
                                                              "information_bar", "calibrated"}
    # a record from before the stress reading: the model has no forecast, and the scores say why
    del recs[0]["slab_peak_stress_ratio"]
    sc = score_records(recs, resamples=200)
    assert "model" not in sc["forecast"] and "slab_peak_stress_ratio" in sc["forecast_missing"]["model"]
    assert sc["forecast_uncertainty"] is None


@pytest.mark.parametrize("path", ["benchmarks/field/results/field_batch.json",
                                  "benchmarks/field/results/measured/field_batch.json"])
def test_the_committed_batches_rescore_to_their_committed_scores(path):
    """Every score a committed batch wrote is what its committed cases give today (the class scores, their
    intervals, the wall times); the forecasts it could not make say why."""
    import json
    import os

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, path)) as fh:
        data = json.load(fh)
    again = json.loads(json.dumps(score_records(data["cases"])))
    for key, value in data["scores"].items():
        assert again[key] == value, key
    assert again["cases"] == len([c for c in data["cases"] if c["status"] == "ok"])
    # the cases carry what every forecast reads: the slab's reading, the information bar's numbers and the
    # model's readings the calibration reads
    assert again["forecast_missing"] == {}
    assert set(again["forecast"]) >= {"model", "information_bar", "calibrated"}


def test_the_run_summary_line_of_the_probabilities():
    from mpm_warp.field.probability import probability_line

    # F(0.5) = 1 - exp(-(0.5 Gamma(5/3))^1.5) = 0.262
    line = probability_line({"class": "END", "slab_peak_stress_ratio": 0.5})
    assert line.startswith("  P(END) 0.74, P(SF) 0.26, P(ARR) 0.00 (the slab's peak stress 0.50 x its strength")
    assert probability_line({"class": None, "slab_peak_stress_ratio": 0.5}) == ""
    assert probability_line({"class": "END"}) == ""                      # a slab that cannot break
    # the slab's body, where the run read it, before the whole slab (whose base rows the weak layer cracks)
    line = probability_line({"class": "END", "slab_peak_stress_ratio": 1.0, "slab_peak_body_stress_ratio": 0.5})
    assert line.startswith("  P(END) 0.74, P(SF) 0.26, P(ARR) 0.00 (the slab body's peak stress 0.50 x its")


def test_the_slab_reading_takes_the_body_first():
    from mpm_warp.field.probability import slab_reading

    rec = {"slab_peak_stress_ratio": 1.0}
    assert slab_reading(rec) == (1.0, "slab_peak_stress_ratio")
    assert slab_reading({**rec, "slab_body_stress_ratio_at_call": 0.2}) == (0.2, "slab_body_stress_ratio_at_call")
    assert slab_reading({**rec, "slab_body_stress_ratio_at_call": 0.2, "slab_peak_body_stress_ratio": 0.3}) == (
        0.3, "slab_peak_body_stress_ratio")
    assert slab_reading({"slab_peak_body_stress_ratio": float("nan"), **rec}) == (1.0, "slab_peak_stress_ratio")
    assert slab_reading({}) == (None, None)


def test_touchdown_distance_and_brittleness_of_a_homogeneous_slab_by_hand():
    """One layer: the bending stiffness E' h^3 / 12 about its middle, Heierli's 2.331 (2 h_f D / q)^(1/4) with
    weac's collapse height of the weak layer; the brittleness h sigma_t^2 / (K_Ic^2 (1 - nu^2))."""
    from mpm_warp.field.mechanisms import brittleness, slab_bending_stiffness, touchdown_distance
    from mpm_warp.scenes.density_laws import fracture_toughness, sigrist_tensile_strength
    from mpm_warp.scenes.pst import PSTParams
    from mpm_warp.scenes.references import weac_collapse_height
    from mpm_warp.scenes.snowpack import SnowLayer

    p = PSTParams(slab_layers=(SnowLayer(0.3, 150.0, 1.0e6, 0.25),), slope_angle=30.0)
    D = 1.0e6 / (1 - 0.25**2) * 0.3**3 / 12
    assert slab_bending_stiffness(p) == pytest.approx(D, rel=1e-12)
    # two identical halves bend as the whole
    halves = PSTParams(slab_layers=(SnowLayer(0.1, 150.0, 1.0e6, 0.25), SnowLayer(0.2, 150.0, 1.0e6, 0.25)),
                       slope_angle=30.0)
    assert slab_bending_stiffness(halves) == pytest.approx(D, rel=1e-12)
    q = 150.0 * 0.3 * 9.81 * math.cos(math.radians(30.0))
    h_f = weac_collapse_height(p.weak_layer_thickness)
    assert touchdown_distance(p) == pytest.approx(2.331 * (2 * h_f * D / q) ** 0.25, rel=1e-12)
    want = 0.3 * sigrist_tensile_strength(150.0) ** 2 / (fracture_toughness(150.0) ** 2 * (1 - 0.25**2))
    assert brittleness(p) == pytest.approx(want, rel=1e-12)
