"""Run every PST of real pits in bulk on Dask and score the outcomes against what the observers wrote.

:func:`run_field` takes folders of CAAML files and CSV tables of PSTs (:mod:`.table`), sets every record up
(:mod:`.cases`), runs the runnable ones by the field protocol (:mod:`.protocol`) as Dask tasks on a local
cluster or on a running scheduler, and writes to ``out_dir``::

    CASE.h5, CASE.json   each case's run and its record (status, observed and predicted class, the cuts)
    refused.csv          every record that could not be set up, one field-terms line each
    cases.csv            one row per case: observed against predicted, recorded cut against the runaway cut
    scores.json          confusion matrix, recall per class, balanced accuracy; the same for the baselines
    confusion.png        the confusion matrix
    dask.log             Dask's own logs (unless verbose: then on the terminal)

The inputs are set up lazily (:mod:`.batch_setup`) and each runnable case is submitted once set up, so a large
table's first case starts at once; a batch with a ``limit`` sets up rows only until it has that many.

A batch killed at any point resumes where it stopped: a case whose JSON says "ok" and whose run file reads
back is not run again. A case that raises is recorded as failed with its error and never stops the others.
"""

from __future__ import annotations

import contextlib
import glob
import hashlib
import itertools
import json
import os
import re
import sys
import uuid
from dataclasses import dataclass

from .. import io
from ..errors import InvalidArgument
from ..scenes.pst.params import CRACK_BAND_CELLS
from .batch_outputs import given_calibration, write_results
from .batch_setup import Progress, check_out_dir, check_scheduler, dask_client, dask_log, iter_gather
from .calibrated import CLOSED_FORMS, add_model_readings, closed_form_readings
from .case_run import column_step, run_case, run_case_group, write_case_record
from .cases import FieldCase, FieldRefusal
from .information_bar import case_record_features
from .plain_words import in_field_terms
from .protocol import FieldProtocol, protocol_equivalent, protocol_params
from .scores import field_class
from .scoring import score_records
from .static_view import static_view

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


def gather(inputs, calibrate: bool = True, limit: int | None = None) -> tuple[list[FieldCase], list[FieldRefusal]]:
    """The cases and refusals of every input: a folder of CAAML files (``*.xml``, ``*.caaml``, any case), one
    CAAML file, or a CSV table of PSTs (:mod:`.table`). ``calibrate=False`` leaves the weak layer's calibration to
    the run (a selection from many records then calibrates only what it runs). With ``limit``, the inputs are set
    up only until ``limit`` cases are found (the refusals met on the way are kept)."""
    cases, refused = [], []
    for r in iter_gather(inputs, calibrate=calibrate):
        (cases if isinstance(r, FieldCase) else refused).append(r)
        if limit is not None and len(cases) >= limit:
            break
    return cases, refused


def case_digest(case: FieldCase, proto: FieldProtocol) -> str:
    """The key of ``case`` run under ``proto``: 12 hex digits of a digest of its parameters and the protocol (the
    last part of its id; the same case set up again from its pit gets the same). The slab's crack band width in
    grid cells enters too, now that it is no longer the half cell the first batches ran with (docs/model.md §9):
    a case run with the old band is not reused as one of today's. A case run with an equivalent weak layer
    (:func:`~.protocol.protocol_equivalent`) has it in its key."""
    key = {"case": case.params.to_dict(), "protocol": proto.run_key()}
    if CRACK_BAND_CELLS != 0.5:
        key["crack_band_cells"] = CRACK_BAND_CELLS
    eq = protocol_equivalent(case.params, proto)
    if eq is not None and not isinstance(eq, str):
        key["equivalent_layer"] = eq.key()
    return hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()[:12]


#: what a case's file name may not hold (a separator above all)
_UNSAFE = re.compile(r"[^\w.-]")


