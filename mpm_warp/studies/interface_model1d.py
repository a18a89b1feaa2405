"""The settled column as a 1D static problem: the stencil's own answer at a stiffness jump, and the candidates.

The column of :mod:`.interface_column` (laterally confined, at rest) reduces to one row of particles per
height: ``K u = f`` with ``K = sum_p V_p M_p B_p B_p^T``, ``B_pi = 4/dx^2 w_ip (x_i - x_p)`` (the MLS strain of
``kernels/g2p.py``), ``f_i = -sum_p m_p g w_ip``, the bed's nodes fixed, and ``M = lambda + 2 mu``. Its
particle stresses are the 2D column's settled rows to about 1 %, in milliseconds, so it compares the ways of
reducing the interfaces' artefact (docs/model.md §5b): ``"none"`` (plain MLS-MPM), ``"bbar"`` (each
particle's strain the mean over its own layer's particles in its cell, B-bar-like) and ``"closure"`` (the
laminate closure, :func:`mpm_warp.interfaces.stack_factors`).
"""

from __future__ import annotations

import math

import numpy as np

from ..interfaces import stack_factors
from ..lattice import GRID_PADDING, lattice_counts
from ..scenes.snow import GRAVITY
from .interface_column import column_scenario, overburden

__all__ = ["SCHEMES", "static_rows"]

#: the schemes :func:`static_rows` solves
SCHEMES = ("none", "bbar", "closure")


def _weights(y: np.ndarray, nodes: np.ndarray, dx: float) -> np.ndarray:
    r = np.abs(y[:, None] - nodes[None, :]) / dx
    return np.where(r < 0.5, 0.75 - r ** 2, np.where(r < 1.5, 0.5 * (1.5 - r) ** 2, 0.0))


def static_rows(cells: float, scheme: str = "none", scenario: str = "pst_demo") -> dict:
    """The static column's particle rows at ``cells`` grid cells across the weak layer.

    Returns
    -------
    dict
        ``y`` (m), ``layer`` (block index, bottom to top), ``sigma_yy`` (Pa, tension positive),
        ``overburden`` (Pa), ``ratio`` (``-sigma_yy / overburden``), ``near`` (mask: within 3 cells of the
        layer), ``worst`` (the largest ``|ratio - 1|`` there) and ``zero_energy_modes`` (the rank the
        system lacks: displacements that strain no particle).
    """
    if scheme not in SCHEMES:
        raise ValueError(f"scheme {scheme!r}: one of {SCHEMES}")
    sc = column_scenario(cells)
    p, dx = sc.scene, sc.scene.dx
    g = GRAVITY * math.cos(math.radians(p.slope_angle))
    y, vol, rho, M, G, lam, lay = [], [], [], [], [], [], []
    for k, b in enumerate(sorted(sc.blocks, key=lambda b: b.lo[1])):
        m = sc.materials[b.material]
        n = lattice_counts((b.lo[1],), (b.hi[1],), dx, b.particles_per_cell)[0]
        h = (b.hi[1] - b.lo[1]) / n
        y.append(b.lo[1] + (np.arange(n) + 0.5) * h)
        for lst, val in ((vol, h), (rho, m.density), (M, m.lam + 2.0 * m.mu), (G, m.mu), (lam, m.lam), (lay, k)):
            lst.append(np.full(n, val))
    y, vol, rho, M, G, lam, lay = map(np.concatenate, (y, vol, rho, M, G, lam, lay))
    origin = sc.domain.lo[1] - GRID_PADDING * dx
    nodes = origin + np.arange(int(math.ceil((y.max() - origin) / dx)) + 3) * dx
    W = _weights(y, nodes, dx)
    B = 4.0 / dx ** 2 * W * (nodes[None, :] - y[:, None])
    Mp = M.copy()
    if scheme == "closure":
        band, fac = stack_factors(y, vol, M, G, lam, lay, origin, dx)
        Mp[band] = M[band] * fac[:, 0]
    if scheme == "bbar":
        cell = np.floor((y - origin) / dx).astype(np.int64)
        key = cell * (lay.max() + 1) + lay
        _, inv = np.unique(key, return_inverse=True)
        P = (inv[:, None] == inv[None, :]) * vol[None, :]
        B = (P / P.sum(axis=1, keepdims=True)) @ B
    K = (B * (vol * Mp)[:, None]).T @ B
    f = -(W * (vol * rho * g)[:, None]).sum(axis=0)
    free = (nodes > 1e-3 * dx) & (np.diag(K) > 1e-12 * np.diag(K).max())
    u = np.zeros(len(nodes))
    Kf = K[np.ix_(free, free)]
    u[free], _, rank, _ = np.linalg.lstsq(Kf, f[free], rcond=None)  # B-bar's system can be singular
    sig = Mp * (B @ u)
    ob = overburden(p, y)
    ratio = -sig / ob
    near = (y >= p.substratum_depth - 3.0 * dx) & (y <= p.base_y + 3.0 * dx)
    return {"cells": float(cells), "dx": dx, "scheme": scheme, "y": y, "layer": lay, "sigma_yy": sig,
            "overburden": ob, "ratio": ratio, "near": near, "worst": float(np.abs(ratio[near] - 1.0).max()),
            "zero_energy_modes": int(Kf.shape[0] - rank)}
