"""Run every PST of real pits in bulk on Dask and score the outcomes against what the observers wrote.

:func:`run_field` takes folders of CAAML files and CSV tables of PSTs (:mod:`.table`), sets every record up
(:mod:`.cases`), runs the runnable ones by the field protocol (:mod:`.protocol`) as Dask tasks on a local
cluster or on a running scheduler, and writes to ``out_dir``::

    CASE.h5, CASE.json   each case's run and its record (status, observed and predicted class, the cuts)
    refused.csv          every record that could not be set up, one field-terms line each
    cases.csv            one row per case: observed against predicted, recorded cut against the runaway cut
    scores.json          confusion matrix, recall per class, balanced accuracy; the same for the baselines
    confusion.png        the confusion matrix

A batch killed at any point resumes where it stopped: a case whose JSON says "ok" and whose run file reads
back is not run again. A case that raises is recorded as failed with its error and never stops the others.
"""

from __future__ import annotations

import contextlib
import csv
import glob
import hashlib
import json
import os
import sys
import time
import traceback
import uuid
from dataclasses import dataclass

from .. import io
from ..errors import InvalidArgument
from .cases import FieldCase, FieldRefusal, field_case, field_cases
from .plain_words import in_field_terms
from .probability import outcome_probability
from .protocol import FieldProtocol, decided, protocol_params
from .scores import field_class
from .scoring import score_records
from .static_rule import weac_static_rule
from .table import table_profiles

__all__ = ["run_field", "run_cases", "gather", "score_records", "finished_records", "run_records", "case_digest",
           "case_scenario", "FieldBatch"]


@dataclass
class FieldBatch:
    """What :func:`run_field` returns: the case records, the refusals, the scores and the files written."""

    records: list
    refused: list
    scores: dict
    skipped: int
    out_dir: str


def gather(inputs, calibrate: bool = True) -> tuple[list[FieldCase], list[FieldRefusal]]:
    """The cases and refusals of every input: a folder of CAAML files (``*.xml``, ``*.caaml``), one CAAML file,
    or a CSV table of PSTs (:mod:`.table`). ``calibrate=False`` leaves the weak layer's calibration to the run
    (a selection from many records then calibrates only what it runs)."""
    cases, refused = [], []
    for path in inputs:
        path = os.fspath(path)
        if os.path.isdir(path):
            files = sorted(glob.glob(os.path.join(path, "*.xml")) + glob.glob(os.path.join(path, "*.caaml")))
        elif path.lower().endswith(".csv"):
            for row in table_profiles(path):
                if row.refusal is not None:
                    refused.append(FieldRefusal(os.path.basename(path), row.id, "table row", row.refusal))
                    continue
                r = field_case(row.profile, row.record, w_f=row.w_f, calibrate=calibrate)
                (cases if isinstance(r, FieldCase) else refused).append(r)
            continue
        elif os.path.isfile(path):
            files = [path]
        else:
            raise InvalidArgument("INPUT", path, "a folder of CAAML files, a CAAML file or a CSV table of PSTs")
        for f in files:
            for r in field_cases(f, calibrate=calibrate):
                (cases if isinstance(r, FieldCase) else refused).append(r)
    return cases, refused


def case_digest(case: FieldCase, proto: FieldProtocol) -> str:
    """The key of ``case`` run under ``proto``: 12 hex digits of a digest of its parameters and the protocol (the
    last part of its id; the same case set up again from its pit gets the same)."""
    key = {"case": case.params.to_dict(), "protocol": proto.run_key()}
    return hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()[:12]


#: what a case record says of the observer's column: the information bar's numbers (:mod:`.information_bar`)
CASE_FEATURES = ("slab_depth", "slab_density", "slope_deg", "column_length", "cut_share")


def case_record_features(case: FieldCase) -> dict:
    """The column's bed-normal slab depth (m), mean slab density (kg/m^3), slope (deg), column length (m) and
    recorded cut over column length (-): :data:`CASE_FEATURES`."""
    p = case.params
    slab = p.slab_stack()
    depth = sum(ly.thickness for ly in slab)
    return {"slab_depth": float(depth), "slab_density": sum(ly.thickness * ly.density for ly in slab) / depth,
            "slope_deg": float(p.slope_angle), "column_length": float(p.length),
            "cut_share": float(case.record.cut_length) / float(p.length)}


def _case_id(case: FieldCase, k: int, proto: FieldProtocol) -> str:
    stem = os.path.splitext(case.pit)[0].replace("#", "-").replace(" ", "_")
    return f"{stem}-{k}-{case_digest(case, proto)}"


def _write_json(path: str, obj: dict) -> None:
    io.write_record(path, obj, "a field case record", default=str)


def _finite(x):
    return x if isinstance(x, (int, float)) and x == x and abs(x) != float("inf") else None


