"""Device state of the weak layer during a run: collapse reference, failure flags and the failure action."""

from __future__ import annotations

import numpy as np
import warp as wp

from ..fronts import collapse_fraction
from .kernels import weak_layer_kernel
from .params import WeakLayer

__all__ = ["WeakLayerTracker", "ReferenceField", "SAWN", "FAILED", "INTACT"]

#: values of the per-particle failure flag
INTACT, FAILED, SAWN = 0, 1, 2


class WeakLayerTracker:
    """Collapse reference, failure flags and the brittle failure action of one weak-layer particle group.

    Parameters
    ----------
    sim : Simulation
    group_name : str
        Name of the weak-layer particle group (a Cam-Clay group).
    t_ref : float
        End of settling (s): the collapse reference is the state then.
    params : WeakLayer
        The failure rule (``failure``, ``failure_log_jp``).

    Attributes
    ----------
    log_jp : wp.array (n,)
        View of the group's ``ln det F_P``.
    ref : wp.array (n,)
        ``log_jp`` collapse is measured from: the settled state, or the state right after failure.
    failed : wp.array of uint8 (n,)
        :data:`INTACT`, :data:`FAILED` or :data:`SAWN`.
    """

    #: relative tolerance on the yield function for "on the yield surface" (after the engine's return y ~ 0)
    YIELD_TOL = 1e-3

    def __init__(self, sim, group_name: str, t_ref: float, params: WeakLayer):
        view = sim.group_state(group_name)
        T = sim.model.T
        m = view.material
        self.group = view
        self.log_jp = view.log_jp
        self.ref = wp.array(np.full(view.count, m.initial_log_jp), dtype=T, device=sim.device)
        self.failed = wp.zeros(view.count, dtype=wp.uint8, device=sim.device)
        self.launch = wp.launch(
            weak_layer_kernel(T), view.count,
            inputs=[view.H, self.log_jp, self.ref, self.failed, sim.clock, float(t_ref), int(params.brittle),
                    T(m.mu), T(m.lam), T(m.M), T(m.beta), T(m.xi), T(m.p0_floor), T(params.failure_log_jp),
                    T(self.YIELD_TOL)],
            device=sim.device, record_cmd=True)

    def collapse(self) -> tuple[np.ndarray, np.ndarray]:
        """Host copies: collapse ``1 - exp(log_jp - ref)`` (-) and the failure flags."""
        lj = self.log_jp.numpy().astype(np.float64)
        return collapse_fraction(lj, self.ref.numpy().astype(np.float64)), self.failed.numpy()

    def state(self) -> dict[str, np.ndarray]:
        """Checkpoint state: ``ref`` and ``failed``."""
        return {"ref": self.ref.numpy(), "failed": self.failed.numpy()}

    def load_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state` into the device arrays."""
        self.ref.assign(state["ref"])
        self.failed.assign(state["failed"])

    def reference_field(self, sim) -> np.ndarray:
        """``log_jp_ref`` of every particle (N,): this layer's reference, ``log_jp`` elsewhere (no collapse there)."""
        out = sim.particle_field("log_jp")
        out[self.group.start:self.group.end] = self.ref.numpy()
        return out


class ReferenceField:
    """Monitor mixin: the per-frame particle field ``log_jp_ref`` (-) of its ``weak`` tracker.

    Written when the output holds ``log_jp``; the collapse of :mod:`mpm_warp.post.fields` is measured
    from it. Needs the attributes ``sim`` and ``weak`` (a :class:`WeakLayerTracker`).
    """

    def particle_fields(self) -> dict[str, tuple[tuple, str]]:
        """``log_jp_ref`` (-), the collapse reference, when the output holds ``log_jp``."""
        return {"log_jp_ref": ((), "1")} if "log_jp" in self.sim.scenario.output.fields else {}

    def particle_field(self, name: str) -> np.ndarray:
        """The field ``name`` (``log_jp_ref``) of every particle."""
        return self.weak.reference_field(self.sim)
