"""The model's readings calibrated as a forecaster calibrates a numerical model: model output statistics.

A weather service does not issue its model's raw fields: it maps them to the observed outcome with a regression
trained on past cases (model output statistics, Glahn and Lowry 1972, J. Appl. Meteor. 11, 1203-1211). Here the
model's readings of a field column (:data:`MODEL_READINGS`: its dynamic run's and its static solution's, never the
records' own numbers) go into the information bar's own regression and folds (a class-balanced logistic
regression, cross-validated with folds grouped by pit; :func:`~.information_bar.cross_validated`), so the two
forecasts differ only in what they read. It measures whether the physics carries what the records carry. Its
coefficients are statistics fitted on other pits, never a physical parameter (docs/field.md, "The model's
readings, calibrated").
"""

from __future__ import annotations

import math

import numpy as np

from .information_bar import cross_validated, fold_count

__all__ = ["MODEL_READINGS", "RUN_READINGS", "CLOSED_FORMS", "reading_row", "closed_form_readings",
           "run_readings", "add_model_readings", "calibrated_forecast"]

#: the model's readings of a column the calibration reads, and what each is: every reading of the mechanism
#: study (docs/field.md, "Why thin, light slabs break") that comes from the model and not from the records
MODEL_READINGS = {
    "run_slab_crack_ratio": "the run's largest slab kappa over strength (-)",
    "run_slab_stress_ratio": "the run's largest stress the slab carried over its strength, to the call (-)",
    "run_slab_crack_cover": "the run's largest share of slab rows cracked through at one place (-)",
    "run_slab_body_stress_ratio": "the stress the run's slab body carried at the call over its strength (-)",
    "run_slab_drop_at_call": "the run's largest slab-base drop at the call over the collapse height (-)",
    "run_slab_down_share": "the run's share of the crack over which the slab had come down at the call (-)",
    "static_peak_ratio": "weac's slab peak stress over strength at the recorded cut (-)",
    "touchdown_distance": "Heierli's touchdown distance of the slab (m)",
    "touchdown_over_column": "the touchdown distance over the column's length (-)",
    "brittleness": "slab depth over its characteristic length K_Ic^2 (1 - nu^2) / sigma_t^2 (-)",
}


#: the readings of :data:`MODEL_READINGS` from the run's files, by the key :mod:`.studies.at_call` gives each
RUN_READINGS = {"run_slab_stress_ratio": "slab_stress_ratio", "run_slab_crack_cover": "slab_crack_cover",
                "run_slab_body_stress_ratio": "slab_body_stress_ratio_at_call",
                "run_slab_drop_at_call": "slab_drop_at_call", "run_slab_down_share": "slab_down_share"}
#: the readings of :data:`MODEL_READINGS` from closed forms of the recorded column (:mod:`.mechanisms`)
CLOSED_FORMS = ("touchdown_distance", "touchdown_over_column", "brittleness")


def closed_form_readings(params) -> dict:
    """The field column's (PSTParams, as recorded) :data:`CLOSED_FORMS`: Heierli's touchdown distance (m), it over
    the column's length (-) and the slab's brittleness (-)."""
    from .mechanisms import brittleness, touchdown_distance

    td = touchdown_distance(params)
    return {"touchdown_distance": td, "touchdown_over_column": td / params.length, "brittleness": brittleness(params)}


def run_readings(run_dir: str, case_id: str, scenario) -> dict:
    """The run's readings of :data:`MODEL_READINGS` (``run_*``) from the case's run file and final checkpoint in
    ``run_dir`` (``scenario``: the case's); None each where a file or the scenario is missing."""
    from .studies.at_call import case_readings, slab_crack_ratio

    got = case_readings(run_dir, case_id, scenario)
    return {"run_slab_crack_ratio": slab_crack_ratio(run_dir, case_id, scenario),
            **{key: got[src] for key, src in RUN_READINGS.items()}}


def add_model_readings(rec: dict, run_dir: str, scenario=None, params=None) -> None:
    """Give a finished field record ``rec`` what it lacks of :data:`MODEL_READINGS`: the run's from its files in
    ``run_dir`` (``scenario``: its scenario; None: the one its final checkpoint stores), the closed forms from
    ``params`` (the column as recorded; None: left as they are). Nothing is written: a record from before the
    readings gets them where it is scored. A run file or checkpoint that does not read back leaves the run's
    readings None and says why in ``readings_note`` (the case still counts; its missing readings take the training
    folds' medians)."""
    if rec.get("status") != "ok":
        return
    if any(k not in rec for k in ("run_slab_crack_ratio", *RUN_READINGS)):
        from .run_on import scenario_of

        try:
            got = run_readings(run_dir, rec["id"], scenario or scenario_of(run_dir, rec["id"]))
        except (OSError, KeyError, ValueError) as e:        # a damaged file: h5py's OSError, a missing dataset
            got = dict.fromkeys(("run_slab_crack_ratio", *RUN_READINGS))
            rec["readings_note"] = (f"the run's readings could not be read from {rec['id']}.h5 or .ckpt.h5 in "
                                    f"{run_dir}: {type(e).__name__}: {e}")
        rec.update(got)
    if params is not None and any(k not in rec for k in CLOSED_FORMS):
        rec.update(closed_form_readings(params))


def reading_row(row: dict) -> list[float]:
    """A case's :data:`MODEL_READINGS` in order, nan where one is missing or not finite (a run written before
    that reading existed)."""
    out = []
    for key in MODEL_READINGS:
        v = row.get(key)
        out.append(float(v) if isinstance(v, (int, float)) and math.isfinite(v) else math.nan)
    return out


def calibrated_forecast(readings, observed: list[str], groups: list[str], *, folds: int = 5, repeats: int = 20,
                        seed: int = 0) -> np.ndarray:
    """Out-of-fold P(END), P(SF), P(ARR) (n, 3) of each case from its model readings.

    Parameters
    ----------
    readings : array_like (n, len(MODEL_READINGS))
        Each case's :func:`reading_row` (nan: missing; it takes the training folds' median).
    observed : list of str
        The observers' classes (END, SF, ARR).
    groups : list of str
        Each case's pit: the folds never split one.
    folds, repeats, seed
        As :func:`~.information_bar.information_bar`.
    """
    from ..errors import InvalidArgument

    X = np.asarray(readings, dtype=float)
    n = len(observed)
    if X.shape != (n, len(MODEL_READINGS)) or len(groups) != n:
        raise InvalidArgument("readings", f"shape {X.shape} for {n} cases and {len(groups)} pits",
                              f"({n}, {len(MODEL_READINGS)}): {', '.join(MODEL_READINGS)}, one pit per case")
    if np.isnan(X).all(axis=0).any():
        missing = [k for k, gone in zip(MODEL_READINGS, np.isnan(X).all(axis=0), strict=True) if gone]
        raise InvalidArgument("readings", f"no case with {', '.join(missing)}", "each reading in one case at least")
    if fold_count(list(observed), list(groups), folds) < 2 or repeats < 1:
        raise InvalidArgument("folds, repeats, pits", (folds, repeats, len(set(groups))),
                              "folds >= 2, repeats >= 1, and cases from at least 2 pits with 2 of one class")
    return cross_validated(X, observed, groups, folds=folds, repeats=repeats, seed=seed)
