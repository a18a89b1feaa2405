"""Parameter sweeps on a Dask cluster: one run per case, resumable, with a summary table and figure.

A sweep is the cartesian product of ``vary`` lists (``--vary KEY=V1,V2,...``), crossed with the
rows of a ``cases`` CSV file if one is given, of scenario overrides: dotted keys as accepted by
:func:`mpm_warp.loader.apply_overrides` (``time.end``, ``materials.snow.E``, ``blocks.0.lo``);
a key whose first part is not a scenario section but a key of its ``[scene]`` table is read as
``scene.KEY`` (``slope_angle`` -> ``scene.slope_angle``). Each case is one :func:`mpm_warp.run`,
executed as a Dask task: by default on an embedded ``LocalCluster`` (one worker process per GPU,
or per CPU core on a machine without one, one thread each, ``MPM_WARP_THREADS=1``), or on an
existing cluster given by its scheduler address (mpm_warp installed on its workers; one worker per
GPU, e.g. with ``CUDA_VISIBLE_DEVICES``). ``out_dir`` must be visible to every worker at one path.

Files in ``out_dir`` (``ID = <scenario name>-<16 hex digits of the SHA-256 of the effective
scenario>``, i.e. of the file's content with the case's overrides applied)::

    ID.h5        the run (see mpm_warp.io)        ID.ckpt.h5   its last checkpoint
    ID.json      parameters, overrides, RunResult fields, scene_result, last-frame scalars, status, error
    summary.csv  one row per case, in case order  summary.png  a result against a parameter

Faults: a run that raises is caught inside its task and comes back as a record with status
``"failed"`` and the error; it never stops the others. A worker process that dies (crash,
``os._exit``, out of memory) has its task rescheduled on another worker by the scheduler
(``distributed.scheduler.allowed-failures`` deaths, plus ``retries``); past that the case is
recorded as failed with the ``KilledWorker`` error. Every file is written under a temporary name
and moved in place (``os.replace``): ``ID.part.h5`` becomes ``ID.h5`` once complete, then
``ID.json`` is written. Running the same sweep again skips every case whose JSON says ``"ok"`` and
whose HDF5 file reads back with the recorded frame count, and runs the rest, so a sweep killed at
any point loses no finished run.
"""

from __future__ import annotations

import contextlib
import csv
import datetime
import functools
import hashlib
import itertools
import json
import os
import re
import stat
import sys
import time
import traceback
import uuid
from dataclasses import dataclass

from . import io
from .errors import InvalidArgument, MPMError
from .loader import TOP_LEVEL_KEYS, apply_overrides, read_scenario_dict, scenario_from_dict, split_override
from .sweep_summary import RESULT_FIELDS, jsonable, number, plot_summary, summary_row, write_summary

__all__ = ["SweepResult", "run_sweep", "expand_cases", "read_cases", "parse_vary", "split_values",
           "default_workers", "plot_summary"]



@dataclass
class SweepResult:
    """What :func:`run_sweep` returns.

    Attributes
    ----------
    rows : list of dict
        One summary row per case, in case order (the rows of ``path``).
    path : str
        The summary CSV file.
    figure : str or None
        The PNG figure (None if nothing could be plotted).
    skipped : int
        Cases found finished by an earlier sweep and not run again.
    """

    rows: list
    path: str
    figure: str | None
    skipped: int

    @property
    def failed(self) -> list:
        """Rows of the failed cases."""
        return [r for r in self.rows if r["status"] != "ok"]


# ------------------------------------------------------------------------------------------ cases
_VALUE = re.compile(r"""(?:\[[^\]]*\]|\{[^}]*\}|"[^"]*"|'[^']*'|[^,\[{"'])+""")


def split_values(text: str) -> list[str]:
    """Split ``"0,10,[1, 2],'a,b'"`` at the commas outside (unnested) brackets and quotes."""
    return [v.strip() for v in _VALUE.findall(text) if v.strip()]


def parse_vary(items) -> dict:
    """``["slope_deg=0,10", "time.cfl=0.3,0.4"]`` -> ``{"slope_deg": ["0", "10"], "time.cfl": [...]}``."""
    vary = {}
    for item in items or ():
        key, sep, values = item.partition("=")
        if not sep or not key.strip() or not split_values(values):
            raise InvalidArgument("--vary", item, "KEY=V1,V2,... with at least one value")
        vary[key.strip()] = split_values(values)
    return vary


