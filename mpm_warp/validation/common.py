"""Measurements and the run record shared by the validation problems."""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..errors import InvalidArgument
from ..simulation import RunResult, Simulation

G = 9.81
"""Gravitational acceleration of the set-ups (m/s^2)."""


# ------------------------------------------------------------------ measuring
def com_velocity(sim: Simulation) -> np.ndarray:
    """Mass-weighted mean particle velocity (m/s), shape (dim,)."""
    v = sim.state.v.numpy().astype(np.float64)
    p = np.zeros(v.shape[1])
    m = 0.0
    for g in sim.model.groups:
        p += g.mass * v[g.start:g.end].sum(axis=0)
        m += g.mass * g.count
    return p / m


def zero_crossings(t, y, cubic: bool = False) -> np.ndarray:
    """Times (s) where the sampled signal ``y(t)`` changes sign.

    Linear interpolation between the two samples around each sign change, or with
    ``cubic`` the root of the cubic through the four samples around it (linear at
    the ends of the record): for a sine sampled 20 times a period with a 1 %
    third harmonic, the period from two crossings is then within ~1e-5 (linear:
    ~2e-4).
    """
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    i = np.nonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)[0]
    z = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    if cubic:
        for n, k in enumerate(i):
            if 1 <= k <= len(t) - 3:
                h = t[k + 1] - t[k]
                r = np.roots(np.polyfit(t[k - 1:k + 3] - t[k], y[k - 1:k + 3], 3))
                r = r[np.isreal(r)].real
                r = r[(r >= 0.0) & (r <= h)]
                if len(r):
                    z[n] = t[k] + r[np.argmin(np.abs(t[k] + r - z[n]))]
    return z


def _cells(name: str, length: float, dx: float) -> int:
    """``length / dx`` as an integer, or InvalidArgument (blocks must fill whole cells)."""
    if not (isinstance(dx, (int, float)) and math.isfinite(dx) and dx > 0):
        raise InvalidArgument("dx", dx, "a finite number > 0 (m)")
    n = round(length / dx)
    if n < 1 or abs(n * dx - length) > 1e-9 * length:
        raise InvalidArgument("dx", dx, f"{name} / dx a whole number ({name} = {length:g} m)")
    return n


def _record(problem: str, sim: Simulation, res: RunResult, dx: float, cfl: float, dt, measured: float,
            reference: float, signed_error: float, details: dict) -> dict:
    """The fixed record of one validation run (see module docstring)."""
    steps = int(res.steps)
    return {
        "problem": problem, "dx": float(dx), "cfl": float(cfl), "dt": None if not dt else float(dt),
        "error": abs(float(signed_error)), "signed_error": float(signed_error),
        "measured": float(measured), "reference": float(reference),
        "wall_time_s": float(res.wall_time), "steps": steps, "n_particles": int(res.n_particles),
        "particle_steps_per_s": float(res.particle_steps_per_s), "device": str(res.device),
        "precision": sim.scenario.precision, "warp_version": str(wp.config.version),
        "n_threads": int(sim.stepper.n_threads), "sim_time_s": float(sim.time),
        "dt_mean_s": float(sim.time / steps) if steps else float("nan"), "details": details,
    }
