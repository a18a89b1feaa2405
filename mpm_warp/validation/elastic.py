"""Elastic reference problems: the fixed-free axial bar and the column under self-weight."""

from __future__ import annotations

import math

import numpy as np

from ..config import Block, Domain, Scenario, TimeControl
from ..errors import MPMError
from ..materials import Elastic
from ..simulation import Simulation
from ..stress import cauchy_stress
from ..walls import Wall
from .common import G, _cells, _record, com_velocity, zero_crossings


# ------------------------------------------------------------------ axial bar
def fixed_free_bar(*, length: float, E: float, nu: float, density: float, v0: float, dx: float,
                   width_cells: int = 1, periods: float = 1.35, samples_per_period: int = 200,
                   cfl: float = 0.4, dt: float | None = None,
                   precision: str = "float32", dimension: int = 3) -> tuple[Scenario, float]:
    """Quasi-1D bar along x, fixed at x = 0, free at x = ``length``, in its first mode.

    The cross-section is ``width_cells`` cells square (``width_cells`` cells
    high in 2D, ``dimension = 2``: plane strain) between slip walls on the y
    (and z) faces (lateral confinement: uniaxial strain); a sticky wall at
    x = 0 fixes that end; the domain extends 4 cells past the free end. The
    initial velocity is ``v0 sin(pi x / (2 L))`` (m/s) along x, no gravity.

    Returns
    -------
    (Scenario, float)
        The scenario and the exact period ``4 L / c_p`` (s),
        ``c_p = sqrt((lam + 2 mu) / rho)`` (``sqrt(E / rho)`` when ``nu = 0``).
    """
    mat = Elastic(E, nu, density)
    period = 4.0 * length / mat.p_wave_speed
    w = width_cells * dx

    def mode1(x):
        v = np.zeros_like(x)
        v[:, 0] = v0 * np.sin(np.pi * x[:, 0] / (2.0 * length))
        return v

    d = dimension
    sc = Scenario(
        name="fixed_free_bar",
        domain=Domain((0.0,) * d, (length + 4 * dx, w, w)[:d], dx, boundary="slip", boundary_faces="yz",
                      dimension=d),
        time=TimeControl(end=periods * period, frame_interval=min(period / samples_per_period, periods * period),
                         cfl=cfl, dt=dt or 0.0, gravity=(0.0,) * d),
        materials={"bar": mat},
        blocks=(Block("bar", (0.0,) * d, (length, w, w)[:d], velocity=mode1),),
        walls=(Wall((0.0,) * d, (1.0, 0.0, 0.0)[:d], kind="sticky", name="fixed_end"),),
        precision=precision,
    )
    return sc, period


def _run_bar(sc: Scenario, device, n_threads, cubic: bool = False):
    sim = Simulation(sc, device=device, n_threads=n_threads)
    t = [0.0]
    v = [com_velocity(sim)[0]]

    def sample(s, frame):
        t.append(s.time)
        v.append(com_velocity(s)[0])

    res = sim.run(None, callback=sample)
    t = np.array(t)
    v = np.array(v)
    z = zero_crossings(t, v, cubic=cubic)
    if len(z) < 3:
        raise MPMError(f"axial bar: expected three zero crossings of the centre-of-mass velocity, got {z.tolist()}")
    return float(z[2] - z[0]), t, v, sim, res


def bar_period(sc: Scenario, device: str | None = "cpu",
               n_threads: int | None = None) -> tuple[float, np.ndarray, np.ndarray, Simulation]:
    """Run a :func:`fixed_free_bar` scenario; return (period (s), t (s), v_com_x (m/s), sim).

    The period is measured between the first and third zero crossings of the
    centre-of-mass velocity (one full period, at about T/4 and 5T/4).
    """
    return _run_bar(sc, device, n_threads)[:4]


def axial_bar(dx: float = 1.0, *, cfl: float = 0.4, dt: float | None = None, precision: str = "float32",
              device: str | None = None, n_threads: int | None = None, length: float = 25.0, E: float = 100.0,
              density: float = 1.0, v0: float = 0.1, dimension: int = 3) -> dict:
    """Fixed-free axial bar, mode 1: period error (docs/validation.md "Elastic").

    L = 25, E = 100, rho = 1, nu = 0, v0 = 0.1 by default: ``T = 4 L / c = 10 s``.
    One cell across between slip walls, sticky wall at x = 0.

    Parameters
    ----------
    dx : float
        Grid spacing (m); ``length / dx`` must be a whole number. The tests use 1 and 0.5.
    cfl : float
        CFL factor of the automatic step (ignored when ``dt`` is given).
    dt : float or None
        Fixed step (s); None for the automatic step.
    precision : {"float32", "float64"}
    device : str or None
        ``"cpu"``, ``"cuda"``, ``"cuda:N"`` or None (see :class:`Simulation`).
    n_threads : int or None
        CPU threads (see :class:`Simulation`).
    length, E, density, v0 : float
        Bar length (m), Young's modulus (Pa), density (kg/m^3), velocity amplitude (m/s).
    dimension : {2, 3}
        2 runs the true 2D plane-strain kernels.

    Returns
    -------
    dict
        The record of the module docstring; ``error = |T / (4 L / c) - 1|``
        (measured and reference periods in s), the period between the first and
        third zero crossings of the centre-of-mass velocity; ``details`` holds
        the frames per period and the centre-of-mass velocity amplitude ratios of
        the first swing and the return.
    """
    _cells("length", length, dx)
    # sampling: 200 frames a period, fewer (down to 20) where that would leave less than 4 steps a frame, so
    # that the step is set by the CFL rule (or dt), not by the frame times; crossings by cubic interpolation
    T_c = 4.0 * length / math.sqrt(E / density)
    spp = int(min(200, max(20, T_c / (4.0 * (dt or cfl * dx / math.sqrt(E / density))))))
    sc, T_exact = fixed_free_bar(length=length, E=E, nu=0.0, density=density, v0=v0, dx=dx, cfl=cfl, dt=dt,
                                 samples_per_period=spp, precision=precision, dimension=dimension)
    T, t, v, sim, res = _run_bar(sc, device, n_threads, cubic=True)
    amp = 2.0 / math.pi * v0
    details = {"samples_per_period": spp, "com_velocity_min_over_amplitude": float(-v.min() / amp),
               "com_velocity_return_over_amplitude": float(v[t > 0.75 * T].max() / amp)}
    return _record("axial_bar", sim, res, dx, cfl, dt, T, T_exact, T / T_exact - 1.0, details)


