"""Model (static description on the device) and State (time-varying particle fields).

Following Newton's split: :class:`Model` holds what does not change during a
run (grid geometry, particle groups with their material parameters, walls,
gravity); :class:`State` holds the particle fields and the device clock. Only
the fields a scene needs are allocated: ``log_jp`` only for Cam-Clay
particles, ``yielded`` only when the output asks for it, wall buffers only when
there are walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from .config import Scenario
from .kernels.camclay import SINGULAR_VALUE_FLOOR
from .kernels.grid_update import wall_struct
from .kernels.types import mat33, vec3
from .materials import CamClaySnow, Elastic

__all__ = ["Model", "State", "ParticleGroup", "seed_block", "velocity_gradient", "SINGULAR_VALUE_FLOOR", "GRID_PADDING"]

#: grid nodes added outside the domain box on each side
GRID_PADDING = 3


@dataclass
class ParticleGroup:
    """A contiguous range of particles of one material and one particle volume.

    ``start:end`` indexes the particle arrays; ``plastic_start`` indexes
    ``log_jp`` (Cam-Clay groups only, else -1).
    """

    name: str
    material_name: str
    material: Elastic
    start: int
    end: int
    vol0: float
    mass: float
    plastic_start: int = -1

    @property
    def count(self) -> int:
        """Number of particles in the group."""
        return self.end - self.start


def seed_block(lo, hi, dx: float, ppc: int) -> tuple[np.ndarray, float]:
    """Particles on a regular lattice filling ``[lo, hi]`` with ``ppc`` per cell and axis.

    Returns positions (n, 3) in m and the particle volume (m^3). The lattice
    spacing is ``dx / ppc``; the count per axis is rounded so the block volume is
    preserved to within half a spacing per face.
    """
    h = dx / ppc
    axes = []
    for a in range(3):
        n = max(1, int(round((hi[a] - lo[a]) / h)))
        step = (hi[a] - lo[a]) / n
        axes.append(lo[a] + (np.arange(n) + 0.5) * step)
    vol = float(np.prod([(hi[a] - lo[a]) / len(axes[a]) for a in range(3)]))
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1), vol


def velocity_gradient(field, x: np.ndarray, h: float) -> np.ndarray:
    """Central-difference gradient ``dv_i/dx_j`` (1/s) of a velocity function at points ``x`` (n, 3).

    Used to start APIC/MLS particles with the affine matrix ``C = grad v`` of a
    prescribed initial velocity field, so a rigid spin or shear starts without
    the energy loss of ``C = 0``.
    """
    grad = np.zeros((len(x), 3, 3))
    for j in range(3):
        e = np.zeros(3)
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
    origin : (3,) float
        Position of grid node (0, 0, 0) (m).
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
        self.dx = dom.dx
        lo = np.asarray(dom.lo, dtype=np.float64)
        hi = np.asarray(dom.hi, dtype=np.float64)
        self.origin = lo - GRID_PADDING * self.dx
        self.grid_shape = tuple(
            int(math.ceil((hi[a] - lo[a]) / self.dx - 1e-9)) + 2 * GRID_PADDING + 1 for a in range(3)
        )
        # particles must keep their 3x3x3 stencil inside the grid: grid coordinate in [1, n - 2]
        self.x_lo = self.origin + 1.0 * self.dx
        self.x_hi = self.origin + (np.asarray(self.grid_shape) - 2.0) * self.dx

        from .walls import box_walls

        walls = []
        if dom.boundary != "none":
            walls += box_walls(lo, hi, dom.boundary, dom.friction, dom.boundary_faces)
        walls += list(scenario.walls)
        self.walls = [w.validate() for w in walls]
        self.c_p = max(m.p_wave_speed for m in scenario.materials.values())
        self.gravity = np.asarray(scenario.time.gravity, dtype=np.float64)

        # particle groups: plastic groups first, so log_jp is one contiguous prefix
        blocks = sorted(scenario.blocks, key=lambda b: not scenario.materials[b.material].plastic)
        self.groups: list[ParticleGroup] = []
        self._seed = []
        start = 0
        pstart = 0
        for b in blocks:
            mat = scenario.materials[b.material]
            x, vol = seed_block(b.lo, b.hi, self.dx, b.particles_per_cell)
            n = len(x)
            g = ParticleGroup(b.name, b.material, mat, start, start + n, vol, mat.density * vol,
                              pstart if mat.plastic else -1)
            if mat.plastic:
                pstart += n
            start += n
            self.groups.append(g)
            self._seed.append((b, x))
        self.n_particles = start
        self.n_plastic = pstart
        self.mass_threshold = 1e-9 * min(g.mass for g in self.groups)
        self.has_plastic = self.n_plastic > 0

        self.walls_device = None
        if self.walls:
            W = wall_struct(self.T)
            items = []
            for w in self.walls:
                s = W()
                s.point = vec3(self.T)(*w.point)
                s.normal = vec3(self.T)(*w.normal)
                s.velocity = vec3(self.T)(*w.velocity)
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
        """Allocate and fill the state at t = 0."""
        x = np.concatenate([s[1] for s in self._seed]).astype(self.np_dtype)
        v = np.zeros_like(x)
        C = np.zeros((len(x), 3, 3), dtype=self.np_dtype)
        for g, (b, xb) in zip(self.groups, self._seed, strict=True):
            if callable(b.velocity):
                v[g.start:g.end] = b.velocity(xb)
                C[g.start:g.end] = velocity_gradient(b.velocity, xb, 1e-3 * self.dx)
            else:
                v[g.start:g.end] = np.broadcast_to(np.asarray(b.velocity), xb.shape)
        ljp = np.zeros(self.n_plastic, dtype=self.np_dtype)
        for g in self.groups:
            if g.material.plastic:
                assert isinstance(g.material, CamClaySnow)
                ljp[g.plastic_start:g.plastic_start + g.count] = g.material.initial_log_jp
        return State(self, x, v, C, ljp, track_yield)

    def bytes_per_particle(self, state: State) -> float:
        """Device bytes of particle fields per particle (grid excluded)."""
        return state.particle_bytes() / self.n_particles


class State:
    """Time-varying fields on the device.

    Attributes
    ----------
    x, v : wp.array of vec3, (N,)
        Position (m) and velocity (m/s).
    C : wp.array of mat33, (N,)
        APIC/MLS affine velocity matrix (1/s).
    F : wp.array of mat33, (N,)
        Elastic deformation gradient F_E (-).
    log_jp : wp.array, (N_plastic,) or None
        ln det F_P of Cam-Clay particles.
    yielded : wp.array of uint8, (N_plastic,) or None
        Return-mapping activity flag, only when the output asks for it.
    clock : wp.array of float64, (3,)
        ``[t, dt, t_end]`` (s).
    steps : wp.array of int64, (1,)
        Steps taken.
    """

    def __init__(self, model: Model, x, v, C, log_jp, track_yield: bool):
        dev = model.device
        T = model.T
        V, M = vec3(T), mat33(T)
        n = len(x)
        self.model = model
        self.x = wp.array(x, dtype=V, device=dev)
        self.v = wp.array(v.astype(model.np_dtype), dtype=V, device=dev)
        self.C = wp.array(C, dtype=M, device=dev)
        self.F = wp.array(np.tile(np.eye(3, dtype=model.np_dtype), (n, 1, 1)), dtype=M, device=dev)
        self.log_jp = wp.array(log_jp, dtype=T, device=dev) if model.n_plastic else None
        track = track_yield and model.n_plastic > 0
        self.yielded = wp.zeros(model.n_plastic, dtype=wp.uint8, device=dev) if track else None
        self.clock = wp.zeros(3, dtype=wp.float64, device=dev)
        self.steps = wp.zeros(1, dtype=wp.int64, device=dev)

    def particle_bytes(self) -> int:
        """Bytes held by per-particle arrays on the device."""
        arrs = [self.x, self.v, self.C, self.F, self.log_jp, self.yielded]
        return sum(a.capacity for a in arrs if a is not None)

    def arrays(self) -> dict[str, np.ndarray]:
        """Host copies of the full state (for checkpoints)."""
        d = {"x": self.x.numpy(), "v": self.v.numpy(), "C": self.C.numpy(), "F": self.F.numpy(),
             "clock": self.clock.numpy(), "steps": self.steps.numpy()}
        if self.log_jp is not None:
            d["log_jp"] = self.log_jp.numpy()
        return d

    def load_arrays(self, d: dict[str, np.ndarray]) -> None:
        """Restore the state from :meth:`arrays` output (bit for bit)."""
        for k in ("x", "v", "C", "F", "clock", "steps", "log_jp"):
            dst = getattr(self, k)
            if dst is None:
                continue
            dst.assign(np.asarray(d[k]))