def run_case(task: dict) -> dict:
    """One case in a worker (never raises: a failure is a record with its error)."""
    from ..runner import run

    t0 = time.perf_counter()
    out = os.path.join(task["out_dir"], task["id"])
    rec = {k: task[k] for k in ("id", "pit", "test", "observed", "recorded_cut", "static_class", "static_peak_ratio",
                                 "w_f", "w_f_source", "setup", *CASE_FEATURES)}
    rec["status"] = "failed"
    used = {}

    def until_decided(sim, frame):
        used["threads"] = sim.stepper.n_threads        # the threads the step really ran on
        return not decided(sim)

    try:
        res = run(task["scenario"], out + ".part.h5", device=task["device"], overwrite=True,
                  n_threads=task.get("threads"), callback=until_decided)
        o = res.scene_result.get("outcome", {})
        rec.update(status="ok", predicted=o.get("class") or "running", field_line=o.get("field_line"),
                   runaway_cut=_finite(res.scene_result.get("runaway_cut")),
                   slab_fracture_at=_finite(o.get("slab_fracture_at")), note=o.get("note", ""),
                   slab_peak_stress_ratio=_finite(o.get("slab_peak_stress_ratio")),
                   sim_time=res.sim_time, steps=res.steps, particles=res.n_particles, wall_s=res.wall_time,
                   threads=used.get("threads"), workers=task.get("workers"),
                   n_frames=io.read_run(out + ".part.h5").n_frames)
        prob = outcome_probability(rec["predicted"], rec["slab_peak_stress_ratio"])
        if prob is not None:
            rec["p_end"], rec["p_sf"], rec["p_arr"] = prob
        io.promote_part(out)
        rec["run_file"] = os.path.basename(out + ".h5")
    except Exception as e:      # a failing case is recorded with its error; it never stops the batch
        rec.update(status="failed", error=f"{type(e).__name__}: {e}", traceback=traceback.format_exc(limit=-4))
    rec["case_wall_s"] = time.perf_counter() - t0
    _write_json(out + ".json", rec)
    return rec


def _finished(task: dict) -> dict | None:
    return io.finished_record(os.path.join(task["out_dir"], task["id"]))


def finished_records(cases: list, out_dir: str, protocol: FieldProtocol | None = None) -> list[dict]:
    """The records of ``cases`` (in order; :func:`run_cases`'s list) whose runs in ``out_dir`` under ``protocol``
    (default :class:`~.protocol.FieldProtocol`) have finished: what a batch stopped early has measured, scored
    without running or building anything."""
    proto = protocol or FieldProtocol()
    recs = (_finished({"out_dir": out_dir, "id": _case_id(c, k, proto)}) for k, c in enumerate(cases))
    return [r for r in recs if r is not None]


def run_records(run_dirs) -> list[tuple[dict, str]]:
    """``(record, run_dir)`` of every case in the batches' runs folders ``run_dirs`` whose run finished with a
    prediction (``status`` ok), in file order: what the analyses of a batch read."""
    out = []
    for run_dir in run_dirs:
        for path in sorted(glob.glob(os.path.join(run_dir, "*.json"))):
            with open(path) as fh:
                r = json.load(fh)
            if r.get("status") == "ok" and "predicted" in r:
                out.append((r, run_dir))
    return out


def _static_cut(case: FieldCase) -> float | None:
    """weac's critical cut (m) of the case's column at its fracture energy; None when it is not critical or weac
    is not installed."""
    from ..scenes.pst.static import static_column
    from ..scenes.weac_reference import critical_cut, weac_unavailable

    if weac_unavailable() is not None:
        return None
    p = case.params
    return critical_cut(static_column(p), p.weak_layer.w_f)


def case_scenario(case: FieldCase, proto: FieldProtocol):
    """The scenario a batch runs for ``case`` under ``proto`` and its setup note: ``(scenario, note)``, or
    ``(None, reason)`` where the column exceeds the per-case budget. Building it calibrates the weak layer; an
    InvalidArgument says what the model cannot represent."""
    from ..scenes.pst import build

    params, tc, note = protocol_params(case.params, proto, _static_cut(case) if proto.pre_cut_share > 0.0 else None)
    return (None, note) if params is None else (build(params, tc, name="field"), note)


def _tasks(cases, out_dir, proto, device, refused) -> list[dict]:
    tasks = []
    for k, c in enumerate(cases):
        try:
            scenario, note = case_scenario(c, proto)
            if scenario is None:
                refused.append(FieldRefusal(c.pit, c.test, "budget", note, c.outcome))
                continue
            params = scenario.scene
        except InvalidArgument as e:
            refused.append(FieldRefusal(c.pit, c.test, *in_field_terms(e, c.params), c.outcome))
            continue
        wf = c.fracture_energy
        static = weac_static_rule(c.params)
        tasks.append({"id": _case_id(c, k, proto), "pit": c.pit, "test": c.test, "observed": field_class(c.outcome),
                      "recorded_cut": c.record.cut_length, **case_record_features(c),
                      "static_class": static["class"], "static_peak_ratio": static["peak_ratio"],
                      "w_f": params.weak_layer.w_f, "w_f_source": "read back" if wf.value is not None else wf.reason,
                      "setup": note, "scenario": scenario, "out_dir": out_dir,
                      "device": device, "threads": proto.threads})
    return tasks


