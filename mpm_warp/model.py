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
from .errors import InvalidArgument
from .kernels.camclay import SINGULAR_VALUE_FLOOR, ellipse_axes
from .kernels.constitutive import material_struct
from .kernels.grid_update import wall_struct
from .kernels.types import mat, vec
from .materials import BondedCamClay, CamClaySnow, CrackingSnow, Elastic

__all__ = ["Model", "State", "ParticleGroup", "seed_block", "lattice_counts", "lattice_columns", "grid_shape",
           "velocity_gradient", "material_params", "SINGULAR_VALUE_FLOOR", "GRID_PADDING"]

#: grid nodes added outside the domain box on each side
GRID_PADDING = 3
#: material models with a softening state ``kappa`` per particle
SOFTENING_MODELS = ("bonded_camclay", "tensile_cracking")


@dataclass
class ParticleGroup:
    """A contiguous range of particles of one material and one particle volume.

    ``start:end`` indexes the particle arrays; ``plastic_start`` indexes
    ``log_jp`` (Cam-Clay groups only, else -1) and, for a bonded weak layer
    (whose groups come first among the plastic ones), ``kappa`` too; ``kappa_start`` indexes ``kappa``
    (bonded and cracking groups, else -1);
    ``columns`` (bonded groups) the lattice column of each particle
    (:func:`lattice_columns`) and ``n_columns`` their count.
    """

    name: str
    material_name: str
    material: Elastic
    start: int
    end: int
    vol0: float
    mass: float
    plastic_start: int = -1
    columns: np.ndarray | None = None
    n_columns: int = 0
    kappa_start: int = -1

    @property
    def count(self) -> int:
        """Number of particles in the group."""
        return self.end - self.start


def grid_shape(lo, hi, dx: float) -> tuple[int, ...]:
    """Grid nodes per axis of the domain ``[lo, hi]`` with spacing ``dx``, :data:`GRID_PADDING` nodes outside it."""
    return tuple(int(math.ceil((hi[a] - lo[a]) / dx - 1e-9)) + 2 * GRID_PADDING + 1 for a in range(len(lo)))


def seed_block(lo, hi, dx: float, ppc: int) -> tuple[np.ndarray, float]:
    """Particles on a regular lattice filling ``[lo, hi]`` with ``ppc`` per cell and axis.

    Returns positions (n, dim) in m (``dim = len(lo)``) and the particle volume
    (m^3; in 2D m^2 times one metre of depth). The lattice spacing is
    ``dx / ppc``; the count per axis is rounded so the block volume is preserved
    to within half a spacing per face. Particles are ordered with the last axis
    fastest (``np.meshgrid(..., indexing="ij")``).
    """
    dim = len(lo)
    axes = []
    for a, n in enumerate(lattice_counts(lo, hi, dx, ppc)):
        step = (hi[a] - lo[a]) / n
        axes.append(lo[a] + (np.arange(n) + 0.5) * step)
    vol = float(np.prod([(hi[a] - lo[a]) / len(axes[a]) for a in range(dim)]))
    grids = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1), vol


def lattice_counts(lo, hi, dx: float, ppc: int) -> tuple[int, ...]:
    """Particles per axis of the :func:`seed_block` lattice of ``[lo, hi]``."""
    h = dx / ppc
    return tuple(max(1, int(round((hi[a] - lo[a]) / h))) for a in range(len(lo)))


def material_params(material: Elastic, T):
    """Kernel-side parameters (``kernels.constitutive.material_struct``) of a material, scalar type ``T``."""
    m = material_struct(T)()
    m.mu, m.lam = T(material.mu), T(material.lam)
    m.s_floor = T(SINGULAR_VALUE_FLOOR)
    m.K, m.inv_K = T(material.bulk), T(1.0 / material.bulk)
    if isinstance(material, (CamClaySnow, BondedCamClay)):
        m.M, m.beta, m.xi, m.p0_floor = T(material.M), T(material.beta), T(material.xi), T(material.p0_floor)
        m.log_jp_ref = T(material.initial_log_jp)
        axes = ellipse_axes(material.bulk, material.mu, material.M, material.beta)
        m.ell_rho, m.ell_inv_rho, m.ell_c, m.ell_inv_c = (T(x) for x in axes)
    if isinstance(material, BondedCamClay):
        m.p_bond, m.kappa_s = T(material.p_bond), T(material.kappa_s)
    if isinstance(material, CrackingSnow):
        m.t_strength, m.t_fail = T(material.tensile_strength), T(material.failure_stress)
    return m


