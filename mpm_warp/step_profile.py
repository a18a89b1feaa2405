"""The CPU step's cost breakdown from its threads' stage times (:meth:`mpm_warp.step.Stepper.profile`).

Each thread of the step records ``(thread, stage, start, end)`` perf-counter times of its launches;
this turns them into per-step wall and busy seconds per stage (docs/architecture.md, "The CPU step
on several threads").
"""

from __future__ import annotations

import time

__all__ = ["stage_walls", "timed", "refuse_no_ops", "STAGES"]

#: the parallel stages of a step, in order
STAGES = ("p2g", "grid", "g2p")


def timed(record: list | None, k: int, stage: str, run) -> None:
    """``run()``, appending ``(k, stage, start, end)`` perf-counter times to ``record`` unless it is None."""
    if record is None:
        run()
        return
    t0 = time.perf_counter()
    run()
    record.append((k, stage, t0, time.perf_counter()))


def stage_walls(record: list, n: int, n_threads: int, total: float) -> dict:
    """Per-step seconds of each stage from ``record`` over ``n`` steps on ``n_threads`` threads.

    Parameters
    ----------
    record : list of (int, str, float, float)
        ``(thread, stage, start, end)`` times (s); ``stage`` one of ``"serial"`` (thread 0's launches
        outside the parallel stages, twice a step) and :data:`STAGES`.
    n : int
        Steps recorded.
    n_threads : int
    total : float
        Wall time of the ``n`` steps (s).

    Returns
    -------
    dict
        ``threads``, ``steps``, ``total`` (s per step), ``serial`` (s per step) and, per stage,
        ``wall`` (first start of the stage on any thread to the first start of the next; G2P ends at
        thread 0's serial launches) and ``busy`` (each thread's own launches, s per step).
    """
    busy = {s: [0.0] * n_threads for s in ("serial", *STAGES)}
    for k, stage, a, b in record:
        busy[stage][k] += (b - a) / n
    first: dict = {}
    for k, stage, a, _ in record:
        if stage != "serial" or k == 0:
            first.setdefault((k, stage), []).append(a)
    ends = first[(0, "serial")][1::2]
    walls = {s: 0.0 for s in STAGES}
    for i in range(n):
        b = [min(first[(j, s)][i] for j in range(n_threads)) for s in STAGES] + [ends[i]]
        for m, s in enumerate(STAGES):
            walls[s] += (b[m + 1] - b[m]) / n
    out = {"threads": n_threads, "steps": n, "total": total / n, "serial": busy["serial"][0]}
    for s in STAGES:
        out[s] = {"wall": walls[s], "busy": busy[s]}
    return out


def refuse_no_ops(clock, when: str) -> None:
    """Raise ``RuntimeError`` when ``clock`` (the step's ``[t, dt, t_end, dt_last]``, s) is at its frame end: the
    steps ``when`` ("before" or "during") a profile are then no-ops (dt = 0) that would time as fast."""
    t, _, t_end, _ = (float(c) for c in clock.numpy()[:4])
    if t >= t_end * (1.0 - 1e-12) - 1e-15:
        raise RuntimeError(f"Stepper.profile: the clock reached its frame end t = {t_end:g} s {when} the profiled "
                           "steps, so they time no-op steps (dt = 0): call set_frame_end(t) with a t beyond them")
