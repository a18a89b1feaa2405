"""What a field batch writes once its cases are done: ``cases.csv``, ``refused.csv``, ``scores.json``,
``confusion.png`` and ``calibration.json`` (the model's readings calibrated on all its scored cases, for another
batch to apply: :mod:`.calibration_file`); and the calibration a batch is given, read before anything runs."""

from __future__ import annotations

import csv
import os

from .calibrated import MODEL_READINGS
from .calibration_file import fit_calibration, read_calibration, write_calibration
from .case_run import write_case_record
from .information_bar import CASE_FEATURES
from .scoring import score_records

__all__ = ["CASE_COLUMNS", "write_results", "given_calibration"]

#: the columns of cases.csv
CASE_COLUMNS = ("id", "status", "pit", "test", "observed", "predicted", "p_end", "p_sf", "p_arr", "static_class",
                "static_peak_ratio", "recorded_cut", "runaway_cut", "slab_fracture_at", "slab_peak_stress_ratio",
                "slab_peak_body_stress_ratio", *CASE_FEATURES, *(k for k in MODEL_READINGS if k != "static_peak_ratio"),
                "w_f", "w_f_source", "setup", "particles", "steps", "threads", "workers", "wall_s", "run_file", "error",
                "readings_note")


def _write_tables(out_dir: str, recs: list, refused: list) -> None:
    with open(os.path.join(out_dir, "cases.csv"), "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, CASE_COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(recs)
    with open(os.path.join(out_dir, "refused.csv"), "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["pit", "test", "outcome", "reason", "message"])
        w.writerows([r.pit, r.test, r.outcome or "", r.reason, r.message] for r in refused)


def given_calibration(path: str | None, protocol=None) -> dict | None:
    """The calibration in ``path`` for a batch under ``protocol`` (default the field protocol; None without a
    path), or one line naming the file: read before the batch makes its folder."""
    from .protocol import FieldProtocol

    return None if path is None else read_calibration(path, (protocol or FieldProtocol()).validate().run_key())


def write_results(out_dir: str, recs: list, refused: list, proto, calibration: dict | None = None) -> dict:
    """Write the batch's files in ``out_dir`` (module docstring) and return its scores (``calibration``: one
    trained on another batch, scored beside the others)."""
    from .figures import plot_confusion

    _write_tables(out_dir, recs, refused)
    sc = score_records(recs, calibration=calibration)
    write_case_record(os.path.join(out_dir, "scores.json"), sc)
    plot_confusion(sc, os.path.join(out_dir, "confusion.png"))
    fitted = fit_calibration(recs, proto.run_key())
    if fitted is not None:
        write_calibration(os.path.join(out_dir, "calibration.json"), fitted)
    return sc
