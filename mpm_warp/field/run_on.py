"""A finished field case run on past its outcome call: does its slab break once the slab behind the crack lands?

The batch stops a case as soon as its outcome is decided (:func:`~.protocol.decided`): END once the damage front
enters the far end zone. An observer watches on: the cut slab falls onto its collapsed weak layer and may break
as it lands, within a few hundredths of a second of the crack reaching the end. :func:`run_on` copies a finished
case's run file and checkpoint to a folder of its own (the batch's files are never written) and resumes the copy
for ``after`` seconds of simulated time past its last frame, stopping early at a crack through the slab. It
returns what the slab did: its through-crack (time and place), its peak stress over strength before and after
the call, and the touchdown distance the run measured.
"""

from __future__ import annotations

import math
import os
import shutil
import time

import numpy as np

from ..io import checkpoint_path_for, read_run

__all__ = ["run_on", "scenario_of", "kept_record"]


def kept_record(path: str, study: dict) -> dict | None:
    """The record a study kept at ``path`` (JSON) when it was made by the same ``study`` (every key of it the
    same: the runs folder, the time run on), None where there is none; a record of another study raises
    :class:`~mpm_warp.errors.InvalidArgument` naming it, and is neither reused nor overwritten."""
    import json

    from ..errors import InvalidArgument

    if not os.path.exists(path):
        return None
    with open(path) as fh:
        kept = json.load(fh)
    other = {k: kept.get(k) for k in study}
    if other != study:
        raise InvalidArgument("work", os.path.dirname(path) or ".",
                              f"a folder without records of another study: {os.path.basename(path)} was made with "
                              f"{other}, this study is {study}")
    return kept


def scenario_of(run_dir: str, case_id: str):
    """The scenario the case ``case_id`` of the runs folder ``run_dir`` ran (from its final checkpoint), or None
    without one."""
    from ..io.checkpoint import read_checkpoint_meta
    from ..loader import resolved_scenario

    ck = os.path.join(run_dir, case_id + ".ckpt.h5")
    return resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck) if os.path.exists(ck) else None


def _peak(x) -> float | None:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return float(x.max()) if x.size else None


def run_on(run_dir: str, case_id: str, work_dir: str, after: float = 0.1, n_threads: int = 1) -> dict:
    """Resume a copy of the case ``case_id`` of the batch folder ``run_dir`` in ``work_dir`` for ``after`` s.

    Parameters
    ----------
    run_dir : str
        The batch's runs folder (``CASE.h5`` and ``CASE.ckpt.h5`` of a finished case).
    case_id : str
        The case's id.
    work_dir : str
        Where the copy goes (created; an earlier copy of the case there is replaced).
    after : float
        Simulated time to run past the last frame (s), > 0.
    n_threads : int
        CPU threads of the step.

    Returns
    -------
    dict
        ``call_time`` (s, the last frame of the batch's run), ``slab_through_crack_time`` (s after the call, None:
        none), ``slab_through_crack_at`` (m from the cut end), ``peak_stress_ratio_before`` and ``_after`` (-),
        ``touchdown_max`` (m, the longest touchdown distance the run measured after the call), ``front_final``
        (m), ``sim_time_after`` (s), ``wall_s``; ``body_peak_before`` and ``_after``: the same of the slab's body,
        its rows beyond the grid's tie to the weak layer (None where the run has no such series).
    """
    from ..errors import InvalidArgument
    from ..runner import resume

    if not (isinstance(after, (int, float)) and after > 0.0 and math.isfinite(after)):
        raise InvalidArgument("after", after, "a time past the last frame in (0, inf) s")
    src = os.path.join(run_dir, case_id + ".h5")
    os.makedirs(work_dir, exist_ok=True)
    dst = os.path.join(work_dir, case_id + ".h5")
    shutil.copyfile(src, dst)
    shutil.copyfile(checkpoint_path_for(src), checkpoint_path_for(dst))
    before = read_run(dst)
    t_call = float(before.times[-1])
    n_before = before.n_frames

    def until_through(sim, frame) -> bool:
        crack = sim.monitors["pst"].series_arrays()[1].get("slab_crack", [])
        return not (len(crack) and np.isfinite(crack[-1]))

    t0 = time.perf_counter()
    res = resume(dst, end_time=t_call + after, callback=until_through, n_threads=n_threads)
    wall = time.perf_counter() - t0
    out = read_run(dst)
    t, s = out.times, out.scalars
    later = slice(n_before, None)
    crack = np.asarray(s.get("slab_crack", np.full(len(t), np.nan)), dtype=float)
    hit = np.flatnonzero(np.isfinite(crack[later]))
    return {"call_time": t_call,
            "slab_through_crack_time": float(t[later][hit[0]] - t_call) if hit.size else None,
            "slab_through_crack_at": float(crack[later][hit[0]]) if hit.size else None,
            "peak_stress_ratio_before": _peak(s.get("slab_stress_ratio", [])[:n_before]),
            "peak_stress_ratio_after": _peak(s.get("slab_stress_ratio", [])[later]),
            "body_peak_before": _peak(s.get("slab_body_stress_ratio", [])[:n_before]),
            "body_peak_after": _peak(s.get("slab_body_stress_ratio", [])[later]),
            "touchdown_max": _peak(s.get("touchdown", [])[later]),
            "front_final": float(s["front"][-1]), "sim_time_after": float(t[-1] - t_call),
            "outcome_after": res.scene_result.get("outcome", {}).get("class"), "wall_s": wall}