def _execute(todo, records, workers, scheduler, stream, total, threads=1) -> None:
    from distributed import Client, LocalCluster, as_completed

    with contextlib.ExitStack() as stack:
        if scheduler:
            client = stack.enter_context(Client(scheduler))
        else:
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers or max(1, (os.cpu_count() or 1) // threads), threads_per_worker=1, processes=True,
                dashboard_address=None, silence_logs=40, env={"MPM_WARP_THREADS": str(threads)}))
            client = stack.enter_context(Client(cluster))
        n_workers = len(client.scheduler_info().get("workers", {})) or None
        todo = [{**t, "workers": n_workers} for t in todo]    # each record says how many cases ran beside it
        token, t0, done = uuid.uuid4().hex[:8], time.perf_counter(), 0
        futures = {client.submit(run_case, t, key=f"{t['id']}-{token}", retries=1, pure=False, priority=-i): t
                   for i, t in enumerate(todo)}
        for fut in as_completed(list(futures)):
            task = futures[fut]
            try:
                rec = fut.result()
            except Exception as e:   # the worker died too often, or the cluster is gone
                rec = {"id": task["id"], "status": "failed", "error": f"{type(e).__name__}: {e}"}
                _write_json(os.path.join(task["out_dir"], task["id"] + ".json"), rec)
            fut.release()
            records[task["id"]] = rec
            done += 1
            if stream is not None:
                el = time.perf_counter() - t0
                stream.write(f"\rfield: {total - len(todo) + done}/{total} cases, elapsed {el:.0f} s, "
                             f"ETA {el / done * (len(todo) - done):.0f} s ")
                stream.flush()
        if stream is not None:
            stream.write("\n")


def run_field(inputs, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
              device: str | None = "cpu", protocol: FieldProtocol | None = None, limit: int | None = None,
              progress=True) -> FieldBatch:
    """Set up, run and score every PST record of ``inputs`` (module docstring).

    Parameters
    ----------
    inputs : list of str
        Folders of CAAML files, CAAML files, CSV tables of PSTs.
    out_dir : str
        Folder of the runs and the results (created; an earlier batch's finished cases are kept and not rerun).
    workers : int, optional
        Worker processes of the local cluster (default: the cores over the protocol's ``threads``); ignored with
        ``scheduler``.
    scheduler : str, optional
        Address of a running Dask scheduler (mpm_warp installed on its workers; ``out_dir`` visible to them).
    device : str, optional
        Warp device of every run (default the CPU).
    protocol : FieldProtocol, optional
        The per-case budget and the saw (default :class:`~.protocol.FieldProtocol`).
    limit : int, optional
        Run only the first ``limit`` runnable cases (in input order).
    progress : bool or text stream
        One progress line on stderr (True), on the given stream, or none.
    """
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int) or limit < 1):
        raise InvalidArgument("limit", limit, "an integer >= 1")
    cases, refused = gather(inputs)
    return run_cases(cases[:limit] if limit is not None else cases, refused, out_dir, workers=workers,
                     scheduler=scheduler, device=device, protocol=protocol, progress=progress)


def run_cases(cases: list, refused: list, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
              device: str | None = "cpu", protocol: FieldProtocol | None = None, progress=True) -> FieldBatch:
    """Run the field cases ``cases`` (:func:`gather`'s, or a selection of them) and score them, as :func:`run_field`;
    ``refused`` (their refusals) goes to ``refused.csv``."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InvalidArgument("workers", workers, "an integer >= 1")
    proto = (protocol or FieldProtocol()).validate()
    refused = list(refused)
    os.makedirs(out_dir, exist_ok=True)
    tasks = _tasks(cases, out_dir, proto, device, refused)
    records = {t["id"]: _finished(t) for t in tasks}
    todo = [t for t in tasks if records[t["id"]] is None]
    stream = sys.stderr if progress is True else (progress or None)
    if todo:
        _execute(todo, records, workers, scheduler, stream, len(tasks), proto.threads)
    recs = [records[t["id"]] for t in tasks]
    _write_outputs(out_dir, recs, refused)
    sc = score_records(recs)
    _write_json(os.path.join(out_dir, "scores.json"), sc)
    from .figures import plot_confusion

    plot_confusion(sc, os.path.join(out_dir, "confusion.png"))
    return FieldBatch(recs, refused, sc, len(tasks) - len(todo), out_dir)


#: the columns of cases.csv
CASE_COLUMNS = ("id", "status", "pit", "test", "observed", "predicted", "p_end", "p_sf", "p_arr", "static_class",
                "static_peak_ratio", "recorded_cut", "runaway_cut", "slab_fracture_at", "slab_peak_stress_ratio",
                *CASE_FEATURES, "w_f", "w_f_source", "setup", "particles", "steps", "threads", "workers", "wall_s",
                "run_file", "error")


def _write_outputs(out_dir: str, recs: list, refused: list) -> None:
    with open(os.path.join(out_dir, "cases.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, CASE_COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(recs)
    with open(os.path.join(out_dir, "refused.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["pit", "test", "outcome", "reason", "message"])
        w.writerows([r.pit, r.test, r.outcome or "", r.reason, r.message] for r in refused)
