"""What the engine offers an experiment that watches or drives a run: the monitor contract and group views.

A monitor (a scene's saw and crack-front tracker, a shear test's push, a user's probe) is added
with :meth:`mpm_warp.Simulation.add_monitor`; the engine then, without knowing what it is:

- launches its :meth:`Monitor.actions` (recorded Warp launches) every step, after the step size is
  set and before P2G;
- calls :meth:`Monitor.frame_scalars` at every frame and stores the values as scalar series (units
  from :meth:`Monitor.units`), and stores its optional per-particle fields
  (:meth:`Monitor.particle_fields`, :meth:`Monitor.particle_field`) in every frame;
- stores :meth:`Monitor.state` in every checkpoint (under ``monitors/<name>/``) and hands it back to
  :meth:`Monitor.load_state` on resume, so a resumed run continues exactly;
- puts :meth:`Monitor.result` into :attr:`mpm_warp.RunResult.scene_result` when a run ends, and an optional
  ``outcome()`` record (how the run ended, a few values) into the run file's ``outcome`` attribute.

A monitor reads and writes particles only through :meth:`mpm_warp.Simulation.group_state`
(array views of one particle group, :class:`GroupState`) and the device clock
(:attr:`mpm_warp.Simulation.clock`, float64 ``[t, dt, t_end, dt_last]`` in s).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
import warp as wp

from .materials import Elastic

__all__ = ["Monitor", "GroupState"]


@runtime_checkable
class Monitor(Protocol):
    """The contract between the engine and a monitor (see the module docstring)."""

    #: unique name; its checkpoint state is stored under ``monitors/<name>/``
    name: str

    def actions(self) -> list:
        """Recorded launches (``wp.launch(..., record_cmd=True)``) run on the device every step."""

    def units(self) -> dict[str, str]:
        """Unit of every frame scalar :meth:`frame_scalars` returns."""

    def frame_scalars(self, sim) -> dict[str, float]:
        """Scalars of the current frame (called once per frame, also without an output file)."""

    def state(self) -> dict[str, np.ndarray]:
        """Everything the monitor needs to continue a run exactly (device arrays, recorded series)."""

    def load_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state` (into the existing device arrays: the recorded launches keep them)."""

    def result(self) -> dict:
        """Results of the run so far (named numbers), e.g. a crack speed."""

    # optional: ``outcome() -> dict``, a short record of how the run ended (a few named values, JSON of at most
    # 2 KiB), stored in the run file's ``outcome`` attribute when a run ends, e.g. a PST's class and field line


@dataclass
class GroupState:
    """Array views of one particle group (no copies): what a monitor's device actions read and write.

    Attributes
    ----------
    name : str
    material : Elastic
        The group's material (its moduli, Cam-Clay parameters).
    start, end : int
        Range of the group in the particle arrays (and in output fields).
    mass, vol0 : float
        Mass (kg) and initial volume (m^3) of one particle.
    x, v : wp.array of dim-vectors
        Positions (m) and velocities (m/s).
    C : wp.array of dim x dim matrices
        Affine velocity matrix (1/s).
    H : wp.array of dim x dim matrices
        Elastic displacement gradient ``F_E - I`` (-) (in 2D the in-plane block).
    hzz : wp.array or None
        ``F_E,zz - 1`` (-) of a plastic group in plane strain (2D), else None (an elastic particle's is 0).
    log_jp : wp.array or None
        ``ln det F_P`` of a Cam-Clay group (None for elastic groups).
    kappa : wp.array or None
        Accumulated plastic strain of a bonded weak-layer group (-), else None.
    x0 : ndarray (n, 3), float64
        Initial positions (m), host copy.
    """

    name: str
    material: Elastic
    start: int
    end: int
    mass: float
    vol0: float
    x: wp.array
    v: wp.array
    C: wp.array
    H: wp.array
    hzz: wp.array | None
    log_jp: wp.array | None
    x0: np.ndarray
    kappa: wp.array | None = None

    @property
    def count(self) -> int:
        """Number of particles of the group."""
        return self.end - self.start
