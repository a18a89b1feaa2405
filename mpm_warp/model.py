"""Model: the static description of a run on the device (grid, particle groups, walls, gravity).

Following Newton's split: :class:`Model` holds what does not change during a
run (grid geometry and bounds, particle groups with their material parameters, walls,
gravity) and builds the :class:`~mpm_warp.state.State` at t = 0, which holds the
particle fields and the device clock. The lattice and the grid's extent are in
:mod:`mpm_warp.lattice`, the material groups in :mod:`mpm_warp.particle_groups`.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .config import Scenario
from .kernels.grid_update import wall_struct
from .kernels.types import vec
from .lattice import GRID_PADDING, grid_shape, lattice_columns, lattice_counts, seed_block
from .particle_groups import SINGULAR_VALUE_FLOOR, SOFTENING_MODELS, ParticleGroup, material_params, seed_groups
from .state import State

# the lattice, groups and state stay importable from here, where they were defined before the split
__all__ = ["Model", "State", "ParticleGroup", "seed_block", "lattice_counts", "lattice_columns", "grid_shape",
           "velocity_gradient", "material_params", "SINGULAR_VALUE_FLOOR", "GRID_PADDING", "SOFTENING_MODELS"]


def velocity_gradient(field, x: np.ndarray, h: float) -> np.ndarray:
    """Central-difference gradient ``dv_i/dx_j`` (1/s) of a velocity function at points ``x`` (n, dim).

    Used to start APIC/MLS particles with the affine matrix ``C = grad v`` of a
    prescribed initial velocity field, so a rigid spin or shear starts without
    the energy loss of ``C = 0``.
    """
    dim = x.shape[1]
    grad = np.zeros((len(x), dim, dim))
    for j in range(dim):
        e = np.zeros(dim)
        e[j] = h
        grad[:, :, j] = (np.asarray(field(x + e)) - np.asarray(field(x - e))) / (2.0 * h)
    return grad


class Model:
    """Static description of a run on one device.

    Parameters
    ----------
    scenario : Scenario
        Validated scenario.
    device : str
        Warp device name.

    Attributes
    ----------
    T : warp scalar type
        ``wp.float32`` or ``wp.float64``.
    dim : int
        Spatial dimension (2: plane strain, 3).
    origin : (dim,) float
        Position of grid node (0, ..., 0) (m).
    grid_shape : tuple of int
        Nodes per axis.
    groups : list of ParticleGroup
    walls : list of Wall
        Box walls from the domain plus the scenario's walls.
    c_p : float
        Largest P-wave speed of the materials present (m/s).
    """

    def __init__(self, scenario: Scenario, device: str):
        self.scenario = scenario
        self.device = device
        self.T = wp.float64 if scenario.precision == "float64" else wp.float32
        self.np_dtype = np.float64 if scenario.precision == "float64" else np.float32
        dom = scenario.domain
        self.dim = dom.dimension
        self.dx = dom.dx
        lo = np.asarray(dom.lo, dtype=np.float64)
        hi = np.asarray(dom.hi, dtype=np.float64)
        self.origin = lo - GRID_PADDING * self.dx
        self.grid_shape = grid_shape(lo, hi, self.dx)
        # particles must keep their 3^dim stencil inside the grid: grid coordinate in [1, n - 2]
        self.x_lo = self.origin + 1.0 * self.dx
        self.x_hi = self.origin + (np.asarray(self.grid_shape) - 2.0) * self.dx

        from .walls import box_walls

        walls = []
        if dom.boundary != "none":
            walls += box_walls(lo, hi, dom.boundary, dom.friction, dom.boundary_faces)
        walls += list(scenario.walls)
        self.walls = [w.validate(dim=self.dim) for w in walls]
        self.c_p = max(m.p_wave_speed for m in scenario.materials.values())
        self.gravity = np.asarray(scenario.time.gravity, dtype=np.float64)

        # particle groups: log_jp and kappa are contiguous prefixes (mpm_warp.particle_groups.seed_groups)
        seeded = seed_groups(scenario, self.dx)
        self.groups: list[ParticleGroup] = seeded.groups
        self._seed = seeded.seed
        self.n_bonded = seeded.n_bonded
        self.n_particles = seeded.n_particles
        self.n_plastic = seeded.n_plastic
        #: particles with a softening state ``kappa`` (bonded weak layers, then cracking groups)
        self.n_kappa = seeded.n_kappa
        # nodes lighter than this are empty. The node velocity (sum w (m v + A dpos)) / (sum w m) is well defined for
        # any positive mass, so the threshold only keeps float32 away from denormals (1e-20 of a particle's mass);
        # dropping nodes a particle reaches with a weight of 1e-9 broke momentum conservation at 1e-10
        self.mass_threshold = 1e-20 * min(g.mass for g in self.groups)
        self.has_plastic = self.n_plastic > 0

        self.walls_device = None
        if self.walls:
            W = wall_struct(self.T, self.dim)
            V = vec(self.dim, self.T)
            items = []
            for w in self.walls:
                s = W()
                s.point = V(*w.point)
                s.normal = V(*w.normal)
                s.velocity = V(*w.velocity)
                s.ramp_time = self.T(w.ramp_time)
                s.kind = w.kind_id
                s.friction = self.T(w.friction)
                items.append(s)
            self.walls_device = wp.array(items, dtype=W, device=device)

    @property
    def wall_names(self) -> list[str]:
        """Names of all walls, in kernel order."""
        return [w.name for w in self.walls]

    def initial_state(self, track_yield: bool = False) -> State:
        """Allocate and fill the state at t = 0 (``F_E = I``, ``log_Jp`` from each material's ``p0_ini``)."""
        d = self.dim
        x = np.concatenate([s[1] for s in self._seed]).astype(self.np_dtype)
        v = np.zeros_like(x)
        C = np.zeros((len(x), d, d), dtype=self.np_dtype)
        for g, (b, xb) in zip(self.groups, self._seed, strict=True):
            if callable(b.velocity):
                v[g.start:g.end] = b.velocity(xb)
                C[g.start:g.end] = velocity_gradient(b.velocity, xb, 1e-3 * self.dx)
            else:
                v[g.start:g.end] = np.broadcast_to(np.asarray(b.velocity), xb.shape)
        ljp = np.zeros(self.n_plastic, dtype=self.np_dtype)
        kappa = np.zeros(self.n_kappa, dtype=self.np_dtype)
        for g in self.groups:
            if g.material.plastic:
                ljp[g.plastic_start:g.plastic_start + g.count] = g.material.initial_log_jp
            if g.kappa_start >= 0:
                kappa[g.kappa_start:g.kappa_start + g.count] = g.material.initial_kappa
        return State(self, x, v, C, ljp, kappa, track_yield)

    def bytes_per_particle(self, state: State) -> float:
        """Device bytes of particle fields per particle (grid excluded)."""
        return state.particle_bytes() / self.n_particles
