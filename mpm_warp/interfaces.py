"""The laminate closure's factors (docs/model.md §5b): which particles sit where a grid cell mixes materials.

The blocks of a scenario that name the same ``interface_normal`` axis form a laterally uniform stack of
layers. Along that axis each grid cell's compliance is the Reuss mean of its particles' (``sum V / M`` over
``sum V``, ``M = lambda + 2 mu`` for the normal, ``mu`` for the shear); summed over the cells it is the
displacement of a unit stress at the nodes, and the grid's smeared compliance at a particle is the MLS strain
its stencil takes from those nodal values (``C = 4/dx^2 sum w v_i (x_i - x_p)``, kernels/g2p.py). A particle
whose stencil's two cells hold only its own block keeps its strain rate; the others get the factors the
closure kernel applies (``kernels/interface_closure.py``), computed once from the initial positions.
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidArgument

__all__ = ["closure_factors", "stack_factors"]


def closure_factors(model) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """The closure of every stack of ``model`` (a :class:`mpm_warp.model.Model`).

    Returns
    -------
    list of (axis, idx, fac)
        Per stack axis: the indices (int32) of the particles the closure changes and their factors
        ``(r_n, r_s, c_p)`` (float64, (n, 3); see ``kernels/interface_closure.py``). Empty without stacks.
    """
    out = []
    axes = sorted({b.interface_normal for b, _ in model._seed if b.interface_normal >= 0})
    for axis in axes:
        idx, y, vol, M, G, lam, mid = [], [], [], [], [], [], []
        for k, (g, (b, x)) in enumerate(zip(model.groups, model._seed, strict=True)):
            if b.interface_normal != axis:
                continue
            m = g.material
            n = g.count
            idx.append(np.arange(g.start, g.end))
            y.append(np.asarray(x[:, axis], dtype=float))
            vol.append(np.full(n, g.vol0))
            M.append(np.full(n, m.lam + 2.0 * m.mu))
            G.append(np.full(n, m.mu))
            lam.append(np.full(n, m.lam))
            mid.append(np.full(n, k))
        idx, y, vol, M, G, lam, mid = map(np.concatenate, (idx, y, vol, M, G, lam, mid))
        band, fac = stack_factors(y, vol, M, G, lam, mid, float(model.origin[axis]), float(model.dx),
                                  f"blocks with interface_normal = {axis}")
        out.append((int(axis), idx[band].astype(np.int32), fac))
    return out


def stack_factors(y, vol, M, G, lam, block, origin: float, dx: float, where: str = "stack"):
    """The closure of one stack's particles: which it changes and their factors.

    Parameters
    ----------
    y : (n,) float
        Positions along the stack's axis (m).
    vol : (n,) float
        Volumes (m^3; any common unit).
    M, G, lam : (n,) float
        Constrained modulus ``lambda + 2 mu``, shear modulus ``mu`` and ``lambda`` (Pa).
    block : (n,) int
        The block (layer) of each particle.
    origin, dx : float
        The grid's origin along the axis and its spacing (m).
    where : str
        What the errors name.

    Returns
    -------
    band : (n,) bool
        The particles the closure changes.
    fac : (n_band, 3) float
        Their ``(r_n, r_s, c_p)``.
    """
    o, mid = origin, block
    y, vol, M, G, lam = (np.asarray(a, dtype=float) for a in (y, vol, M, G, lam))
    cell = np.floor((y - o) / dx).astype(np.int64)
    cells, inv = np.unique(cell, return_inverse=True)
    v = np.bincount(inv, vol)
    cn = np.bincount(inv, vol / M) / v
    cs = np.bincount(inv, vol / G) / v
    # a cell of one block's particles only: its block, else -1
    lo_id = np.full(len(cells), np.iinfo(np.int64).max)
    hi_id = np.full(len(cells), -1)
    np.minimum.at(lo_id, inv, mid)
    np.maximum.at(hi_id, inv, mid)
    pure = np.where(lo_id == hi_id, lo_id, -1)
    if np.any(np.diff(cells) != 1):
        raise InvalidArgument(where, "a stack with a gap",
                              "blocks that fill the stack's cells without an empty cell between them")
    # the MLS strain the stencil gives the cumulative compliance (the displacement of a unit stress)
    b = np.floor((y - o) / dx - 0.5).astype(np.int64)
    f = (y - o) / dx - b
    w = (0.5 * (1.5 - f) ** 2, 0.75 - (f - 1.0) ** 2, 0.5 * (f - 0.5) ** 2)
    c_n = sum(4.0 * w[a] * (a - f) * _cumulative(cn, b + a - cells[0]) for a in range(3))
    c_s = sum(4.0 * w[a] * (a - f) * _cumulative(cs, b + a - cells[0]) for a in range(3))
    # the particle's stencil spans the cells b and b + 1: changed unless both hold its own block only
    k0, k1 = np.clip(b - cells[0], 0, len(cells) - 1), np.clip(b + 1 - cells[0], 0, len(cells) - 1)
    band = ~((pure[k0] == mid) & (pure[k1] == mid))
    r_n = 1.0 / (c_n[band] * M[band])
    r_s = 1.0 / (c_s[band] * G[band])
    if not (np.all(r_n > 0.0) and np.all(r_s > 0.0)):
        raise InvalidArgument(where, "a non-positive smeared compliance",
                              "a stack of layers each at least a cell thick")
    fac = np.stack([r_n, r_s, (r_n - 1.0) * lam[band] / M[band]], axis=1)
    return band, fac


def _cumulative(c: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The cumulative compliance at nodes ``k`` (in cells from the stack's first cell; units of dx) of cells of
    compliance ``c``, continued linearly with the end cells' compliance beyond the stack."""
    cum = np.concatenate([[0.0], np.cumsum(c)])
    n = len(c)
    return np.where(k < 0, k * c[0], np.where(k > n, cum[-1] + (k - n) * c[-1], cum[np.clip(k, 0, n)]))