def _case_id(case: FieldCase, k: int, proto: FieldProtocol) -> str:
    """The case's file name in ``--out``: its pit's name (any character but letters, digits, ``.``, ``_`` and
    ``-`` replaced, so that an id ``a/b`` or ``../..`` stays a file inside the folder), its position, its key."""
    stem = os.path.splitext(case.pit)[0].replace("#", "-").replace(" ", "_")
    return f"{_UNSAFE.sub('_', stem)}-{k}-{case_digest(case, proto)}"


def _write_json(path: str, obj: dict) -> None:
    write_case_record(path, obj)


def _finished(task: dict, claimed: set | None = None) -> dict | None:
    """The task's record from an earlier batch when it finished; None (run it again) where its file says otherwise,
    whatever it holds (``[]``, a truncated file).

    A batch of another selection (the measured-density columns with the stratified draw, or without) numbers the
    same case differently: where the task's own file has no finished run, a finished run of the same pit and key
    under another position is taken, each at most once in a batch (``claimed``: the ids taken so far), so that two
    identical records of one pit stay two cases."""
    claimed = set() if claimed is None else claimed
    own = task["id"]
    stem, _, digest = own.rsplit("-", 2)
    pattern = os.path.join(glob.escape(task["out_dir"]), f"{glob.escape(stem)}-*-{digest}.json")
    candidates = [own] + sorted(os.path.basename(p)[:-5] for p in glob.glob(pattern))
    for cid in candidates:
        if cid in claimed or cid.rsplit("-", 2)[0] != stem:
            continue
        rec = io.finished_record(os.path.join(task["out_dir"], cid))
        if rec is not None:
            claimed.add(cid)
            return rec
    return None


def finished_records(cases: list, out_dir: str, protocol: FieldProtocol | None = None,
                     missing: list | None = None) -> list[dict]:
    """The records of ``cases`` (in order; :func:`run_cases`'s list) whose runs in ``out_dir`` under ``protocol``
    (default :class:`~.protocol.FieldProtocol`) have finished: what a batch stopped early has measured, scored
    without running or building anything; each with the model's readings (:func:`~.calibrated.add_model_readings`)
    from its files and its case. The cases without a finished run go to ``missing`` where it is given."""
    proto, claimed, out = protocol or FieldProtocol(), set(), []
    for k, c in enumerate(cases):
        rec = _finished({"out_dir": out_dir, "id": _case_id(c, k, proto)}, claimed)
        if rec is None:
            if missing is not None:
                missing.append(c)
            continue
        add_model_readings(rec, out_dir, params=c.params)
        out.append(rec)
    return out


def run_records(run_dirs) -> list[tuple[dict, str]]:
    """``(record, run_dir)`` of every case in the batches' runs folders ``run_dirs`` whose run finished with a
    prediction (``status`` ok), in file order: what the analyses of a batch read."""
    out = []
    for run_dir in run_dirs:
        for path in sorted(glob.glob(os.path.join(run_dir, "*.json"))):
            with open(path) as fh:
                r = json.load(fh)
            if isinstance(r, dict) and r.get("status") == "ok" and "predicted" in r:
                out.append((r, run_dir))
    return out


def case_scenario(case: FieldCase, proto: FieldProtocol):
    """The scenario a batch runs for ``case`` under ``proto`` and its setup note: ``(scenario, note)``, or
    ``(None, reason)`` where the column exceeds the per-case budget. Building it calibrates the weak layer; an
    InvalidArgument says what the model cannot represent."""
    from ..scenes.pst import build

    params, tc, note = protocol_params(case.params, proto,
                                       static_view(case.params).critical_cut if proto.pre_cut_share > 0.0 else None)
    return (None, note) if params is None else (build(params, tc, name="field"), note)


