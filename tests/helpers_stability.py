"""Shared helpers of the stability tests (``tests/test_stability_*.py``).

Readers of a simulation's state on the host (sigma_yy by the float64 mirror,
particle masses, energies with the gravitational potential), a random
rotation, the check that a blow-up error names step, particle, field and
cause, and the elastic snow of the lone-particle scenes.
"""

from __future__ import annotations

import numpy as np

import mpm_warp as mw
from mpm_warp.stress import cauchy_stress

G = 9.81   # m/s^2

#: Elastic snow (E 1 MPa, nu 0.3, rho 250 kg/m^3) of the lone-particle scenes.
SNOW = mw.Elastic(1.0e6, 0.3, 250.0)


def rotation(rng: np.random.Generator) -> np.ndarray:
    """A random proper rotation (det +1)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1.0
    return q


def cauchy_yy(sim: mw.Simulation) -> np.ndarray:
    """sigma_yy (Pa, tension positive) of every particle, from F_E by the float64 host mirror."""
    F = sim.state.elastic_deformation_gradient()
    out = np.zeros(len(F))
    for g in sim.model.groups:
        out[g.start:g.end] = cauchy_stress(F[g.start:g.end], g.material.mu, g.material.lam)[:, 1, 1]
    return out


def masses(sim: mw.Simulation) -> np.ndarray:
    """Mass (kg) of every particle, from its group."""
    m = np.zeros(sim.model.n_particles)
    for g in sim.model.groups:
        m[g.start:g.end] = g.mass
    return m


def total_energy(sim: mw.Simulation, mass: np.ndarray, g: float = G, y0: float = 0.0) -> tuple[float, float, float]:
    """(kinetic, elastic, gravitational) energy (J); the potential is ``m g (y - y0)`` in float64."""
    e = sim.energies()
    y = sim.state.x.numpy().astype(np.float64)[:, 1]
    return e["kinetic_energy"], e["elastic_energy"], float((mass * g * (y - y0)).sum())


def check_blowup(e: mw.SimulationBlowUp, n_particles: int) -> None:
    """A blow-up error names a step, a particle index, a field and a cause."""
    assert e.step > 0
    assert 0 <= e.particle < n_particles
    assert e.field in ("v", "x/v/F", "F")
    assert e.cause
    msg = str(e)
    assert f"step {e.step}" in msg and f"particle {e.particle}" in msg and e.field in msg
