"""Running field cases in a worker: one case alone (:func:`run_case`), or a group stepped together
(:func:`run_case_group`, :mod:`mpm_warp.column_batch`); each case ends as a record and a run file.

A case's record is the same either way (status, predicted class, cuts, probabilities, cost); a case of a group
also says how many columns shared its step (``columns``) and what the shared step cost it (``shared_step_cost``:
its own elastic step over the group's, 1 for the column that sets it). A case that fails is a record with its
error; it never stops the others.
"""

from __future__ import annotations

import os
import time
import traceback

from .. import io
from .calibrated import CLOSED_FORMS, add_model_readings
from .information_bar import CASE_FEATURES
from .probability import record_probabilities
from .protocol import decided, run_to_decision

__all__ = ["run_case", "run_case_group", "write_case_record", "column_step"]

#: the task's fields every record carries
_TASK_FIELDS = ("id", "pit", "test", "observed", "recorded_cut", "static_class", "static_peak_ratio", "w_f",
                "w_f_source", "setup", *CASE_FEATURES, *CLOSED_FORMS)


def write_case_record(path: str, obj: dict) -> None:
    """Write a case's record ``obj`` (JSON) to ``path`` as the batch reads it back."""
    io.write_record(path, obj, "a field case record", default=str)


def column_step(scenario) -> float:
    """The column's own elastic step at rest, ``cfl dx / c_p`` (s): what it steps with alone."""
    from ..time_step import first_step

    s = scenario.validate()
    return first_step(s.time, s.domain.dx, s.materials, s.blocks)[0]


def _finite(x):
    return x if isinstance(x, (int, float)) and x == x and abs(x) != float("inf") else None


def _new_record(task: dict) -> dict:
    rec = {k: task[k] for k in _TASK_FIELDS}
    rec["status"] = "failed"
    return rec


def _finish(rec: dict, task: dict, res, threads) -> None:
    """Fill ``rec`` from the run's result ``res`` and promote the case's run file (raises on a damaged one)."""
    out = os.path.join(task["out_dir"], task["id"])
    o = res.scene_result.get("outcome", {})
    rec.update(status="ok", predicted=o.get("class") or "running", field_line=o.get("field_line"),
               runaway_cut=_finite(res.scene_result.get("runaway_cut")),
               slab_fracture_at=_finite(o.get("slab_fracture_at")), note=o.get("note", ""),
               slab_peak_stress_ratio=_finite(o.get("slab_peak_stress_ratio")),
               slab_peak_body_stress_ratio=_finite(o.get("slab_peak_body_stress_ratio")),
               sim_time=res.sim_time, steps=res.steps, particles=res.n_particles, wall_s=res.wall_time,
               threads=threads, workers=task.get("workers"), n_frames=io.read_run(out + ".part.h5").n_frames)
    record_probabilities(rec)
    io.promote_part(out)
    rec["run_file"] = os.path.basename(out + ".h5")
    add_model_readings(rec, task["out_dir"], task["scenario"])


def _failed(rec: dict, e: BaseException) -> None:
    rec.update(status="failed", error=f"{type(e).__name__}: {e}",
               traceback="".join(traceback.format_exception(type(e), e, e.__traceback__, limit=-4)))


def run_case(task: dict) -> dict:
    """One case in a worker (never raises: a failure is a record with its error)."""
    t0 = time.perf_counter()
    out = os.path.join(task["out_dir"], task["id"])
    rec = _new_record(task)
    try:
        res, threads = run_to_decision(task["scenario"], out + ".part.h5", device=task["device"],
                                       n_threads=task.get("threads"))
        _finish(rec, task, res, threads)
    except Exception as e:      # a failing case is recorded with its error; it never stops the batch
        _failed(rec, e)
    rec["case_wall_s"] = time.perf_counter() - t0
    write_case_record(out + ".json", rec)
    return rec


def run_case_group(tasks: list[dict]) -> list[dict]:
    """The cases ``tasks`` (on one device) stepped together, each on one thread, until each is decided; their
    records in order (never raises). ``case_wall_s`` is the group's wall time shared by particles."""
    from ..column_batch import run_columns
    from ..runner import simulation_for

    t0 = time.perf_counter()
    recs = [_new_record(t) for t in tasks]
    outs = [os.path.join(t["out_dir"], t["id"]) for t in tasks]
    sims, members = [], []
    for k, t in enumerate(tasks):
        try:
            sims.append(simulation_for(t["scenario"], t["device"], 1))
            members.append(k)
        except Exception as e:     # a case that cannot be built fails alone
            _failed(recs[k], e)
    if sims:
        own = [column_step(tasks[k]["scenario"]) for k in members]
        try:
            results = run_columns(sims, [outs[k] + ".part.h5" for k in members],
                                  lambda j, sim, frame: not decided(sim), overwrite=True)
        except Exception as e:     # the group could not start (a run file it may not write): each case says so
            results = [e] * len(sims)
        for j, (k, res) in enumerate(zip(members, results, strict=True)):
            recs[k]["columns"], recs[k]["shared_step_cost"] = len(sims), own[j] / min(own)
            try:
                if isinstance(res, BaseException):
                    raise res
                _finish(recs[k], tasks[k], res, 1)
            except Exception as e:
                _failed(recs[k], e)
    wall = time.perf_counter() - t0
    total = sum(r.get("particles") or 0 for r in recs) or 1
    for k, rec in enumerate(recs):
        rec["case_wall_s"] = wall * (rec.get("particles") or 0) / total
        write_case_record(outs[k] + ".json", rec)
    return recs
