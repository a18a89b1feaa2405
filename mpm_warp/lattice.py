"""Where particles and grid nodes sit: the grid's extent around the domain and the lattice that seeds a block.

The background grid covers the domain box plus :data:`GRID_PADDING` nodes on each side; a block is
filled with particles on a regular lattice of ``ppc`` per cell and axis, whose columns along the bed
normal the bonded weak layer averages over.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["GRID_PADDING", "grid_shape", "seed_block", "lattice_counts", "lattice_columns"]

#: grid nodes added outside the domain box on each side
GRID_PADDING = 3


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