def lattice_columns(counts) -> np.ndarray:
    """Column index (int32) of every particle of a :func:`seed_block` lattice with ``counts`` per axis.

    A column is the particles seeded at one bed position (same lattice index on every axis
    but ``y``, axis 1, the bed normal): the bonded weak layer averages its plastic strain
    over them after every step (``kernels/bonded_camclay.py``: the softening lives on the
    layer's total slip, so its energy per unit area does not depend on dx).
    """
    idx = np.indices(counts).reshape(len(counts), -1)
    col = idx[0] * (counts[2] if len(counts) == 3 else 1) + (idx[2] if len(counts) == 3 else 0)
    return col.astype(np.int32)


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

        # particle groups: bonded weak layers, the other plastic groups, cracking ones, then elastic ones, so that
        # log_jp is a contiguous prefix and kappa holds the bonded groups (from 0) and then the cracking ones
        def order(b):
            m = scenario.materials[b.material]
            return not m.plastic, m.model != "bonded_camclay", m.model != "tensile_cracking"

        blocks = sorted(scenario.blocks, key=order)
        self.groups: list[ParticleGroup] = []
        self._seed = []
        start = 0
        pstart = 0
        kstart = 0
        self.n_bonded = 0
        for b in blocks:
            mat = scenario.materials[b.material]
            x, vol = seed_block(b.lo, b.hi, self.dx, b.particles_per_cell)
            keep = b.inside(x)
            if not keep.any():
                raise InvalidArgument(f"block {b.name!r}.halfspaces", b.halfspaces, "planes that leave some of the box")
            x = x[keep] if b.halfspaces else x
            n = len(x)
            g = ParticleGroup(b.name, b.material, mat, start, start + n, vol, mat.density * vol,
                              pstart if mat.plastic else -1)
            if mat.model == "bonded_camclay":
                cols = lattice_columns(lattice_counts(b.lo, b.hi, self.dx, b.particles_per_cell))
                g.columns = cols[keep] if b.halfspaces else cols
                g.n_columns = int(cols.max()) + 1
                self.n_bonded += n
            if mat.model in SOFTENING_MODELS:
                g.kappa_start = kstart
                kstart += n
            if mat.plastic:
                pstart += n
            start += n
            self.groups.append(g)
            self._seed.append((b, x))
        self.n_particles = start
        self.n_plastic = pstart
        #: particles with a softening state ``kappa`` (bonded weak layers, then cracking groups)
        self.n_kappa = kstart
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


