"""The block scenes of the throughput benchmarks, as every engine builds them.

The elastic block: a unit box (square in 2D) with slip faces three cells in from the grid edge, the
block ``[0.25, 0.75]^dim`` with 2 particles per cell and axis (``n_grid^dim`` particles), Hencky
elastic E = 1e5 Pa, nu = 0.3, rho = 1000 kg/m^3, gravity along -y, in free fall from rest, with
the fixed step :func:`elastic_time_step` (1e-4 s, or one cell per step at the P-wave speed on grids
finer than 1.16 mm, where 1e-4 s would exceed the engine's stability limit). The plastic block: the same lattice of
the struck Cam-Clay snow of :mod:`.plastic_block`. ``dim = 2`` is plane strain (per metre of depth).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..config import Block, Domain, Output, Scenario, TimeControl
from ..materials import CamClaySnow, Elastic
from ..simulation import Simulation
from . import plastic_block as pb

__all__ = ["ELASTIC_E", "ELASTIC_NU", "ELASTIC_RHO", "ELASTIC_DT", "GRAVITY_Y", "elastic_time_step", "block_scenario",
           "plastic_material", "block_simulation", "default_warmup", "expected_com_y", "block_positions",
           "initial_state"]

#: Elastic block: Young's modulus (Pa), Poisson ratio, density (kg/m^3), fixed step (s).
ELASTIC_E, ELASTIC_NU, ELASTIC_RHO, ELASTIC_DT = 1.0e5, 0.3, 1000.0, 1.0e-4
#: Gravity along y (m/s^2), both blocks.
GRAVITY_Y = pb.GRAVITY_Y


def elastic_time_step(n_grid: int) -> float:
    """Fixed step (s) of the elastic block on ``n_grid`` cells: ``min(ELASTIC_DT, dx / c_p)``.

    ``dx / c_p`` (one cell per step at the P-wave speed, 11.6 m/s) lies under the engine's stability
    limit 1.11 dx / c_p (:data:`mpm_warp.time_step.STABLE_DT`); it is smaller than 1e-4 s from ``n_grid``
    = 862 on, so every CPU size (at most 512 cells per axis) keeps 1e-4 s.
    """
    c_p = Elastic(ELASTIC_E, ELASTIC_NU, ELASTIC_RHO).p_wave_speed
    return min(ELASTIC_DT, (1.0 / n_grid) / c_p)


def block_scenario(n_grid: int, material=None, boundary: str = "slip", precision: str = "float32",
                   dt: float = ELASTIC_DT, dim: int = 3) -> Scenario:
    """The elastic block (module docstring) as a Scenario; ``material`` replaces its elastic material."""
    dx = 1.0 / n_grid
    mat = material or Elastic(ELASTIC_E, ELASTIC_NU, ELASTIC_RHO)
    return Scenario(
        name=f"block{n_grid}_{dim}d",
        domain=Domain((3 * dx,) * dim, (1 - 3 * dx,) * dim, dx, boundary=boundary, dimension=dim),
        time=TimeControl(end=1.0, frame_interval=1.0, dt=dt),
        materials={"m": mat},
        blocks=(Block("m", (0.25,) * dim, (0.75,) * dim),),
        precision=precision,
    )


def plastic_material() -> CamClaySnow:
    """The Cam-Clay snow of :mod:`.plastic_block`."""
    return CamClaySnow(pb.YOUNG_E, pb.POISSON_NU, pb.DENSITY, M=pb.M_CSL, beta=pb.BETA, xi=pb.XI,
                       p0_ini=pb.P0_INI, p0_floor_ratio=pb.P0_FLOOR_RATIO)


def block_simulation(dim: int, material: str, n_grid: int, device: str = "cpu", n_threads: int | None = 1,
                     track_yield: bool = False, elastic_twin: bool = False) -> Simulation:
    """The block of the throughput benchmarks as an mpm_warp Simulation.

    Parameters
    ----------
    dim : {2, 3}
        2 is plane strain (``[domain] dimension = 2``).
    material : {"elastic", "plastic"}
        The elastic block (:func:`block_scenario`) or the struck Cam-Clay block of :mod:`.plastic_block`
        (its ``v`` and exact ``C`` assigned).
    n_grid : int
        Cells per axis of the unit box (``n_grid**dim`` particles).
    track_yield : bool
        Cam-Clay only: keep the ``yielded`` output field (diagnostics).
    elastic_twin : bool
        Cam-Clay scene with an elastic material of the same E, nu, rho: the same step with plasticity
        compiled out (no yield check, no return).
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    if material == "elastic":
        return Simulation(block_scenario(n_grid, dt=elastic_time_step(n_grid), dim=dim), device=device,
                          n_threads=n_threads)
    if material != "plastic":
        raise ValueError(f"material must be 'elastic' or 'plastic', got {material!r}")
    pb.check_n_grid(n_grid)
    mat = Elastic(pb.YOUNG_E, pb.POISSON_NU, pb.DENSITY) if elastic_twin else plastic_material()
    sc = block_scenario(n_grid, material=mat, dt=pb.time_step(n_grid), dim=dim)
    if track_yield:
        sc = dataclasses.replace(sc, output=Output(fields=("x", "yielded")))
    sim = Simulation(sc, device=device, n_threads=n_threads)
    x0 = sim.state.x.numpy()
    sim.state.v.assign(pb.initial_velocity(x0).astype(sim.model.np_dtype))
    sim.state.C.assign(pb.initial_velocity_gradient(x0).astype(sim.model.np_dtype))
    return sim


def default_warmup(material: str, n_grid: int) -> int:
    """Untimed steps before timing: 3 for the elastic block, :func:`.plastic_block.warmup_steps` for Cam-Clay."""
    return pb.warmup_steps(n_grid) if material == "plastic" else 3


def expected_com_y(steps: int, dt: float = ELASTIC_DT, y0: float = 0.5) -> float:
    """Centre-of-mass height (m) of the freely falling elastic block after ``steps`` steps from rest.

    MLS-MPM conserves linear momentum and the block does not reach the walls in a short run, so
    symplectic Euler gives ``y0 + g dt^2 steps (steps + 1) / 2``.
    """
    return y0 + GRAVITY_Y * dt * dt * steps * (steps + 1) / 2.0


def block_positions(n_grid: int, dim: int = 3) -> np.ndarray:
    """Initial particle lattice of the block: ``(n_grid**dim, dim)`` float32 positions (m).

    ``x = 0.25 + (i + 0.5) dx / 2`` per axis (2 particles per cell and axis), computed in float64 and
    rounded once; C order over the axes, the same lattice as mpm_warp's seeding.
    """
    if n_grid <= 0 or n_grid % 2:
        raise ValueError(f"n_grid must be a positive even integer, got {n_grid}")
    dx = 1.0 / n_grid
    axis = 0.25 + (np.arange(n_grid, dtype=np.float64) + 0.5) * (0.5 * dx)
    grids = np.meshgrid(*([axis] * dim), indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1).astype(np.float32)


def initial_state(n_grid: int, dim: int, material: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x0, v0, C0)`` float32 arrays of the block: at rest (elastic) or struck (:mod:`.plastic_block`)."""
    x0 = block_positions(n_grid, dim)
    if material == "plastic":
        return (x0, pb.initial_velocity(x0).astype(np.float32),
                pb.initial_velocity_gradient(x0).astype(np.float32))
    return x0, np.zeros_like(x0), np.zeros((len(x0), dim, dim), dtype=np.float32)