def read_cases(path) -> list[dict]:
    """Cases from a CSV file: a header of override keys, one case per row; an empty cell is no override.

    The file must be a regular UTF-8 file with a header of distinct, non-empty keys, at least one case
    and, in every row, one value per column (blank lines are skipped); otherwise
    :class:`InvalidArgument` names the row.
    """
    path = os.fspath(path)
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise InvalidArgument("cases", path, "a regular CSV file (not a folder, FIFO, device or socket)")
        with open(path, newline="", encoding="utf-8") as fh:
            rows = [(i, r) for i, r in enumerate(csv.reader(fh), start=1) if any(c.strip() for c in r)]
    except UnicodeDecodeError as e:
        raise InvalidArgument("cases", path, f"a UTF-8 CSV file (byte {e.start} is not UTF-8)") from None
    except csv.Error as e:
        raise InvalidArgument("cases", path, f"a CSV file ({e})") from None
    except OSError as e:
        raise InvalidArgument("cases", path, f"a readable CSV file ({e.strerror})") from None
    if len(rows) < 2:
        raise InvalidArgument("cases", path, "a CSV file with a header of override keys and at least one case row "
                              f"(it has {'a header only' if rows else 'nothing'})")
    header = [h.strip() for h in rows[0][1]]
    if not all(header) or len(set(header)) < len(header):
        raise InvalidArgument(f"cases header (line {rows[0][0]} of {path})", header, "distinct, non-empty override "
                              "keys, e.g. scene.slope_angle,time.end")
    for line, r in rows[1:]:
        if len(r) != len(header):
            raise InvalidArgument(f"cases row (line {line} of {path})", r, f"{len(header)} values, one per column of "
                                  f"the header {header} (an empty cell is no override); it has {len(r)}")
    return [{k: v.strip() for k, v in zip(header, r, strict=True) if v.strip()} for _, r in rows[1:]]


def expand_cases(vary: dict | None = None, cases=None) -> list[dict]:
    """The cases of a sweep: each of ``cases`` (dicts, or a CSV path) crossed with the product of ``vary``.

    Parameters
    ----------
    vary : dict of str -> list or str
        Override key -> values (a list, or a comma-separated string).
    cases : list of dict, str or None
        Explicit cases; a str or path is read with :func:`read_cases`.
    """
    base = read_cases(cases) if isinstance(cases, (str, os.PathLike)) else [dict(c) for c in (cases or [{}])]
    keys = list(vary or {})
    lists = [split_values(v) if isinstance(v, str) else list(v) for v in (vary or {}).values()]
    return [{**c, **dict(zip(keys, combo, strict=True))} for c in base for combo in itertools.product(*lists)]


def _parse(value):
    """A value as :func:`apply_overrides` reads it: TOML literal, else the bare string."""
    return apply_overrides({}, {"v": value})["v"]


def _full_key(raw: dict, key: str) -> str:
    head = key.split(".")[0]
    if head not in TOP_LEVEL_KEYS and isinstance(raw.get("scene"), dict) and head in raw["scene"]:
        return "scene." + key
    return key


def _tasks(raw, source, cases, fixed, out_dir, device, runner) -> list[dict]:
    """One task per distinct case, named by the hash of its effective scenario."""
    tasks, seen = [], set()
    for case in cases:
        params = {k: _parse(v) for k, v in case.items()}
        overrides = [*fixed, *((_full_key(raw, k), v) for k, v in params.items())]
        try:
            blob = apply_overrides(raw, dict(overrides))
        except MPMError:                          # reported by the task itself
            blob = {"scenario": raw, "overrides": overrides}
        digest = hashlib.sha256(json.dumps(blob, sort_keys=True, default=str).encode()).hexdigest()[:16]
        rid = f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', str(raw.get('name', 'run')))}-{digest}"
        if rid not in seen:
            seen.add(rid)
            tasks.append(dict(id=rid, params=params, overrides=overrides, raw=raw, source=source,
                              out_dir=os.path.abspath(out_dir), device=device, runner=runner))
    return tasks


