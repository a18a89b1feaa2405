"""What a run returns (:class:`RunResult`) and the versions stored with it."""

from __future__ import annotations

import platform
from dataclasses import dataclass, field

import numpy as np
import warp as wp

from .errors import InvalidArgument
from .monitor import Monitor

__all__ = ["RunResult", "versions"]


def versions() -> dict[str, str]:
    """Versions of the library and its main dependencies."""
    import h5py

    from .version import __version__

    return {"mpm_warp": __version__, "warp": wp.config.version, "numpy": np.__version__, "h5py": h5py.__version__,
            "python": platform.python_version()}


@dataclass
class RunResult:
    """What a run returns.

    Attributes
    ----------
    output : str or None
        Path of the HDF5 file.
    steps : int
        Steps taken in this call.
    frames : int
        Frames written in this call.
    sim_time : float
        Simulated time reached (s).
    wall_time : float
        Wall-clock time of the stepping (s), compilation excluded.
    particle_steps_per_s : float
        ``n_particles * steps / wall_time``.
    n_particles : int
    device : str
    edge_hits : int
        Particle clamps at the grid edge (see ``kernels/g2p.py``).
    scene_result : dict
        The monitors' results (:meth:`mpm_warp.monitor.Monitor.result`), e.g. a PST's crack speed.
    monitors : dict of str -> Monitor
        The monitors of the run by name (their recorded series, device arrays).
    floor_events : int
        Particle updates in this call whose elastic singular values were floored at
        ``SINGULAR_VALUE_FLOOR`` (an element crushed to almost nothing; ``kernels/p2g.py``).
    inversions : int
        Particle updates in this call with an inverted trial state, ``det F_tr <= 0`` (then floored too).
        ``output.on_inversion = "stop"`` ends the run at the first health check that sees either.
    stopped : bool
        The run ended before its end time on request (a callback, a signal, :meth:`Simulation.request_stop`).
    """

    output: str | None
    steps: int
    frames: int
    sim_time: float
    wall_time: float
    particle_steps_per_s: float
    n_particles: int
    device: str
    edge_hits: int = 0
    scene_result: dict = field(default_factory=dict)
    monitors: dict = field(default_factory=dict)
    floor_events: int = 0
    inversions: int = 0
    stopped: bool = False

    @property
    def monitor(self) -> Monitor | None:
        """The run's one monitor (a scene's), None without; InvalidArgument when there are several."""
        if len(self.monitors) > 1:
            raise InvalidArgument("monitor", sorted(self.monitors), "a run with one monitor (use .monitors)")
        return next(iter(self.monitors.values()), None)
