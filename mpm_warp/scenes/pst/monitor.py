"""The PST monitor: the saw, the weak layer's failure rule, the crack-front trackers and the frame series."""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..fronts import front_from_arrival
from ..series import SeriesMonitor, entries_below
from ..weak_layer import SAWN, ReferenceField, WeakLayerTracker
from .analysis import pst_summary
from .kernels import pst_action_kernel
from .params import PSTParams

__all__ = ["PSTMonitor", "attach"]


class PSTMonitor(ReferenceField, SeriesMonitor):
    """The saw, the front trackers and the frame diagnostics of one PST simulation.

    Frame scalars (stored in the run file): ``front`` (m from the cut end, the collapse criterion of
    :mod:`mpm_warp.scenes.pst`), ``failure_front`` (m, the same with failed-or-sawn particles), ``saw``
    (m), ``collapse_height`` (m, mean collapse times ``D_wl`` over failed, unsawn particles that
    collapsed by more than the threshold), ``marker{k}_ux``/``marker{k}_uy`` (m, displacement since
    t = 0 of the slab-base particle nearest to ``params.markers()[k]``). Per-frame particle field
    (with ``log_jp`` in the output): ``log_jp_ref``, the collapse reference (see
    :mod:`mpm_warp.post.fields`).

    Parameters
    ----------
    sim : Simulation
        Built from a PST scenario (``sim.scenario.scene`` a :class:`PSTParams`).
    """

    name = "pst"

    def __init__(self, sim):
        super().__init__()
        p = sim.scenario.scene
        if not isinstance(p, PSTParams):
            raise TypeError("PSTMonitor needs a scenario built by mpm_warp.scenes.pst.build")
        self.params = p
        self.sim = sim
        T = sim.model.T
        self.direction = 1.0 if p.saw.from_end == "left" else -1.0
        self.x_start = 0.0 if self.direction > 0 else float(p.length)
        self.bin = p.bin_width
        self.n_bins = p.n_bins
        self.length = float(p.length)
        self.t_start = p.saw_start
        self.cut_length = float(p.saw.cut_length)
        self.speed = float(p.saw.speed)
        self.d_wl = float(p.weak_layer_thickness)
        self.threshold = float(p.front.threshold)
        self.weak = WeakLayerTracker(sim, "weak_layer", self.t_start, p.weak_layer)
        wl = self.weak.group
        self.arrival = wp.full(self.n_bins, np.inf, dtype=wp.float64, device=sim.device)
        self.arrival_failure = wp.full(self.n_bins, np.inf, dtype=wp.float64, device=sim.device)
        self.saw_action = wp.launch(
            pst_action_kernel(T), wl.count,
            inputs=[wl.x, self.weak.log_jp, self.weak.ref, self.weak.failed, sim.clock, self.t_start, self.x_start,
                    self.direction, self.speed, self.cut_length, T(float(p.saw.log_jp)),
                    T(math.log(1.0 - self.threshold)), self.bin, self.arrival, self.arrival_failure],
            device=sim.device, record_cmd=True)
        # slab-base markers: the particle of the lowest slab row nearest to each station (middle of z)
        self.slab = sim.group_state("slab")
        x0 = self.slab.x0
        base = x0[:, 1] <= x0[:, 1].min() + 1e-6
        zmid = 0.5 * p.width_z
        idx = np.nonzero(base)[0]
        zc = idx[np.abs(x0[idx, 2] - zmid) <= np.abs(x0[idx, 2] - zmid).min() + 1e-6]
        self.markers = p.markers()
        #: index of each marker's particle within the slab group
        self.marker_index = zc[np.argmin(np.abs(x0[zc, 0][None, :] - self.markers[:, None]), axis=1)]

    # ----------------------------------------------------------------- contract
    def actions(self) -> list:
        """The weak layer's failure rule, then the saw and front trackers, every step."""
        return [self.weak.launch, self.saw_action]

    def units(self) -> dict[str, str]:
        """Units of the frame scalars."""
        u = {"front": "m", "failure_front": "m", "saw": "m", "collapse_height": "m"}
        for k in range(len(self.markers)):
            u[f"marker{k}_ux"] = "m"
            u[f"marker{k}_uy"] = "m"
        return u

    def measure(self, sim) -> dict[str, float]:
        """Frame scalars (see the class docstring)."""
        t = sim.time
        out = {"front": min(front_from_arrival(self.arrival.numpy(), t, self.bin), self.length),
               "failure_front": min(front_from_arrival(self.arrival_failure.numpy(), t, self.bin), self.length),
               "saw": self.saw_position(t)}
        c, flag = self.weak.collapse()
        sel = (c >= self.threshold) & (flag != SAWN)
        out["collapse_height"] = float(np.mean(c[sel]) * self.d_wl) if sel.any() else 0.0
        u = self.slab.x.numpy()[self.marker_index].astype(np.float64) - self.slab.x0[self.marker_index]
        for k in range(len(self.markers)):
            out[f"marker{k}_ux"] = float(u[k, 0])
            out[f"marker{k}_uy"] = float(u[k, 1])
        return out

    def device_state(self) -> dict[str, np.ndarray]:
        """Weak-layer reference and flags, front arrival times."""
        return {**{f"weak_layer/{k}": v for k, v in self.weak.state().items()},
                "arrival": self.arrival.numpy(), "arrival_failure": self.arrival_failure.numpy()}

    def load_device_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`device_state`."""
        self.weak.load_state(entries_below(state, "weak_layer/"))
        self.arrival.assign(state["arrival"])
        self.arrival_failure.assign(state["arrival_failure"])

    def result(self) -> dict:
        """Scene results from the series recorded so far (:func:`~mpm_warp.scenes.pst.analysis.pst_summary`)."""
        times, series = self.series_arrays()
        return pst_summary(self.params, times, series, arrival=self.arrival_times())

    # ------------------------------------------------------------------ queries
    def arrival_times(self) -> tuple[np.ndarray, np.ndarray]:
        """Bin centres (m from the cut end) and first-collapse times (s, inf where not collapsed)."""
        s = np.minimum((np.arange(self.n_bins) + 0.5) * self.bin, self.length)
        return s, self.arrival.numpy().copy()

    def saw_position(self, t: float) -> float:
        """Blade distance from the cut end (m) at time ``t`` (s)."""
        return float(np.clip(self.speed * (t - self.t_start), 0.0, self.cut_length))


def attach(sim) -> PSTMonitor:
    """Add the PST's monitor (saw, failure rule, front trackers, frame series) to ``sim``; return it."""
    return sim.add_monitor(PSTMonitor(sim))