# ------------------------------------------------------------------------------------- one run
def _record(task: dict, status: str, error: str | None = None) -> dict:
    return {"id": task["id"], "status": status, "error": error, "params": task["params"],
            "overrides": [f"{k}={v}" for k, v in task["overrides"]], "scenario": task["source"],
            "output": task["id"] + ".h5", "result": {}, "scene_result": {}, "final": {}, "n_frames": 0, "worker": None,
            "finished": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def _write_json(path: str, obj: dict) -> None:
    io.write_record(path, obj, "a sweep record", default=jsonable)


def _n_gpus() -> int:
    import warp as wp

    from .device import init_warp

    init_warp()
    return wp.get_cuda_device_count()


def _worker_device(device: str | None) -> str | None:
    """``None``/``"cuda"`` with several GPUs: ``cuda:(worker name mod GPUs)``; else ``device`` as given."""
    if device not in (None, "cuda") or (device is None and os.environ.get("MPM_WARP_DEVICE")) or _n_gpus() < 2:
        return device
    from distributed import get_worker

    try:
        return f"cuda:{int(get_worker().name) % _n_gpus()}"
    except (ValueError, TypeError):               # not in a worker, or a worker not named by a number
        return device


def _run_case(task: dict) -> dict:
    """Run one case (in a worker); never raises: a failure comes back as a record with its error."""
    t0 = time.perf_counter()
    out = os.path.join(task["out_dir"], task["id"])
    rec = _record(task, "failed")
    try:
        from distributed import get_worker

        from .runner import run

        rec["worker"] = get_worker().address
        scenario = scenario_from_dict(apply_overrides(task["raw"], dict(task["overrides"])), task["source"])
        runner = task["runner"] or functools.partial(run, overwrite=True)   # a dead worker's .part.h5 is replaced
        res = runner(scenario, out + ".part.h5", device=_worker_device(task["device"]))
        data = io.read_run(out + ".part.h5")
        rec.update(status="ok", result={k: getattr(res, k) for k in RESULT_FIELDS}, scene_result=dict(res.scene_result),
                   final={k: float(v[-1]) for k, v in data.scalars.items() if len(v)}, n_frames=data.n_frames)
        io.promote_part(out)
    except Exception as e:
        rec.update(status="failed", error=f"{type(e).__name__}: {e}", traceback=traceback.format_exc(limit=-4))
    rec["elapsed_s"] = time.perf_counter() - t0
    _write_json(out + ".json", rec)
    return rec


def _finished(task: dict) -> dict | None:
    """The record of a case finished by an earlier sweep (JSON "ok" and HDF5 readable), else None."""
    return io.finished_record(os.path.join(task["out_dir"], task["id"]))


# ---------------------------------------------------------------------------------- the sweep
def default_workers(device: str | None = None) -> int:
    """One worker per CUDA device, or per usable CPU core when there is none (or ``device="cpu"``)."""
    if device != "cpu" and _n_gpus():
        return _n_gpus()
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def _running(client) -> int:
    try:
        threads = client.nthreads()
        return sum(min(len(v), threads.get(w, 1)) for w, v in client.processing().items())
    except Exception:                             # progress only; never fail the sweep for it
        return 0


def _execute(client, todo: list, records: dict, retries: int, stream, total: int) -> None:
    """Submit every task; collect the records as they complete, with one progress line on ``stream``."""
    from distributed import as_completed

    token, t0, done, failed, skipped = uuid.uuid4().hex[:8], time.perf_counter(), 0, 0, total - len(todo)
    futures = {client.submit(_run_case, t, key=f"{t['id']}-{token}", retries=retries, pure=False, priority=-i): t
               for i, t in enumerate(todo)}
    for fut in as_completed(list(futures)):
        task = futures[fut]
        try:
            rec = fut.result()
        except Exception as e:                    # the worker died too often (KilledWorker) or the cluster is gone
            rec = _record(task, "failed", f"{type(e).__name__}: {e}")
            _write_json(os.path.join(task["out_dir"], task["id"] + ".json"), rec)
        fut.release()
        records[task["id"]] = rec
        done, failed = done + 1, failed + (rec["status"] != "ok")
        if stream is not None:
            el = time.perf_counter() - t0
            stream.write(f"\rsweep: {skipped + done}/{total} done ({failed} failed, {skipped} skipped), "
                         f"{_running(client)} running, elapsed {el:.0f} s, ETA {el / done * (len(todo) - done):.0f} s ")
            stream.flush()


def run_sweep(scenario, vary: dict | None = None, cases=None, out_dir="sweep", *, overrides=None,
              scheduler: str | None = None, n_workers: int | None = None, device: str | None = None,
              retries: int = 2, plot_x: str | None = None, plot_y: str | None = None,
              summary_path: str | None = None, figure_path: str | None = None, runner=None,
              progress=True) -> SweepResult:
    """Run every case of a sweep on a Dask cluster; write per-run files, a summary CSV and a figure.

    Parameters
    ----------
    scenario : str or os.PathLike
        Scenario file, or the name of a ready scene.
    vary : dict, optional
        Override key -> values (list, or comma-separated string); the sweep is their cartesian product.
    cases : list of dict or str, optional
        Explicit cases (override key -> value), or a CSV file of them; crossed with ``vary``.
    out_dir : str
        Folder of the run files (created); the summary goes there unless ``summary_path`` is given.
    overrides : list of str or dict, optional
        Overrides applied to every case (``["time.end=0.1"]``).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); default: an embedded LocalCluster.
    n_workers : int, optional
        Workers of the embedded cluster (default :func:`default_workers`); ignored with ``scheduler``.
    device : str, optional
        ``"cpu"``, ``"cuda"`` or ``"cuda:N"`` for every run (default: each worker's GPU, else the CPU).
    retries : int
        Extra attempts of a task whose worker died (beyond ``distributed.scheduler.allowed-failures``).
    plot_x, plot_y : str, optional
        Figure axes: a parameter (default the first varied key) and a summary column (default the first
        numeric ``scene_result`` value, else ``wall_time``).
    summary_path, figure_path : str, optional
        Default ``out_dir/summary.csv`` and the same name with ``.png``.
    runner : callable, optional
        ``runner(scenario: Scenario, output: str, device) -> RunResult`` run in the workers (default
        :func:`mpm_warp.run`); it must be importable (or picklable) there.
    progress : bool or text stream
        One progress line on stderr (True), on the given stream, or none (False).

    Returns
    -------
    SweepResult
    """
    if n_workers is not None and (not isinstance(n_workers, int) or n_workers < 1):
        raise InvalidArgument("n_workers", n_workers, "an integer >= 1")
    raw, source = read_scenario_dict(os.fspath(scenario))
    pairs = overrides.items() if isinstance(overrides, dict) else [split_override(o) for o in overrides or ()]
    fixed = [(_full_key(raw, k), _parse(v)) for k, v in pairs]
    case_list = expand_cases(vary, cases)
    os.makedirs(out_dir, exist_ok=True)
    tasks = _tasks(raw, source, case_list, fixed, out_dir, device, runner)
    records = {t["id"]: _finished(t) for t in tasks}
    todo = [t for t in tasks if records[t["id"]] is None]
    stream = sys.stderr if progress is True else (progress or None)
    if todo:
        try:
            from distributed import Client, LocalCluster
        except ImportError as e:                  # pragma: no cover - optional dependency
            raise MPMError("the sweep needs dask.distributed: pip install 'mpm-warp[sweep]'") from e
        with contextlib.ExitStack() as stack:
            if scheduler:
                client = stack.enter_context(Client(scheduler))
            else:
                cluster = stack.enter_context(LocalCluster(
                    n_workers=n_workers or default_workers(device), threads_per_worker=1, processes=True,
                    dashboard_address=None, silence_logs=40, env={"MPM_WARP_THREADS": "1"}))
                client = stack.enter_context(Client(cluster))
            try:
                _execute(client, todo, records, retries, stream, len(tasks))
            finally:
                if stream is not None:
                    stream.write("\n")
    params = list(dict.fromkeys(k for t in tasks for k in t["params"]))
    rows = [summary_row(t["params"], records[t["id"]]) for t in tasks]
    path = summary_path or os.path.join(out_dir, "summary.csv")
    write_summary(path, rows, ["id", "status", *params])
    scene_keys = list(dict.fromkeys(k for t in tasks for k in records[t["id"]].get("scene_result", {})))
    x = plot_x or (params[0] if params else "id")
    y = plot_y or next((k for k in scene_keys if any(number(r.get(k)) is not None for r in rows)), "wall_time")
    fig = plot_summary(rows, x, y, figure_path or os.path.splitext(path)[0] + ".png", params)
    return SweepResult(rows, path, fig, len(tasks) - len(todo))
