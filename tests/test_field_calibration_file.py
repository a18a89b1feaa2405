"""A calibration trained on one field batch and applied to another (mpm_warp.field.calibration_file): the file gives
the probabilities scikit-learn's fitted regression gives, never learns from the cases it is applied to, and a file
of another protocol or a damaged one is one line."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.field.calibrated import MODEL_READINGS, reading_row
from mpm_warp.field.calibration_file import apply_calibration, fit_calibration, read_calibration, write_calibration
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.scoring import score_records
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES

KEY = FieldProtocol().run_key()


def _recs(n=30, seed=0, classes=FIELD_CLASSES):
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        c = classes[i % len(classes)]
        row = {k: float(rng.standard_normal()) for k in MODEL_READINGS}
        row["run_slab_body_stress_ratio"] = 0.2 + 0.3 * FIELD_CLASSES.index(c) + 0.1 * rng.standard_normal()
        out.append({"id": f"c{i}", "pit": f"p{i // 2}", "status": "ok", "observed": c, "predicted": "END",
                    "static_class": "END", "slab_peak_stress_ratio": 0.5, "slab_depth": 0.4, "slab_density": 150.0,
                    "slope_deg": 30.0, "cut_share": 0.4, "wall_s": 1.0, **row})
    out[3]["brittleness"] = None                                # a missing reading takes the training median
    return out


def _sklearn(recs):
    from sklearn.impute import SimpleImputer
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    X = np.array([reading_row(r) for r in recs])
    return make_pipeline(SimpleImputer(strategy="median"), StandardScaler(),
                         LogisticRegression(class_weight="balanced", max_iter=2000)).fit(X, [r["observed"] for r in
                                                                                            recs]), X


@pytest.mark.parametrize("classes", [FIELD_CLASSES, ("END", "ARR")])
def test_the_file_gives_the_fitted_regressions_probabilities(classes, tmp_path):
    train = _recs(classes=classes)
    cal = fit_calibration(train, KEY)
    assert cal["trained_on"] == {c: sum(r["observed"] == c for r in train) for c in FIELD_CLASSES}
    path = str(tmp_path / "calibration.json")
    write_calibration(path, cal)
    back = read_calibration(path, KEY)
    new = _recs(n=12, seed=5)
    model, _ = _sklearn(train)
    want = model.predict_proba(np.array([reading_row(r) for r in new]))
    got = apply_calibration(back, new)
    for j, c in enumerate(model.classes_):
        assert np.allclose(got[:, FIELD_CLASSES.index(c)], want[:, j], rtol=0, atol=1e-12)
    assert np.allclose(got.sum(axis=1), 1.0)
    absent = [k for k, c in enumerate(FIELD_CLASSES) if c not in classes]
    assert np.all(got[:, absent] == 0.0)


def test_a_batch_applies_it_and_never_learns_from_its_own_cases():
    cal = fit_calibration(_recs(), KEY)
    new = _recs(n=18, seed=7)
    sc = score_records(new, resamples=200, calibration=cal)
    assert "calibrated_from_file" in sc["forecast"] and "calibrated" in sc["forecast"]
    # the cases' own classes shuffled: the cross-validated calibration moves, the file's forecast does not
    swapped = [dict(r, observed=FIELD_CLASSES[(FIELD_CLASSES.index(r["observed"]) + 1) % 3]) for r in new]
    assert np.array_equal(apply_calibration(cal, swapped), apply_calibration(cal, new))


def test_too_little_to_fit_is_no_file():
    assert fit_calibration(_recs(classes=("END",)), KEY) is None
    gone = _recs()
    for r in gone:
        r["touchdown_distance"] = math.nan
    assert fit_calibration(gone, KEY) is None


def test_a_file_of_another_protocol_or_a_damaged_one_is_one_line(tmp_path):
    path = str(tmp_path / "calibration.json")
    write_calibration(path, fit_calibration(_recs(), KEY))
    other = FieldProtocol(max_particles=50_000).run_key()
    with pytest.raises(InvalidArgument, match="another protocol .max_particles differ") as e:
        read_calibration(path, other)
    assert "\n" not in str(e.value) and path in str(e.value)
    # how many columns step together is not compared
    assert read_calibration(path, FieldProtocol(columns=8).run_key())["readings"] == list(MODEL_READINGS)
    with open(path) as fh:
        cal = json.load(fh)
    for broken in ('{"format": "mpm_warp field calibration 1"', "[]",
                   json.dumps({**cal, "readings": cal["readings"][:-1]}),
                   json.dumps({**cal, "scale": [0.0] * len(MODEL_READINGS)})):
        with open(path, "w") as fh:
            fh.write(broken)
        with pytest.raises(InvalidArgument, match="calibration") as e:
            read_calibration(path, KEY)
        assert "\n" not in str(e.value)
    with pytest.raises(InvalidArgument, match="No such file"):
        read_calibration(str(tmp_path / "none.json"), KEY)