# ----------------------------------------------------- column under self-weight
def column_scenario(dx: float, *, height: float = 1.0, E: float = 1.0e6, nu: float = 0.3, density: float = 250.0,
                    cfl: float = 0.4, dt: float | None = None, precision: str = "float64",
                    dimension: int = 3) -> tuple[Scenario, dict]:
    """Column of ``height``, one cell square (one cell wide in 2D), between slip faces; gravity ramped, then held.

    A linear ramp lasting ten mode-1 periods ``T1 = 4 H / c_p`` leaves almost no free
    vibration of the fixed-free column (all its modes have periods ``T1 / (2k - 1)``);
    the hold lasts two periods, and the stress is averaged over the last one.
    Returns the scenario and ``info``: ``T1`` (s), ``ramp`` (s), ``height`` (m).
    """
    mat = Elastic(E, nu, density)
    T1 = 4.0 * height / mat.p_wave_speed
    ramp = 10.0 * T1
    d = dimension
    sc = Scenario(
        name="column_self_weight",
        domain=Domain((0.0,) * d, (dx, height + 2 * dx, dx)[:d], dx, boundary="slip", boundary_faces="xyz",
                      dimension=d),
        time=TimeControl(end=ramp + 2.0 * T1, frame_interval=T1 / 20.0, cfl=cfl, dt=dt or 0.0,
                         gravity=(0.0, -G, 0.0)[:d], gravity_ramp=ramp),
        materials={"snow": mat},
        blocks=(Block("snow", (0.0,) * d, (dx, height, dx)[:d]),),
        precision=precision,
    )
    return sc, {"T1": T1, "ramp": ramp, "height": height}


def self_weight_column(dx: float = 1.0 / 16.0, *, cfl: float = 0.4, dt: float | None = None,
                       precision: str = "float64", device: str | None = None, n_threads: int | None = None,
                       height: float = 1.0, E: float = 1.0e6, nu: float = 0.3, density: float = 250.0,
                       dimension: int = 3) -> dict:
    """Column under self-weight with lateral rollers: ``sigma_yy(Y) = -rho g (H - Y)`` (docs/validation.md).

    Hencky Cauchy stress computed in numpy from ``F_E``, averaged over the last
    mode-1 period of the hold (:func:`column_scenario`), ``Y`` the particle's
    reference height.

    Parameters
    ----------
    dx : float
        Grid spacing (m); ``height / dx`` must be a whole number (the tests use H/8, H/16, H/32).
    cfl, dt, precision, device, n_threads, dimension
        As :func:`axial_bar`. float64 by default (float32 keeps F_E - I, so its
        round-off is that of the strain, not of the stretch).
    height, E, nu, density : float
        H (m), Young's modulus (Pa), Poisson's ratio, density (kg/m^3).

    Returns
    -------
    dict
        The record of the module docstring; ``error`` is the RMS over the
        particles away from the floor (``Y > H / 4``) of
        ``(sigma_yy + rho g (H - Y)) / (rho g H)`` (so ``signed_error = error``);
        ``measured`` the mean ``-sigma_yy`` of those particles (Pa), ``reference``
        the mean of ``rho g (H - Y)`` over them (Pa); ``details`` adds the RMS over
        all particles and the largest error in the cell next to the floor (a
        boundary layer a fixed number of cells thick, see the tests).
    """
    _cells("height", height, dx)
    sc, info = column_scenario(dx, height=height, E=E, nu=nu, density=density, cfl=cfl, dt=dt, precision=precision,
                               dimension=dimension)
    mat = sc.materials["snow"]
    t_avg = info["ramp"] + info["T1"] * (1.0 + 1e-9)
    sim = Simulation(sc, device=device, n_threads=n_threads)
    samples = []

    def sample(s, frame):
        if s.time > t_avg:
            samples.append(cauchy_stress(s.state.elastic_deformation_gradient(), mat.mu, mat.lam)[:, 1, 1])

    res = sim.run(None, callback=sample)
    syy = np.mean(samples, axis=0)
    Y = sim.x0[:, 1]
    W = density * G * (height - Y)
    err = (syy + W) / (density * G * height)
    inner = Y > 0.25 * height
    rms = float(np.sqrt(np.mean(err[inner] ** 2)))
    details = {"rms_all_particles": float(np.sqrt(np.mean(err**2))), "floor_cell_max": float(np.abs(err[Y < dx]).max()),
               "samples": len(samples)}
    return _record("self_weight_column", sim, res, dx, cfl, dt, float(-syy[inner].mean()), float(W[inner].mean()),
                   rms, details)
