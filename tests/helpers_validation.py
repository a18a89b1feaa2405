"""Shared helpers of the elastic and wall validation tests (docs/validation.md).

Set-ups with closed-form answers (a quasi-1D fixed-free bar, a block on a
floor), measurements (centre-of-mass velocity, zero crossings, fitted orders)
and the Hencky Cauchy stress computed in numpy from ``F_E``, independently of
the kernels.
"""

from __future__ import annotations

import math

import numpy as np
from helpers_device import DEVICE  # noqa: F401  (re-exported: MPM_WARP_TEST_DEVICE)

import mpm_warp as mw
from mpm_warp.studies.convergence import observed_order  # noqa: F401  (re-exported for the tests)
from mpm_warp.validation import (  # noqa: F401  (re-exported for the tests)
    bar_period,
    com_velocity,
    fixed_free_bar,
    zero_crossings,
)


# ------------------------------------------------------------------ measuring
def com_position(sim: mw.Simulation) -> np.ndarray:
    """Mass-weighted mean particle position (m), shape (3,)."""
    x = sim.state.x.numpy().astype(np.float64)
    s = np.zeros(3)
    m = 0.0
    for g in sim.model.groups:
        s += g.mass * x[g.start:g.end].sum(axis=0)
        m += g.mass * g.count
    return s / m


def total_mass(sim: mw.Simulation) -> float:
    """Mass of all particles (kg)."""
    return float(sum(g.mass * g.count for g in sim.model.groups))


def grid_after_one_step(sim: mw.Simulation):
    """Take one step and return the grid it produced.

    Returns ``(x_node (nx, ny, nz, 3) m, m_node (nx, ny, nz) kg, v_node (nx, ny, nz, 3) m/s)``:
    node positions, nodal masses and the nodal velocities after the grid
    update (gravity and walls applied), read from the stepper's grid buffers
    (on the CPU one scatter copy per thread: masses are summed over the copies,
    copy 0 holds the velocity).
    """
    st = sim.stepper
    st.set_frame_end(sim.time + 1.0e6)
    st.steps(1)
    if hasattr(st, "grid_m_all"):
        m = st.grid_m_all.numpy().astype(np.float64).sum(axis=0)
    else:
        m = st.grid_m.numpy().astype(np.float64)
    v = st.grid_p.numpy().astype(np.float64)
    idx = np.stack(np.meshgrid(*[np.arange(n) for n in m.shape], indexing="ij"), axis=-1)
    x = np.asarray(sim.model.origin) + idx * sim.model.dx
    return x, m, v


def apic_momenta(sim: mw.Simulation):
    """Linear (kg m/s) and angular momentum (kg m^2/s, about the origin) of the first material group's particles,
    in float64, the angular one with APIC's spin term ``m D (C - C^T)``, ``D = dx^2 / 4`` (quadratic B-splines):
    a scalar (about z) in 2D, a vector in 3D."""
    m = sim.model.groups[0].mass
    x = sim.state.x.numpy().astype(np.float64)
    v = sim.state.v.numpy().astype(np.float64)
    C = sim.state.C.numpy().astype(np.float64)
    D = sim.model.dx ** 2 / 4.0
    P = m * v.sum(axis=0)
    if x.shape[1] == 2:
        return P, m * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]).sum() + m * D * (C[:, 1, 0] - C[:, 0, 1]).sum()
    spin = np.stack([C[:, 2, 1] - C[:, 1, 2], C[:, 0, 2] - C[:, 2, 0], C[:, 1, 0] - C[:, 0, 1]], axis=1)
    return P, m * np.cross(x, v).sum(axis=0) + m * D * spin.sum(axis=0)


# ------------------------------------------------------------------- set-ups
def block_on_floor(*, kind: str, friction: float = 0.0, gravity=(0.0, -9.81, 0.0), gravity_ramp: float = 0.0,
                   velocity=(0.0, 0.0, 0.0), floor_velocity=(0.0, 0.0, 0.0), floor_ramp: float = 0.0,
                   end: float = 0.1, frame_interval: float = 0.005, E: float = 1.0e7, nu: float = 0.25,
                   density: float = 1000.0, dx: float = 0.02, length_x: float = 0.8, block_x=(0.1, 0.3),
                   block_h: float = 0.1, extra_walls=(), precision: str = "float32") -> mw.Scenario:
    """A stiff block resting on a floor wall ``y = 0`` (normal +y), plane strain in z.

    The block fills ``block_x`` along x, ``[0, block_h]`` along y and one cell
    along z between slip z faces (the only box walls: ``z_lo``, ``z_hi`` come
    first in the wall list, then the ``floor``, then ``extra_walls``). The
    defaults (E 1e7 Pa, rho 1000 kg/m^3, dx 2 cm) give c_p = 110 m/s and a
    vertical period 4 h / c_p = 3.6 ms, far below the times measured.
    """
    floor = mw.Wall((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), kind=kind, friction=friction, velocity=floor_velocity,
                    ramp_time=floor_ramp, name="floor")
    return mw.Scenario(
        name="block_on_floor",
        domain=mw.Domain((0.0, 0.0, 0.0), (length_x, 2 * block_h, dx), dx, boundary="slip", boundary_faces="z"),
        time=mw.TimeControl(end=end, frame_interval=frame_interval, gravity=tuple(gravity),
                            gravity_ramp=gravity_ramp),
        materials={"block": mw.Elastic(E, nu, density)},
        blocks=(mw.Block("block", (block_x[0], 0.0, 0.0), (block_x[1], block_h, dx), velocity=tuple(velocity)),),
        walls=(floor, *extra_walls),
        precision=precision,
    )


def slope_gravity(theta_deg: float, g: float = 9.81) -> tuple[float, float, float]:
    """Gravity of a slope of ``theta_deg`` over the flat floor ``y = 0``: downhill is +x."""
    th = math.radians(theta_deg)
    return (g * math.sin(th), -g * math.cos(th), 0.0)