class State:
    """Time-varying fields on the device (``dim``-vectors and ``dim x dim`` matrices).

    Attributes
    ----------
    x, v : wp.array of vec, (N,)
        Position (m) and velocity (m/s).
    C : wp.array of mat, (N,)
        APIC/MLS affine velocity matrix (1/s).
    H : wp.array of mat, (N,)
        Elastic displacement gradient ``F_E - I`` (-), in-plane block in 2D (see
        ``kernels/constitutive.py``: stored as ``F_E - I`` so that float32 keeps
        increments far below its resolution of 1).
    hzz : wp.array, (N_plastic,) or None
        Out-of-plane elastic stretch minus one, ``F_E,zz - 1`` (-), of the plastic particles in plane strain
        (indexed as ``log_jp``); an elastic particle's ``F_E,zz`` is the total, 1, and is not stored.
    log_jp : wp.array, (N_plastic,) or None
        ln det F_P of Cam-Clay particles.
    kappa : wp.array, (N_kappa,) or None
        The softening state of the bonded weak-layer particles (plastic work, J/m^3; the first plastic ones)
        and then of the cracking ones (largest effective tensile stress, Pa), indexed by ``kappa_start``.
    yielded : wp.array of uint8, (N_plastic,) or None
        Return-mapping activity flag, only when the output asks for it.
    clock : wp.array of float64, (4,)
        ``[t, dt, t_end, dt_last]`` (s).
    steps : wp.array of int64, (1,)
        Steps taken.
    """

    #: the arrays a checkpoint holds (those that exist; ``yielded`` holds the flags of a frame stopped half-way)
    CHECKPOINT_FIELDS = ("x", "v", "C", "H", "hzz", "log_jp", "kappa", "yielded", "clock", "steps")

    def __init__(self, model: Model, x, v, C, log_jp, kappa, track_yield: bool):
        dev = model.device
        T = model.T
        d = model.dim
        V, M = vec(d, T), mat(d, T)
        n = len(x)
        self.model = model
        self.x = wp.array(x, dtype=V, device=dev)
        self.v = wp.array(v.astype(model.np_dtype), dtype=V, device=dev)
        self.C = wp.array(C, dtype=M, device=dev)
        self.H = wp.zeros(n, dtype=M, device=dev)
        self.hzz = wp.zeros(model.n_plastic, dtype=T, device=dev) if d == 2 and model.n_plastic else None
        self.log_jp = wp.array(log_jp, dtype=T, device=dev) if model.n_plastic else None
        self.kappa = wp.array(kappa, dtype=T, device=dev) if model.n_kappa else None
        track = track_yield and model.n_plastic > 0
        self.yielded = wp.zeros(model.n_plastic, dtype=wp.uint8, device=dev) if track else None
        self.clock = wp.zeros(4, dtype=wp.float64, device=dev)
        self.steps = wp.zeros(1, dtype=wp.int64, device=dev)

    def particle_bytes(self) -> int:
        """Bytes held by per-particle arrays on the device."""
        arrs = [self.x, self.v, self.C, self.H, self.hzz, self.log_jp, self.kappa, self.yielded]
        return sum(a.capacity for a in arrs if a is not None)

    def elastic_deformation_gradient(self) -> np.ndarray:
        """Host copy of ``F_E`` as (N, 3, 3) float64 (in 2D: the in-plane block and ``F_zz``)."""
        H = self.H.numpy().astype(np.float64)
        n, d = H.shape[0], H.shape[1]
        F = np.zeros((n, 3, 3))
        F[:, :d, :d] = H
        F[:, range(3), range(3)] += 1.0
        if self.hzz is not None:
            hzz = self.hzz.numpy().astype(np.float64)
            for g in self.model.groups:
                if g.plastic_start >= 0:
                    F[g.start:g.end, 2, 2] += hzz[g.plastic_start:g.plastic_start + g.count]
        return F

    def set_elastic_deformation_gradient(self, F) -> None:
        """Set ``F_E`` from (N, 3, 3) (in 2D only the in-plane block and ``F_zz`` are used; computed as
        ``F - I`` in float64 before rounding to the state's precision)."""
        F = np.asarray(F, dtype=np.float64)
        d = self.model.dim
        H = F[:, :d, :d] - np.eye(d)
        self.H.assign(H.astype(self.model.np_dtype))
        if d == 2:
            hzz = np.zeros(self.model.n_plastic)
            for g in self.model.groups:
                zz = F[g.start:g.end, 2, 2] - 1.0
                if g.plastic_start >= 0:
                    hzz[g.plastic_start:g.plastic_start + g.count] = zz
                elif np.any(zz != 0.0):
                    raise InvalidArgument(f"F[{g.start}:{g.end}, 2, 2] (group {g.name!r}, elastic, plane strain)",
                                          float(F[g.start + int(np.argmax(zz != 0.0)), 2, 2]),
                                          "1 (an elastic particle's out-of-plane stretch is the total one)")
            if self.hzz is not None:
                self.hzz.assign(hzz.astype(self.model.np_dtype))

    def arrays(self) -> dict[str, np.ndarray]:
        """Host copies of the full state (checkpoints, snapshots): copies, never views of the device
        memory (on the CPU ``wp.array.numpy()`` is a view, which the next step would overwrite)."""
        d = {}
        for k in self.CHECKPOINT_FIELDS:
            a = getattr(self, k)
            if a is not None:
                d[k] = np.array(a.numpy(), copy=True)
        return d

    def load_arrays(self, d: dict[str, np.ndarray]) -> None:
        """Restore the state from :meth:`arrays` output (bit for bit)."""
        for k in self.CHECKPOINT_FIELDS:
            dst = getattr(self, k)
            if dst is None or (k == "yielded" and k not in d):   # older checkpoints hold no yielded flags
                continue
            a = np.asarray(d[k])
            if k == "hzz" and a.shape[0] != dst.shape[0]:    # an older checkpoint: hzz of every particle
                a = np.concatenate([a[g.start:g.end] for g in self.model.groups if g.plastic_start >= 0])
            if k == "clock" and a.shape[0] < dst.shape[0]:  # a 3-entry clock of an older checkpoint
                a = np.concatenate([a, [a[1]]])
            dst.assign(a)
