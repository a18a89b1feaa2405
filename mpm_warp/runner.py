"""The one way to run anything: :func:`run` (a scenario, a file or a ready scene) and :func:`resume`.

Both build the :class:`~mpm_warp.Simulation`, attach the scene's monitor when the scenario has a
scene (:func:`mpm_warp.scenes.attach`), run, and return the :class:`~mpm_warp.RunResult` with the
scene's result (``scene_result``) and its monitor (``monitor``).
"""

from __future__ import annotations

import os

from . import io
from .config import Scenario
from .loader import load_scenario, resolved_scenario
from .result import RunResult
from .scenes import attach
from .simulation import Simulation

__all__ = ["run", "resume", "simulation_for"]


def simulation_for(scenario: Scenario, device: str | None = None, n_threads: int | None = None,
                   use_graph: bool | None = None) -> Simulation:
    """A :class:`Simulation` of ``scenario`` with its scene's monitor attached (if it has a scene)."""
    sim = Simulation(scenario, device=device, use_graph=use_graph, n_threads=n_threads)
    attach(sim)
    return sim


def run(scenario, output: str | None = None, device: str | None = None, overrides=None, *,
        n_threads: int | None = None, use_graph: bool | None = None, **run_kwargs) -> RunResult:
    """Run a scenario and return its :class:`RunResult`.

    Parameters
    ----------
    scenario : Scenario, str or os.PathLike
        A scenario, a TOML file, or the name of a ready scene (``mpm-warp scenes``).
    output : str, optional
        HDF5 run file (a checkpoint ``<run>.ckpt.h5`` is written beside it); None runs without output.
    device : str, optional
        ``"cpu"``, ``"cuda"``, ``"cuda:N"``; default ``MPM_WARP_DEVICE``, then CUDA if present.
    overrides : list of str or dict, optional
        ``section.key=value`` overrides of a file or ready scene (as ``--set``).
    n_threads, use_graph
        As :class:`~mpm_warp.Simulation`.
    **run_kwargs
        ``end_time``, ``frame_interval``, ``callback`` of :meth:`Simulation.run`.

    Returns
    -------
    RunResult
        With ``scene_result`` (e.g. a PST's crack speed) and ``monitor`` (the scene's series).
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(os.fspath(scenario), overrides)
    elif overrides:
        from .errors import InvalidArgument

        raise InvalidArgument("overrides", overrides, "None with a Scenario object (use dataclasses.replace)")
    sim = simulation_for(scenario, device, n_threads, use_graph)
    return sim.run(output, **run_kwargs)


def resume(output, device: str | None = None, end_time: float | None = None, callback=None,
           n_threads: int | None = None) -> RunResult:
    """Continue the run stored in ``output`` from its last checkpoint, monitors included.

    The run file is truncated to the checkpoint's frame and extended; on the CPU a resumed run
    matches an uninterrupted one bit for bit (positions, ``log_jp``, the monitors' series and result).
    """
    output = os.fspath(output)
    meta = io.read_checkpoint_meta(io.checkpoint_path_for(output))
    sim = simulation_for(resolved_scenario(meta["scenario"], source=output), device, n_threads)
    sim.restore(output)
    return sim.run(output, end_time=end_time, callback=callback, append=True)
