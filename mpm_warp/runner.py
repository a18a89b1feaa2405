"""The one way to run anything: :func:`run` (a scenario, a file or a ready scene) and :func:`resume`.

Both first claim the output (:func:`claimed_output`: the path is checked, never the input
scenario nor a non-regular file, and locked against a second run), then build the
:class:`~mpm_warp.Simulation` (its memory estimate checked before anything is allocated),
attach the scene's monitor when the scenario has a scene (:func:`mpm_warp.scenes.attach`), run,
and return the :class:`~mpm_warp.RunResult` with the scene's result (``scene_result``) and its
monitor (``monitor``).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable

from . import checks, io
from .config import Scenario, check_end_time
from .errors import InvalidArgument, OutputError
from .io.hdf5 import pad_to_stored_eof
from .loader import load_scenario, resolved_scenario, scenario_path
from .result import RunResult
from .scenes import attach
from .simulation import Simulation
from .snapshot import check_identity

__all__ = ["run", "resume", "simulation_for", "claimed_output"]


def simulation_for(scenario: Scenario, device: str | None = None, n_threads: int | None = None,
                   use_graph: bool | None = None, max_memory=None) -> Simulation:
    """A :class:`Simulation` of ``scenario`` with its scene's monitor attached (if it has a scene)."""
    sim = Simulation(scenario, device=device, use_graph=use_graph, n_threads=n_threads, max_memory=max_memory)
    attach(sim)
    return sim


@contextlib.contextmanager
def claimed_output(output, *, overwrite: bool = False, inputs=(), append: bool = False):
    """Check run file ``output`` (:func:`mpm_warp.io.check_output_file`) and hold its lock for the block.

    Yields the path as a ``str`` (None when ``output`` is None: nothing to claim).
    """
    if output is None:
        yield None
        return
    output = io.check_output_file(output, overwrite=overwrite, inputs=inputs, append=append)
    with io.output_lock(output):
        yield output


def run(scenario, output: str | None = None, device: str | None = None, overrides=None, *,
        n_threads: int | None = None, use_graph: bool | None = None, overwrite: bool = False, max_memory=None,
        on_start: Callable[[Simulation], None] | None = None, **run_kwargs) -> RunResult:
    """Run a scenario and return its :class:`RunResult`.

    Parameters
    ----------
    scenario : Scenario, str or os.PathLike
        A scenario, a TOML file, or the name of a ready scene (``mpm-warp scenes``).
    output : str, optional
        HDF5 run file (a checkpoint ``<run>.ckpt.h5`` is written beside it); None runs without output.
        An existing file is refused unless ``overwrite``; the input scenario and non-regular files
        always are; a second run on the same output fails at once (:func:`claimed_output`).
    device : str, optional
        ``"cpu"``, ``"cuda"``, ``"cuda:N"``; default ``MPM_WARP_DEVICE``, then CUDA if present.
    overrides : list of str or dict, optional
        ``section.key=value`` overrides of a file or ready scene (as ``--set``).
    n_threads, use_graph, max_memory
        As :class:`~mpm_warp.Simulation`.
    overwrite : bool
        Replace an existing ``output`` (and its checkpoint).
    on_start : callable, optional
        ``on_start(sim)`` once the simulation is built, before it runs (e.g. to keep it for
        :meth:`Simulation.request_stop`).
    **run_kwargs
        ``end_time``, ``frame_interval``, ``callback`` of :meth:`Simulation.run`.

    Returns
    -------
    RunResult
        With ``scene_result`` (e.g. a PST's crack speed) and ``monitor`` (the scene's series).
    """
    overwrite = checks.flag("overwrite", overwrite)
    output = checks.file_path("output", output, none=True)
    on_start = checks.optional_callable("on_start", on_start)
    unknown = sorted(run_kwargs.keys() - {"end_time", "frame_interval", "callback"})
    if unknown:
        raise InvalidArgument("run_kwargs", unknown, "only end_time, frame_interval and callback (of Simulation.run)")
    if isinstance(scenario, Scenario):
        if overrides:
            raise InvalidArgument("overrides", overrides, "None with a Scenario object (use dataclasses.replace)")
        inputs = ()
    else:
        inputs = (scenario_path(scenario),)
        scenario = os.fspath(scenario)
    with claimed_output(output, overwrite=overwrite, inputs=inputs) as output:
        if not isinstance(scenario, Scenario):
            scenario = load_scenario(scenario, overrides)
        sim = simulation_for(scenario, device, n_threads, use_graph, max_memory)
        if on_start is not None:
            on_start(sim)
        return sim.run(output, overwrite=overwrite, **run_kwargs)


def _every_frame_reads(path: str) -> None:
    run = io.read_run(path)
    for i in range(run.n_frames):
        run.frame(i)


def resume(output, device: str | None = None, end_time: float | None = None, callback=None,
           n_threads: int | None = None, max_memory=None,
           on_start: Callable[[Simulation], None] | None = None) -> RunResult:
    """Continue the run stored in ``output`` from its last checkpoint, monitors included.

    The checkpoint must be of this run file (the ``run_id`` both hold:
    :func:`mpm_warp.snapshot.check_identity`) and is verified (SHA-256); the run file's frames are
    read once (a damaged one stops the resume) and all kept: those written after the checkpoint are
    stepped over again, not rewritten. On the CPU a resumed run matches an uninterrupted one bit for
    bit (positions, ``log_jp``, the monitors' series and result), also from a checkpoint written
    mid-frame by :meth:`Simulation.request_stop`.

    ``end_time`` (default the scenario's ``time.end``) is checked as ``time.end`` is (finite, > 0, the
    step budget) and must lie after the run file's last frame: a resume never removes frames.
    """
    output = checks.file_path("output", output)
    callback = checks.optional_callable("callback", callback)
    on_start = checks.optional_callable("on_start", on_start)
    with claimed_output(output, append=True) as output:
        with contextlib.suppress(OSError):     # a run that found no room may have left its file short of its end
            pad_to_stored_eof(output, _every_frame_reads)
        ckpt = io.checkpoint_path_for(output)
        if not os.path.exists(ckpt):
            raise OutputError(f"{output}: has no checkpoint {ckpt} to resume from")
        meta = io.read_checkpoint_meta(ckpt)
        run = io.read_run(output)
        check_identity(output, ckpt, run.attrs, meta)
        scenario = resolved_scenario(meta["scenario"], source=output)
        end = scenario.time.end if end_time is None else check_end_time(scenario, end_time)
        last = float(run.times[-1])
        if end <= last * (1 + 1e-12):
            raise InvalidArgument("end_time", end_time if end_time is not None else end, (
                f"a time after the last frame's t = {last:.6g} s: {output} holds {run.n_frames} frames to there "
                "and a resume never removes frames" + (" (give a later end time to extend it)"
                                                       if end >= last * (1 - 1e-12) else "")))
        sim = simulation_for(scenario, device, n_threads, max_memory=max_memory)
        sim.restore(output)
        if on_start is not None:
            on_start(sim)
        return sim.run(output, end_time=end, callback=callback, append=True)