def _task(c: FieldCase, k: int, out_dir, proto, device, refused) -> dict | None:
    """The task of the ``k``-th case ``c``, or None with its refusal added to ``refused``."""
    try:
        scenario, note = case_scenario(c, proto)
        if scenario is None:
            refused.append(FieldRefusal(c.pit, c.test, "budget", note, c.outcome))
            return None
        params = scenario.scene
    except InvalidArgument as e:
        refused.append(FieldRefusal(c.pit, c.test, *in_field_terms(e, c.params), c.outcome))
        return None
    wf = c.fracture_energy
    source = "given" if wf.reason == "given" else ("read back" if wf.value is not None else wf.reason)
    static = static_view(c.params)
    return {"id": _case_id(c, k, proto), "pit": c.pit, "test": c.test, "observed": field_class(c.outcome),
            "recorded_cut": c.record.cut_length, **case_record_features(c), **closed_form_readings(c.params),
            "static_class": static.static_class,
            "static_peak_ratio": static.peak_ratio, "w_f": params.weak_layer.w_f, "w_f_source": source,
            "setup": note, "scenario": scenario, "out_dir": out_dir, "device": device, "threads": proto.threads}


def _tasks(cases, out_dir, proto, device, refused) -> list[dict]:
    tasks = (_task(c, k, out_dir, proto, device, refused) for k, c in enumerate(cases))
    return [t for t in tasks if t is not None]


def _execute(todo, records, workers, scheduler, progress: Progress, threads=1, out_dir=".", verbose=False,
             columns: int = 1) -> None:
    """Run the tasks of the iterator ``todo`` as they come (each submitted once set up, so the first case starts
    while the later rows are set up) and put their records in ``records``; no cluster where there is none. With
    ``columns`` > 1 the tasks go in groups of that many columns stepped together (:func:`column_groups`)."""
    from distributed import as_completed

    first = next(todo, None)
    if first is None:
        return
    groups = column_groups(itertools.chain([first], todo), columns) if columns > 1 else ([t] for t in
                                                                                        itertools.chain([first], todo))
    with contextlib.ExitStack() as stack:
        terminal = stack.enter_context(dask_log(out_dir, verbose))
        if progress.stream is sys.stderr:
            progress.stream = terminal
        client = dask_client(stack, scheduler, workers, threads, verbose)
        n_workers = len(client.scheduler_info().get("workers", {})) or None
        token, futures, running = uuid.uuid4().hex[:8], {}, as_completed()

        def collect(fut):
            group = futures.pop(fut)
            try:
                recs = fut.result()
                recs = recs if isinstance(recs, list) else [recs]
            except Exception as e:   # the worker died too often, or the cluster is gone
                recs = [{"id": t["id"], "status": "failed", "error": f"{type(e).__name__}: {e}"} for t in group]
                for t, rec in zip(group, recs, strict=True):
                    _write_json(os.path.join(t["out_dir"], t["id"] + ".json"), rec)
            fut.release()
            for rec in recs:
                records[rec["id"]] = rec
                progress.done += 1
            progress.show()

        for i, group in enumerate(groups):
            group = [{**t, "workers": n_workers} for t in group]    # each record says how many cases ran beside it
            run, arg = (run_case, group[0]) if columns == 1 else (run_case_group, group)
            fut = client.submit(run, arg, key=f"{group[0]['id']}-{token}", retries=1, pure=False, priority=-i)
            futures[fut] = group
            running.add(fut)
            while running.has_ready():
                collect(next(running))
        progress.setting_up = False
        for fut in running:
            collect(fut)
        progress.stream = sys.stderr if progress.stream is terminal else progress.stream


def column_groups(tasks, columns: int, window: int = 4):
    """Groups of up to ``columns`` tasks from the iterator ``tasks``, for columns stepped together: each
    ``window`` groups' worth of tasks is sorted by the column's own elastic step (:func:`column_step`), so that
    a group's columns step at similar sizes and the shared step costs the others little."""
    batch = list(itertools.islice(tasks, columns * window))
    while batch:
        batch.sort(key=lambda t: column_step(t["scenario"]))
        for k in range(0, len(batch), columns):
            yield batch[k:k + columns]
        batch = list(itertools.islice(tasks, columns * window))


