"""The shear-test monitor: the push of the loading block, the weak layer's bookkeeping, the frame series."""

from __future__ import annotations

import numpy as np
import warp as wp

from ..series import SeriesMonitor, entries_below
from ..weak_layer import ReferenceField, WeakLayerTracker, stored_calibration
from .analysis import analyze_shear_series
from .kernels import push_kernel
from .params import ShearTestParams

__all__ = ["ShearMonitor", "attach"]


class ShearMonitor(ReferenceField, SeriesMonitor):
    """The push, the weak layer's bookkeeping and the frame diagnostics of one shear test.

    Frame scalars: ``shear_displacement`` and ``normal_displacement`` (m, mean displacement of the
    loading block since t = 0), ``layer_slip`` (m, the weak layer's own shear displacement: the mean
    ``x`` displacement of its top lattice row less that of its bottom row, over their spacing times
    ``D_wl``; the block moves more, since it reaches the layer through grid nodes it shares with it),
    ``shear_strain`` (``u_x / D_wl``) and ``axial_strain`` (``-u_y / D_wl``, compaction positive; both
    since t = 0, settling adds ~0.1 %), ``shear_stress`` (Pa, the push's
    mean force over the last frame divided by the sample's area: the wall reaction of SI Note 2; it
    equals the substratum's shear reaction, by momentum balance), ``layer_shear_stress`` (Pa, mean
    Cauchy ``sigma_xy`` of the weak-layer particles from the device's stress field: lower, since the
    free ends carry none and part of the push reaches the layer's top through the shared grid
    nodes), ``interior_shear_stress`` (Pa, the same over the layer's interior, at least one layer thickness
    ``D_wl`` from both ends: the strength the material shows away from the traction-free ends, whose share
    lowers the whole sample's peak as ``1/L_s``), ``mises_q``/``p_mean`` (Pa, mean Mises stress and pressure
    of the weak layer, Cauchy), ``p_kirchhoff``
    (Pa, its mean Kirchhoff pressure, the yield function's),
    ``collapse`` (-, mean ``1 - J_P/J_P,ref`` of the layer), ``bond`` (-, the layer's mean bond
    ``1 - kappa/kappa_s``), ``bond_interior`` (-, the same away from the sample's ends: particles placed at
    least one layer thickness ``D_wl`` from both; the traction-free ends debond last, the closer to the end
    the later, so the whole layer's bond reaches zero later the finer the columns) and ``damaged_fraction``
    (-, bond at or below one half). Per-frame particle
    field (with ``log_jp`` in the output): ``log_jp_ref``, the collapse reference.
    """

    name = "shear_test"
    UNITS = {"shear_displacement": "m", "normal_displacement": "m", "layer_slip": "m", "shear_strain": "1",
             "axial_strain": "1",
             "layer_shear_stress": "Pa", "interior_shear_stress": "Pa", "shear_stress": "Pa", "mises_q": "Pa",
             "p_mean": "Pa", "p_kirchhoff": "Pa",
             "collapse": "1",
             "bond": "1", "bond_interior": "1", "damaged_fraction": "1"}

    def __init__(self, sim):
        super().__init__()
        self.params = p = self.scene_params(sim, ShearTestParams)
        self.calibration = stored_calibration(sim.scenario)
        self.sim = sim
        T = sim.model.T
        self.weak = WeakLayerTracker(sim, "weak_layer", p.push_start)
        self.load = sim.group_state("load")
        self.impulse = wp.zeros(1, dtype=wp.float64, device=sim.device)
        self.push = wp.launch(push_kernel(sim.model.dim, T), self.load.count,
                              inputs=[self.load.v, self.load.C, sim.clock, p.push_start, T(p.wall_speed),
                                      T(self.load.mass), self.impulse],
                              device=sim.device, record_cmd=True)
        self._last = (0.0, 0.0)  # (time, impulse) at the previous frame
        y0 = self.weak.group.x0[:, 1]
        self.top_row = np.nonzero(y0 >= y0.max() - 1e-9)[0]
        self.bottom_row = np.nonzero(y0 <= y0.min() + 1e-9)[0]
        self.row_span = float(y0.max() - y0.min())
        x0 = self.weak.group.x0[:, 0]
        d_wl = float(p.weak_layer_thickness)
        self.interior = np.nonzero((x0 >= x0.min() + d_wl) & (x0 <= x0.max() - d_wl))[0]

    def actions(self) -> list:
        """The weak layer's bookkeeping, then the push, every step."""
        return [self.weak.launch, self.push]

    def units(self) -> dict[str, str]:
        """Units of the frame scalars."""
        return dict(self.UNITS)

    def measure(self, sim) -> dict[str, float]:
        """Frame scalars (see the class docstring)."""
        t = sim.time
        u = (self.load.x.numpy().astype(np.float64) - self.load.x0).mean(axis=0)
        wl = self.weak.group
        p, q, sigma = sim.stresses(cauchy=True)
        sxy = sigma[wl.start:wl.end, 0, 1].astype(np.float64)
        p_k = sim.stresses()[0][wl.start:wl.end]
        c, _ = self.weak.collapse()
        bond = self.weak.bond()
        d_wl = float(self.params.weak_layer_thickness)
        imp = float(self.impulse.numpy()[0])
        t_last, imp_last = self._last
        self._last = (t, imp)
        push = (imp - imp_last) / (t - t_last) / self.params.sample_area if t > t_last else 0.0
        ux = self.weak.group.x.numpy()[:, 0].astype(np.float64) - self.weak.group.x0[:, 0]
        slip = (ux[self.top_row].mean() - ux[self.bottom_row].mean()) * d_wl / self.row_span
        return {"shear_displacement": float(u[0]), "normal_displacement": float(u[1]), "shear_stress": push,
                "layer_slip": float(slip),
                "shear_strain": float(u[0]) / d_wl, "axial_strain": -float(u[1]) / d_wl,
                "layer_shear_stress": float(np.mean(sxy)), "interior_shear_stress": float(np.mean(sxy[self.interior])),
                "mises_q": float(np.mean(q[wl.start:wl.end])), "p_mean": float(np.mean(p[wl.start:wl.end])),
                "p_kirchhoff": float(np.mean(p_k)),
                "collapse": float(np.mean(c)), "bond": float(np.mean(bond)),
                "bond_interior": float(np.mean(bond[self.interior])), "damaged_fraction": float(np.mean(bond <= 0.5))}

    def device_state(self) -> dict[str, np.ndarray]:
        """Weak-layer reference and damage times, the push impulse and the last frame's (time, impulse)."""
        return {**{f"weak_layer/{k}": v for k, v in self.weak.state().items()},
                "impulse": self.impulse.numpy(), "last": np.asarray(self._last, dtype=np.float64)}

    def load_device_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`device_state`."""
        self.weak.load_state(entries_below(state, "weak_layer/"))
        self.impulse.assign(state["impulse"])
        self._last = (float(state["last"][0]), float(state["last"][1]))

    def result(self) -> dict:
        """Shear-test results from the series recorded so far (:func:`analyze_shear_series`)."""
        times, series = self.series_arrays()
        return analyze_shear_series(self.params, self.calibration, times, series)


def attach(sim) -> ShearMonitor:
    """Add the shear test's monitor (push, weak-layer bookkeeping, frame series) to ``sim``; return it."""
    return sim.add_monitor(ShearMonitor(sim))
