"""Device state of the weak layer during a run: collapse reference, saw flags, damage arrival times.

The damage front of a snow scene: a particle is damaged once its bond ``1 - kappa/kappa_s`` has
fallen to :data:`DAMAGE_BOND` (0.5); a bin along the column is damaged once the median of its
particles' damage times has passed (more than half of them damaged); the front is the far edge of
the contiguous run of damaged bins from the saw (:func:`~mpm_warp.scenes.fronts.front_from_arrival`).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..fronts import collapse_fraction
from .kernels import weak_layer_kernel

__all__ = ["WeakLayerTracker", "ReferenceField", "DAMAGE_BOND", "bin_median"]

#: a weak-layer particle is damaged once its bond has fallen to this (-)
DAMAGE_BOND = 0.5


def bin_median(s, values, bin_width: float, n_bins: int) -> np.ndarray:
    """Median of ``values`` per bin of ``s`` (bins of ``bin_width`` from 0; inf where a bin is empty)."""
    b = np.floor(np.asarray(s, dtype=float) / bin_width).astype(int)
    ok = (b >= 0) & (b < n_bins)
    out = np.full(n_bins, np.inf)
    b, v = b[ok], np.asarray(values, dtype=float)[ok]
    order = np.lexsort((v, b))
    b, v = b[order], v[order]
    starts = np.searchsorted(b, np.arange(n_bins))
    ends = np.searchsorted(b, np.arange(n_bins), side="right")
    for k in np.nonzero(ends > starts)[0]:
        out[k] = float(np.median(v[starts[k]:ends[k]]))  # inf unless more than half are finite
    return out


class WeakLayerTracker:
    """The weak layer's device bookkeeping (and, in a PST, the saw) for one bonded particle group.

    Parameters
    ----------
    sim : Simulation
    group_name : str
        Name of the weak-layer particle group (a bonded Cam-Clay group).
    t_ref : float
        End of settling (s): the collapse reference is the state then.
    saw : (t_start, speed, cut_length, x_start, direction[, pre_cut]) or None
        The saw (s, m/s, m, m, +1/-1; m, the length cut from the start, 0 without), or none (shear test).
        ``cut_length`` is the blade's end to begin with (:attr:`blade_end`; :meth:`stop_blade` moves it between
        frames).

    Attributes
    ----------
    log_jp, kappa : wp.array (n,)
        Views of the group's state.
    ref : wp.array (n,)
        ``log_jp`` at the end of settling (collapse reference).
    sawn : wp.array of uint8 (n,)
        1 behind the saw.
    arrival : wp.array of float64 (n,)
        Damage time (s) of each particle, inf while its bond is above :data:`DAMAGE_BOND`.
    blade_end : wp.array of float64 (1,)
        Where the blade stops (m from ``x_start``), read by the saw kernel every step: ``cut_length`` until
        :meth:`stop_blade` writes it.
    """

    def __init__(self, sim, group_name: str, t_ref: float, saw=None):
        view = sim.group_state(group_name)
        if view.kappa is None:
            raise TypeError(f"the weak layer {group_name!r} must be a bonded Cam-Clay group (model 'bonded_camclay')")
        T = sim.model.T
        m = view.material
        self.group = view
        self.material = m
        self.log_jp, self.kappa = view.log_jp, view.kappa
        self.ref = wp.array(np.full(view.count, m.initial_log_jp), dtype=T, device=sim.device)
        self.sawn = wp.zeros(view.count, dtype=wp.uint8, device=sim.device)
        self.arrival = wp.full(view.count, np.inf, dtype=wp.float64, device=sim.device)
        t_saw, speed, cut, x_start, direction, *pre = saw if saw is not None else (math.inf, 0.0, 0.0, 0.0, 1.0)
        self.blade_end = wp.array([float(cut)], dtype=wp.float64, device=sim.device)
        self.launch = wp.launch(
            weak_layer_kernel(sim.model.dim, T), view.count,
            inputs=[view.x, self.log_jp, self.kappa, self.ref, self.sawn, self.arrival, sim.clock, float(t_ref),
                    T(m.kappa_s), T(DAMAGE_BOND), float(t_saw), float(speed), self.blade_end, float(x_start),
                    float(direction), float(pre[0]) if pre else 0.0],
            device=sim.device, record_cmd=True)

    def bond(self) -> np.ndarray:
        """Host copy of the bond ``max(0, 1 - kappa/kappa_s)`` (-) of every particle."""
        return np.maximum(0.0, 1.0 - self.kappa.numpy().astype(np.float64) / self.material.kappa_s)

    def collapse(self) -> tuple[np.ndarray, np.ndarray]:
        """Host copies: collapse ``1 - exp(log_jp - ref)`` (-) and the saw flags."""
        lj = self.log_jp.numpy().astype(np.float64)
        return collapse_fraction(lj, self.ref.numpy().astype(np.float64)), self.sawn.numpy()

    def damage_arrival(self, s0, bin_width: float, n_bins: int) -> np.ndarray:
        """Damage time (s) of every bin along ``s0`` (m, the particles' initial distances from the cut end):
        the median of its particles' damage times (inf: not damaged yet)."""
        return bin_median(s0, self.arrival.numpy(), bin_width, n_bins)

    def stop_blade(self, position: float) -> None:
        """Stop the blade at ``position`` (m from ``x_start``): a copy into :attr:`blade_end`, between frames
        (the steps queued after it, graphs included, read it)."""
        self.blade_end.assign(np.array([float(position)], dtype=np.float64))

    def state(self) -> dict[str, np.ndarray]:
        """Checkpoint state: ``ref``, ``sawn`` and ``arrival`` (the blade's end is the scene monitor's: a trial
        forked from another run's snapshot keeps its own cut)."""
        return {"ref": self.ref.numpy(), "sawn": self.sawn.numpy(), "arrival": self.arrival.numpy()}

    def load_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state` into the device arrays."""
        self.ref.assign(state["ref"])
        self.sawn.assign(state["sawn"])
        self.arrival.assign(state["arrival"])

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