def run_field(inputs, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
              device: str | None = "cpu", protocol: FieldProtocol | None = None, limit: int | None = None,
              progress=True, verbose: bool = False, calibration: str | None = None) -> FieldBatch:
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
        Run only the first ``limit`` runnable cases (in input order): the inputs are set up only until that many
        are found, and a refused record does not count.
    progress : bool or text stream
        One progress line on stderr (True), on the given stream, or none.
    verbose : bool
        Dask's logs on the terminal; else in ``dask.log`` in ``out_dir``.
    calibration : str, optional
        A ``calibration.json`` another batch under the same protocol wrote: its calibrated forecast is scored on
        these cases too (:mod:`.calibration_file`; read before anything runs).
    """
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int) or limit < 1):
        raise InvalidArgument("limit", limit, "an integer >= 1")
    cal = given_calibration(calibration, protocol)
    proto = _checked(workers, scheduler, protocol, out_dir, device)
    items, refused, shown = iter_gather(inputs), [], Progress(_stream(progress))

    def setup():
        cases = runnable = 0
        for item in items:
            shown.records += 1
            if isinstance(item, FieldCase):
                task = _task(item, cases, out_dir, proto, device, refused)
                cases += 1
                if task is not None:
                    yield task
                    runnable += 1
                    if limit is not None and runnable >= limit:
                        return
            else:
                refused.append(item)
            shown.refused = len(refused)
            shown.show()

    return _run_tasks(setup(), refused, out_dir, proto, workers, scheduler, shown, verbose, cal)


def _checked(workers, scheduler, protocol, out_dir, device=None) -> FieldProtocol:
    """The batch's protocol, once its arguments, its device (here, unless the cases go to a running scheduler,
    whose workers may have devices this machine has not) and its folder are checked (before anything is set
    up)."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InvalidArgument("workers", workers, "an integer >= 1")
    proto = (protocol or FieldProtocol()).validate()
    check_scheduler(scheduler)
    if scheduler is None and device is not None:
        from ..device import resolve_device

        resolve_device(device)
    check_out_dir(out_dir)
    return proto


def _stream(progress):
    return sys.stderr if progress is True else (progress or None)


def run_cases(cases: list, refused: list, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
              device: str | None = "cpu", protocol: FieldProtocol | None = None, progress=True,
              verbose: bool = False, calibration: str | None = None) -> FieldBatch:
    """Run the field cases ``cases`` (:func:`gather`'s, or a selection of them) and score them, as :func:`run_field`;
    ``refused`` (their refusals) goes to ``refused.csv``."""
    cal = given_calibration(calibration, protocol)
    proto = _checked(workers, scheduler, protocol, out_dir, device)
    refused, shown = list(refused), Progress(_stream(progress))

    def setup():
        for k, c in enumerate(cases):
            shown.records += 1
            task = _task(c, k, out_dir, proto, device, refused)
            if task is not None:
                yield task

    return _run_tasks(setup(), refused, out_dir, proto, workers, scheduler, shown, verbose, cal)


def _run_tasks(tasks, refused, out_dir, proto, workers, scheduler, progress: Progress, verbose,
               calibration=None) -> FieldBatch:
    """Run the tasks of the iterator ``tasks`` not finished in ``out_dir`` before, as they are set up; write the
    records, the refusals and the scores."""
    done, ran, records, claimed = [], [], {}, set()

    def todo():
        for t in tasks:
            done.append(t)
            progress.tasks = len(done)
            progress.refused = len(refused)
            records[t["id"]] = rec = _finished(t, claimed)
            if rec is None:
                ran.append(t)
                yield t
            else:                               # a record from before the model's readings gets them here
                add_model_readings(rec, out_dir, t["scenario"])
                rec.update({k: t[k] for k in CLOSED_FORMS if k not in rec})
                progress.done += 1
            progress.show()

    _execute(todo(), records, workers, scheduler, progress, proto.threads, out_dir, verbose, proto.columns)
    progress.refused = len(refused)
    progress.end()
    recs = [records[t["id"]] for t in done]
    sc = write_results(out_dir, recs, refused, proto, calibration)
    return FieldBatch(recs, refused, sc, len(done) - len(ran), out_dir)
