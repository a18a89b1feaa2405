"""The model's material groups: which particles hold which material, and that material as the kernels take it.

Each block of a scenario becomes a :class:`ParticleGroup`, a contiguous range of particles of one
material and one particle volume. :func:`seed_groups` orders them so that the plastic state
(``log_jp``) and the softening state (``kappa``) are contiguous prefixes; :func:`material_params`
turns a material into the kernel-side parameter struct.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .config import Scenario
from .errors import InvalidArgument
from .kernels.camclay import SINGULAR_VALUE_FLOOR, ellipse_axes
from .kernels.constitutive import material_struct
from .lattice import lattice_columns, lattice_counts, seed_block
from .materials import BondedCamClay, CamClaySnow, CrackingSnow, Elastic

__all__ = ["ParticleGroup", "SeededGroups", "seed_groups", "material_params", "SOFTENING_MODELS",
           "SINGULAR_VALUE_FLOOR"]

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
    (:func:`~mpm_warp.lattice.lattice_columns`) and ``n_columns`` their count.
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


class SeededGroups(NamedTuple):
    """The particle groups of a scenario and the counts of the state they index (:func:`seed_groups`)."""

    #: the groups, in particle order
    groups: list[ParticleGroup]
    #: per group, its block and the positions seeded for it (m)
    seed: list
    n_particles: int
    #: particles with a plastic state ``log_jp`` (Cam-Clay groups)
    n_plastic: int
    #: particles with a softening state ``kappa`` (bonded weak layers, then cracking groups)
    n_kappa: int
    #: particles of bonded weak layers
    n_bonded: int


def seed_groups(scenario: Scenario, dx: float) -> SeededGroups:
    """Seed every block of ``scenario`` on its lattice of spacing ``dx / ppc`` and lay the groups out.

    Bonded weak layers come first, then the other plastic groups, the cracking ones and the elastic
    ones, so that ``log_jp`` is a contiguous prefix and ``kappa`` holds the bonded groups (from 0)
    and then the cracking ones.
    """
    def order(b):
        m = scenario.materials[b.material]
        return not m.plastic, m.model != "bonded_camclay", m.model != "tensile_cracking"

    blocks = sorted(scenario.blocks, key=order)
    groups: list[ParticleGroup] = []
    seed = []
    start = 0
    pstart = 0
    kstart = 0
    n_bonded = 0
    for b in blocks:
        mat = scenario.materials[b.material]
        x, vol = seed_block(b.lo, b.hi, dx, b.particles_per_cell)
        keep = b.inside(x)
        if not keep.any():
            raise InvalidArgument(f"block {b.name!r}.halfspaces", b.halfspaces, "planes that leave some of the box")
        x = x[keep] if b.halfspaces else x
        n = len(x)
        g = ParticleGroup(b.name, b.material, mat, start, start + n, vol, mat.density * vol,
                          pstart if mat.plastic else -1)
        if mat.model == "bonded_camclay":
            cols = lattice_columns(lattice_counts(b.lo, b.hi, dx, b.particles_per_cell))
            g.columns = cols[keep] if b.halfspaces else cols
            g.n_columns = int(cols.max()) + 1
            n_bonded += n
        if mat.model in SOFTENING_MODELS:
            g.kappa_start = kstart
            kstart += n
        if mat.plastic:
            pstart += n
        start += n
        groups.append(g)
        seed.append((b, x))
    return SeededGroups(groups, seed, start, pstart, kstart, n_bonded)


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
