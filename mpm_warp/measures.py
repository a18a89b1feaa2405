"""Energies and stresses of a run's particles, computed on the device from its state between steps.

The kernels are ``kernels/diagnostics.py`` (``energy_kernel``, ``stress_kernel``), one launch per
particle group with that group's material; their host mirror is :mod:`mpm_warp.stress`.
:class:`~mpm_warp.simulation.Simulation` answers ``energies()`` and ``stresses()`` with them.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .kernels.diagnostics import energy_kernel, stress_kernel
from .model import Model, State
from .particle_groups import material_params

__all__ = ["ParticleMeasures"]


class ParticleMeasures:
    """The energies and stresses of ``state``'s particles (a state of ``model``), with their device buffers."""

    def __init__(self, model: Model, state: State):
        self.model = model
        self.state = state
        self.device = model.device
        self._energy = wp.zeros(2, dtype=wp.float64, device=self.device)
        self._empty = wp.zeros(0, dtype=model.T, device=self.device)  # elastic groups: no plastic volume

    def _hzz_of(self, g) -> wp.array:
        """``hzz`` of group ``g``'s particles, or an empty array (elastic or 3D: ``F_E,zz`` not stored)."""
        s = self.state
        if s.hzz is None or g.plastic_start < 0:
            return self._empty
        return s.hzz[g.plastic_start:g.plastic_start + g.count]

    def _kappa_of_cracking(self, g) -> wp.array:
        """``kappa`` of a cracking group's particles (their softened stress), else an empty array."""
        if g.material.model != "tensile_cracking":
            return self._empty
        return self.state.kappa[g.kappa_start:g.kappa_start + g.count]

    def energies(self) -> dict[str, float]:
        """Kinetic and elastic energy (J; J/m of depth in 2D) of the current state."""
        self._energy.zero_()
        T = self.model.T
        s = self.state
        for g in self.model.groups:
            sl = slice(g.start, g.end)
            hz = self._hzz_of(g)
            wp.launch(energy_kernel(self.model.dim, T), g.count,
                      inputs=[s.v[sl], s.H[sl], hz, self._kappa_of_cracking(g), T(g.mass), T(g.vol0),
                              material_params(g.material, T), self._energy], device=self.device)
        e = self._energy.numpy()
        return {"kinetic_energy": float(e[0]), "elastic_energy": float(e[1])}

    def stresses(self, cauchy: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Pressure p and Mises stress q (Pa, Kirchhoff, compression positive) of every particle and,
        with ``cauchy``, the Cauchy stress tensor (N, 3, 3) (Pa, tension positive; plane strain: in-plane
        block and ``sigma_zz``)."""
        T = self.model.T
        n = self.model.n_particles
        s = self.state
        p = wp.zeros(n, dtype=T, device=self.device)
        q = wp.zeros(n, dtype=T, device=self.device)
        sig = wp.zeros(n, dtype=wp.types.matrix((3, 3), T), device=self.device) if cauchy else None
        for g in self.model.groups:
            sl = slice(g.start, g.end)
            hz = self._hzz_of(g)
            ljp = s.log_jp[g.plastic_start:g.plastic_start + g.count] if g.plastic_start >= 0 else self._empty
            wp.launch(stress_kernel(self.model.dim, T), g.count,
                      inputs=[s.H[sl], hz, ljp, self._kappa_of_cracking(g), material_params(g.material, T), int(cauchy),
                              p[sl], q[sl], sig[sl] if cauchy else None],
                      device=self.device)
        return p.numpy(), q.numpy(), sig.numpy() if cauchy else None
