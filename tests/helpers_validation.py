"""Shared helpers of the elastic and wall validation tests (VALIDATION.md).

Set-ups with closed-form answers (a quasi-1D fixed-free bar, a block on a
floor), measurements (centre-of-mass velocity, zero crossings, fitted orders)
and the Hencky Cauchy stress computed in numpy from ``F_E``, independently of
the kernels.
"""

from __future__ import annotations

import math

import numpy as np

import mpm_warp as mw

DEVICE = "cpu"


# ------------------------------------------------------------------ measuring
def com_velocity(sim: mw.Simulation) -> np.ndarray:
    """Mass-weighted mean particle velocity (m/s), shape (3,)."""
    v = sim.state.v.numpy().astype(np.float64)
    p = np.zeros(3)
    m = 0.0
    for g in sim.model.groups:
        p += g.mass * v[g.start:g.end].sum(axis=0)
        m += g.mass * g.count
    return p / m


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


def zero_crossings(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Times where the sampled signal ``y(t)`` changes sign (linear interpolation)."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    i = np.nonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)[0]
    return t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])


def observed_order(h, err) -> float:
    """Slope of ``log(err)`` against ``log(h)`` (least squares, as Devito's tests)."""
    return float(np.polyfit(np.log(np.asarray(h, float)), np.log(np.asarray(err, float)), 1)[0])


def hencky_cauchy_stress(F: np.ndarray, mu: float, lam: float) -> np.ndarray:
    """Cauchy stress (Pa, tension positive) of Hencky St Venant-Kirchhoff (MODEL.md 1).

    ``F = U diag(s) V^T``, ``eps = ln s``, ``tau = U diag(2 mu eps + lam tr eps) U^T``,
    ``sigma = tau / det F``. ``F`` has shape (n, 3, 3); computed in float64.
    """
    F = np.asarray(F, dtype=np.float64)
    U, s, _ = np.linalg.svd(F)
    eps = np.log(s)
    tau_p = 2.0 * mu * eps + lam * eps.sum(axis=-1, keepdims=True)
    tau = np.einsum("nij,nj,nkj->nik", U, tau_p, U)
    return tau / np.linalg.det(F)[:, None, None]


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


# ------------------------------------------------------------------- set-ups
def fixed_free_bar(*, length: float, E: float, nu: float, density: float, v0: float, dx: float,
                   width_cells: int = 1, periods: float = 1.35, samples_per_period: int = 200,
                   precision: str = "float32") -> tuple[mw.Scenario, float]:
    """Quasi-1D bar along x, fixed at x = 0, free at x = ``length``, in its first mode.

    The cross-section is ``width_cells`` cells square between slip walls on the
    y and z faces (lateral confinement: uniaxial strain); a sticky wall at
    x = 0 fixes that end; the domain extends 4 cells past the free end. The
    initial velocity is ``v0 sin(pi x / (2 L))`` along x, no gravity. Returns the
    scenario and the exact period ``4 L / c_p`` (s), with
    ``c_p = sqrt((lam + 2 mu) / rho)`` (``sqrt(E / rho)`` when ``nu = 0``).
    """
    mat = mw.Elastic(E, nu, density)
    period = 4.0 * length / mat.p_wave_speed
    w = width_cells * dx

    def mode1(x):
        v = np.zeros_like(x)
        v[:, 0] = v0 * np.sin(np.pi * x[:, 0] / (2.0 * length))
        return v

    sc = mw.Scenario(
        name="fixed_free_bar",
        domain=mw.Domain((0.0, 0.0, 0.0), (length + 4 * dx, w, w), dx, boundary="slip", boundary_faces="yz"),
        time=mw.TimeControl(end=periods * period, frame_interval=period / samples_per_period,
                            gravity=(0.0, 0.0, 0.0)),
        materials={"bar": mat},
        blocks=(mw.Block("bar", (0.0, 0.0, 0.0), (length, w, w), velocity=mode1),),
        walls=(mw.Wall((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), kind="sticky", name="fixed_end"),),
        precision=precision,
    )
    return sc, period


def bar_period(sc: mw.Scenario) -> tuple[float, np.ndarray, np.ndarray, mw.Simulation]:
    """Run a :func:`fixed_free_bar` scenario; return (period (s), t, v_com_x, sim).

    The period is measured between the first and third zero crossings of the
    centre-of-mass velocity (one full period, at about T/4 and 5T/4).
    """
    sim = mw.Simulation(sc, device=DEVICE)
    t = [0.0]
    v = [com_velocity(sim)[0]]

    def sample(s, frame):
        t.append(s.time)
        v.append(com_velocity(s)[0])

    sim.run(None, callback=sample)
    t = np.array(t)
    v = np.array(v)
    z = zero_crossings(t, v)
    assert len(z) >= 3, f"expected three zero crossings of the COM velocity, got {z}"
    return float(z[2] - z[0]), t, v, sim


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
