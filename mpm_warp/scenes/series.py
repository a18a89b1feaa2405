"""Frame series of a scene monitor: scalars recorded once per frame time, and their checkpoint state."""

from __future__ import annotations

import numpy as np

__all__ = ["SeriesMonitor", "entries_below"]


class SeriesMonitor:
    """Base of the scene monitors: the frame series recorded so far and what the engine asks of every monitor.

    Subclasses set :attr:`name`, fill :meth:`actions`, :meth:`units`, :meth:`measure` (the frame
    scalars), :meth:`result` and, for their device arrays, :meth:`device_state` /
    :meth:`load_device_state`.

    Attributes
    ----------
    times : list of float
        Frame times recorded (s).
    series : dict of str -> list of float
        Frame scalars recorded, by name (units: :meth:`units`).
    """

    name = "scene"

    def __init__(self):
        self.times: list[float] = []
        self.series: dict[str, list[float]] = {}

    def scene_params(self, sim, params_type):
        """``sim``'s scene parameters, which must be a ``params_type`` (a scene's parameter class, its ``kind``
        the scene's package); a TypeError naming this monitor and the scene's builder otherwise."""
        p = sim.scenario.scene
        if not isinstance(p, params_type):
            raise TypeError(f"{type(self).__name__} needs a scenario built by "
                            f"mpm_warp.scenes.{params_type.kind}.build")
        return p

    # ------------------------------------------------------------- to override
    def actions(self) -> list:
        """Recorded launches run every step."""
        return []

    def units(self) -> dict[str, str]:
        """Units of the frame scalars."""
        return {}

    def measure(self, sim) -> dict[str, float]:
        """The frame scalars of the current state."""
        return {}

    def result(self) -> dict:
        """Results from the series recorded so far."""
        return {}

    def device_state(self) -> dict[str, np.ndarray]:
        """Host copies of the monitor's device arrays (for checkpoints)."""
        return {}

    def load_device_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`device_state` into the device arrays."""

    # ------------------------------------------------------- the engine's calls
    def frame_scalars(self, sim) -> dict[str, float]:
        """:meth:`measure` once per frame time, appended to :attr:`series` (a repeated time returns the last)."""
        t = sim.time
        if self.times and self.times[-1] == t:
            return {k: v[-1] for k, v in self.series.items()}
        out = self.measure(sim)
        self.times.append(t)
        for k, v in out.items():
            self.series.setdefault(k, []).append(v)
        return out

    def particle_fields(self) -> dict[str, tuple[tuple, str]]:
        """Per-frame particle fields this monitor adds to the output: name -> (shape, unit)."""
        return {}

    def state(self) -> dict[str, np.ndarray]:
        """Checkpoint state: the device arrays and the series recorded so far."""
        out = {f"device/{k}": np.asarray(v) for k, v in self.device_state().items()}
        out["series/times"] = np.asarray(self.times, dtype=np.float64)
        out.update({f"series/values/{k}": np.asarray(v, dtype=np.float64) for k, v in self.series.items()})
        return out

    def load_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        self.load_device_state(entries_below(state, "device/"))
        self.times = [float(t) for t in state["series/times"]]
        self.series = {k: [float(x) for x in v] for k, v in entries_below(state, "series/values/").items()}

    def series_arrays(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """The recorded times (s) and series as arrays."""
        return np.asarray(self.times, dtype=float), {k: np.asarray(v, dtype=float) for k, v in self.series.items()}


def entries_below(state: dict, prefix: str) -> dict:
    """The entries of ``state`` under ``prefix``, with the prefix removed from their names."""
    return {k[len(prefix):]: v for k, v in state.items() if k.startswith(prefix)}
