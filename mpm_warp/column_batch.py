"""Many independent columns run together: each its own run file, frames, monitors and outcome, one step size.

:func:`run_columns` steps simulations together (:class:`~mpm_warp.shared_step.SharedStep`) to the union of
their frame times; each writes its frames, checkpoints and outcome as its own run does
(:class:`~mpm_warp.run_loop.FrameRun`). A column whose callback says stop (its outcome is decided), whose
frames are done, or whose run fails leaves the batch at once and costs no more work; the others go on. How
the step is shared and what it costs: docs/architecture.md, "Columns stepped together".
"""

from __future__ import annotations

import contextlib
import time

import numpy as np
import warp as wp

from . import checks, io
from .errors import InvalidArgument, SimulationBlowUp
from .result import RunResult
from .run_loop import FrameRun
from .shared_step import SharedStep
from .time_step import run_times

__all__ = ["run_columns"]


def run_columns(sims: list, outputs: list | None = None, callback=None, *, overwrite: bool = False
                ) -> list[RunResult | Exception]:
    """Run the simulations ``sims`` (each new, on one thread, on one device) together to their scenarios' end.

    Parameters
    ----------
    sims : list of Simulation
        The columns, with their monitors attached.
    outputs : list of (str or None), optional
        Each column's run file (None: no file); default none.
    callback : callable, optional
        ``callback(k, sim, frame)`` after every frame of column ``k``; returning False takes it out of the batch
        (e.g. once its outcome is decided), as :meth:`Simulation.run`'s callback stops a run.
    overwrite : bool
        Replace existing run files.

    Returns
    -------
    list
        Per column its :class:`~mpm_warp.result.RunResult` (``wall_time``: the batch's wall time while the column
        was in it, shared among the columns by their particles), or the exception its run ended with.
    """
    sims = list(sims)
    outputs = [None] * len(sims) if outputs is None else list(outputs)
    if len(outputs) != len(sims):
        raise InvalidArgument("outputs", f"{len(outputs)} paths", f"one per simulation ({len(sims)})")
    callback = checks.optional_callable("callback", callback)
    for k, s in enumerate(sims):
        if s.time > 0.0:
            raise InvalidArgument(f"sims[{k}]", f"a Simulation at t = {s.time:.6g} s", "a new Simulation")
    step = SharedStep(sims)
    with contextlib.ExitStack() as held:
        paths = [None if o is None else io.check_output_file(checks.file_path(f"outputs[{k}]", o),
                                                              overwrite=overwrite)
                 for k, o in enumerate(outputs)]
        for p in paths:
            if p is not None:
                held.enter_context(io.output_lock(p))
        return _run(sims, paths, step, callback)


def _run(sims, paths, step: SharedStep, callback) -> list:
    out: list = [None] * len(sims)
    runs = []
    for k, (s, p) in enumerate(zip(sims, paths, strict=True)):
        end, fi = run_times(s.scenario, None, None)
        cb = None if callback is None else (lambda sim, frame, k=k: callback(k, sim, frame))
        runs.append(FrameRun(s, p, end, fi, cb, False))
    for k in range(len(sims)):
        _guarded(k, runs, out, step, runs[k].open)
    step.compile()
    particles = np.array([s.model.n_particles for s in sims], dtype=float)
    while step.active:
        t_next = min(runs[k].next_time for k in step.active)
        here = list(step.active)
        t0 = time.perf_counter()
        steps, blown = step.step_to(t_next)
        wp.synchronize_device(step.device)
        wall = time.perf_counter() - t0
        share = particles[here] / particles[here].sum()
        for k, w in zip(here, share * wall, strict=True):
            if k in blown:
                runs[k].steps_total += steps
                runs[k].blew_up(blown[k])
                _leave(k, runs, out, step, blown[k])
            elif runs[k].next_time <= t_next * (1 + 1e-12) + 1e-15:
                _guarded(k, runs, out, step, lambda k=k, w=w, n=steps: runs[k].reached(n, w))
            else:
                runs[k].steps_total += steps
                runs[k].wall += w
    return out


def _guarded(k: int, runs: list, out: list, step: SharedStep, action) -> None:
    """Run ``action`` for column ``k``; the column leaves the batch when it fails or its run has ended."""
    try:
        action()
    except SimulationBlowUp as e:
        runs[k].blew_up(e)
        _leave(k, runs, out, step, e)
        return
    except Exception as e:      # one column's failure never stops the others
        _leave(k, runs, out, step, e)
        return
    if not runs[k].running:
        _leave(k, runs, out, step, None)


def _leave(k: int, runs: list, out: list, step: SharedStep, error: Exception | None) -> None:
    step.retire(k)
    try:
        runs[k].close()
    except Exception as e:
        error = error or e
    out[k] = error if error is not None else runs[k].result()
