"""A static plane-strain (or plane-stress) finite-element solution of a sawn PST column: the slab's stresses with every
layer resolved.

The column is the one weac sees (a layered slab on a weak layer on a rigid base, free ends, gravity on a slope, the
weak layer removed over the cut), meshed with biquadratic (9-node) elements that carry a linear strain through
each element, so a slab layer's bending is exact with one element through it and every layer gets at least
``cells_per_layer``. The weak layer is an elastic continuum, not weac's springs. It is a reference for the slab's
stress where weac's one-rotation laminate and a field run's 1-2 grid cells across a thin stiff layer part: the
derivation and its checks are in docs/field.md ("A resolved slab"). Needs scipy (the sparse direct solver).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import finite_number
from ..errors import InvalidArgument

__all__ = ["ColumnFE", "solve_column"]

_GAUSS = (np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)]), np.array([5.0, 8.0, 5.0]) / 9.0)
_NODES_1D = np.array([-1.0, 0.0, 1.0])


def _lagrange(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The three quadratic Lagrange functions on [-1, 1] (nodes -1, 0, 1) and their derivatives at ``t``."""
    n = np.stack([0.5 * t * (t - 1.0), 1.0 - t * t, 0.5 * t * (t + 1.0)], axis=-1)
    d = np.stack([t - 0.5, -2.0 * t, t + 0.5], axis=-1)
    return n, d


def _shape(xi: float, eta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """N (9,), dN/dxi (9,), dN/deta (9,) of the 9-node element; node k = 3 * b + a (a along x, b along z)."""
    nx, dx = _lagrange(np.array(xi))
    nz, dz = _lagrange(np.array(eta))
    return np.outer(nz, nx).ravel(), np.outer(nz, dx).ravel(), np.outer(dz, nx).ravel()


def _elasticity(E: float, nu: float, plane: str = "strain") -> np.ndarray:
    """Elasticity matrix (Pa) for (eps_xx, eps_zz, gamma_xz): plane strain (no strain across the column), or plane
    stress (no stress across it: the in-plane Lame constant is then ``2 lam mu / (lam + 2 mu)``)."""
    lam, mu = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])


def _b_matrix(xi: float, eta: float, hx: float, hz: float, shear: float) -> tuple[np.ndarray, float]:
    """Strain-displacement matrix (3, 18) at (xi, eta) of an element of width ``hx``, height ``hz``, its
    vertical sides sheared by ``dx/dz = shear``; and det J."""
    _, dxi, deta = _shape(xi, eta)
    J = np.array([[hx / 2.0, 0.0], [shear * hz / 2.0, hz / 2.0]])        # rows: d/dxi, d/deta of (x, z)
    dN = np.linalg.solve(J, np.vstack([dxi, deta]))                         # rows: dN/dx, dN/dz
    B = np.zeros((3, 18))
    B[0, 0::2], B[1, 1::2] = dN[0], dN[1]
    B[2, 0::2], B[2, 1::2] = dN[1], dN[0]
    return B, float(np.linalg.det(J))


@dataclass
class ColumnFE:
    """The solution: stresses (Pa) at every element's 9 nodes, element by element (not averaged).

    ``x`` is along the column from the cut end at the weak layer's top (m, the distance the saw travels),
    ``from_end_face`` the same from the cut end's face at the point's own depth (with plumb ends the two differ),
    ``depth`` below the slab's surface (m); ``layer`` the slab layer (0 = top; -1 the weak layer);
    ``sigma`` (n, 3) = (sigma_xx along the bed, sigma_zz normal to it, sigma_xz); ``sigma_1`` the largest
    in-plane principal stress; ``moment(x)`` the slab's bending moment about its mid-depth (N m / m)."""

    x: np.ndarray
    from_end_face: np.ndarray
    depth: np.ndarray
    layer: np.ndarray
    sigma: np.ndarray
    sigma_1: np.ndarray
    dofs: int
    dx: float
    _section: object = None

    def moment(self, x: float) -> tuple[float, float]:
        """``(N, M)``: the slab's axial force (N/m) and bending moment about its mid-depth (N m/m) at ``x``."""
        return self._section(x)


def _grid(thicknesses, cells_per_layer: int, dz_max: float) -> tuple[np.ndarray, np.ndarray]:
    """Element faces z (m, from the base up) and each element row's layer index in ``thicknesses`` (bottom up)."""
    z, rows = [0.0], []
    for k, t in enumerate(thicknesses):
        n = max(cells_per_layer, int(math.ceil(t / dz_max - 1e-9)))
        z.extend(z[-1] + t * np.arange(1, n + 1) / n)
        rows.extend([k] * n)
    return np.array(z), np.array(rows)


def solve_column(slab, weak_layer, length: float, cut: float, *, slope_angle: float = 0.0,
                 cut_from: str = "upslope", column_ends: str = "slope_normal", dx: float = 0.01,
                 cells_per_layer: int = 2, g: float = 9.81, plane: str = "strain") -> ColumnFE:
    """Solve a sawn column statically.

    Parameters
    ----------
    slab : sequence of (thickness m, density kg/m^3, E Pa, nu)
        The slab's layers, top to bottom (``StaticColumn.slab``).
    weak_layer : (thickness m, E Pa, nu)
        The weak layer, massless (as weac's), fixed at its base (the rigid substratum).
    length, cut : float
        Column length along the slope at the weak layer (m) and the saw's cut from the cut end (m, [0, length)).
    slope_angle : float
        deg, in [-60, 60]; gravity is ``g (sin, -cos)`` with downslope ``+x``, the end ``x = 0`` upslope.
    cut_from : {"upslope", "downslope"}
    column_ends : {"slope_normal", "vertical"}
    dx : float
        Element width along the column (m); ``cells_per_layer`` elements at least through every layer, and
        none taller than ``dx``.
    plane : {"strain", "stress"}
        Plane strain (a column infinitely wide across the slope, as weac's and the run's) or plane stress (one
        infinitely thin): a 30 cm wide field column lies between the two.
    """
    length = finite_number("length", length, lo=0.0, lo_open=True)
    cut = finite_number("cut", cut, lo=0.0, hi=length, hi_open=True)
    slope_angle = finite_number("slope_angle", slope_angle, lo=-60.0, hi=60.0)
    dx = finite_number("dx", dx, lo=0.0, lo_open=True, hi=length)
    if cut_from not in ("upslope", "downslope"):
        raise InvalidArgument("cut_from", cut_from, '"upslope" or "downslope"')
    if column_ends not in ("slope_normal", "vertical"):
        raise InvalidArgument("column_ends", column_ends, '"slope_normal" or "vertical"')
    if plane not in ("strain", "stress"):
        raise InvalidArgument("plane", plane, '"strain" or "stress"')
    if not isinstance(cells_per_layer, int) or cells_per_layer < 1:
        raise InvalidArgument("cells_per_layer", cells_per_layer, "an integer >= 1")
    try:
        import scipy.sparse as sp
        import scipy.sparse.linalg as spl
    except ModuleNotFoundError as exc:                                     # pragma: no cover - scipy comes with weac
        raise ModuleNotFoundError("solve_column needs scipy: pip install 'mpm-warp[weac]' (or scipy)") from exc

    theta = math.radians(slope_angle)
    shear = -math.tan(theta) if column_ends == "vertical" else 0.0         # dx/dz of a plumb end face
    layers = [(weak_layer[0], 0.0, weak_layer[1], weak_layer[2])] + [tuple(ly) for ly in reversed(slab)]
    zf, row_layer = _grid([ly[0] for ly in layers], cells_per_layer, dx)
    nex, nez = int(math.ceil(length / dx - 1e-9)), row_layer.size
    hx = length / nex
    nnx, nnz = 2 * nex + 1, 2 * nez + 1
    node = np.arange(nnx * nnz).reshape(nnz, nnx)                           # node[j, i]: row j (z), column i (x)
    ex, ez = np.meshgrid(np.arange(nex), np.arange(nez))
    ex, ez = ex.ravel(), ez.ravel()
    local = np.array([[b, a] for b in range(3) for a in range(3)])  # (dz, dx) offsets of the 9 nodes
    conn = node[2 * ez[:, None] + local[None, :, 0], 2 * ex[:, None] + local[None, :, 1]]   # (ne, 9)
    x_mid = (ex + 0.5) * hx
    s_mid = x_mid if cut_from == "upslope" else length - x_mid             # from the cut end
    keep = ~((row_layer[ez] == 0) & (s_mid < cut))                          # the sawn weak layer is gone
    conn, ez = conn[keep], ez[keep]

    gvec = g * np.array([math.sin(theta), -math.cos(theta)])
    Ke_rows, fe_rows, D_rows = [], [], []
    for j in range(nez):
        t, rho, E, nu = layers[row_layer[j]]
        hz = zf[j + 1] - zf[j]
        D = _elasticity(E, nu, plane)
        Ke, fe = np.zeros((18, 18)), np.zeros(18)
        for a, wa in zip(*_GAUSS, strict=True):
            for b, wb in zip(*_GAUSS, strict=True):
                B, det = _b_matrix(a, b, hx, hz, shear)
                Ke += B.T @ D @ B * det * wa * wb
                N = _shape(a, b)[0]
                fe[0::2] += N * rho * gvec[0] * det * wa * wb
                fe[1::2] += N * rho * gvec[1] * det * wa * wb
        Ke_rows.append(Ke)
        fe_rows.append(fe)
        D_rows.append(D)
    Ke_rows, fe_rows = np.array(Ke_rows), np.array(fe_rows)
    edofs = np.stack([2 * conn, 2 * conn + 1], axis=-1).reshape(len(conn), 18)
    ndof = 2 * nnx * nnz
    K = sp.coo_matrix((Ke_rows[ez].ravel(), (np.repeat(edofs, 18, axis=1).ravel(), np.tile(edofs, (1, 18)).ravel())),
                      shape=(ndof, ndof)).tocsc()
    F = np.bincount(edofs.ravel(), weights=fe_rows[ez].ravel(), minlength=ndof)
    used = np.zeros(ndof, bool)
    used[edofs.ravel()] = True
    used[np.stack([2 * node[0], 2 * node[0] + 1]).ravel()] = False          # the rigid base
    free = np.flatnonzero(used)
    u = np.zeros(ndof)
    u[free] = spl.spsolve(K[free][:, free], F[free])

    # stresses at each element's own 9 nodes
    pts = [(xi, eta) for eta in _NODES_1D for xi in _NODES_1D]
    ue = u[edofs]                                                           # (ne, 18)
    sig = np.empty((len(conn), 9, 3))
    for j in np.unique(ez):
        sel = ez == j
        hz = zf[j + 1] - zf[j]
        for k, (xi, eta) in enumerate(pts):
            B, _ = _b_matrix(xi, eta, hx, hz, shear)
            sig[sel, k] = ue[sel] @ (D_rows[j] @ B).T
    zn = np.concatenate([np.linspace(zf[j], zf[j + 1], 3)[:2] for j in range(nez)] + [[zf[-1]]])   # node z
    xn_base = np.linspace(0.0, length, nnx)
    jn, in_ = np.divmod(conn.ravel(), nnx)
    z = zn[jn]
    x_at = xn_base[in_] + shear * (z - zf[1 + np.flatnonzero(row_layer == 0)[-1]])   # m, at the weak layer's top
    s = x_at if cut_from == "upslope" else length - x_at
    s_face = xn_base[in_] if cut_from == "upslope" else length - xn_base[in_]
    top = zf[-1]
    lay = np.repeat(len(layers) - 1 - row_layer[ez], 9)                     # slab layer from the top; weak: -1
    lay[lay == len(layers) - 1] = -1
    S = sig.reshape(-1, 3)
    a_, b_, c_ = S[:, 0], S[:, 1], S[:, 2]
    s1 = 0.5 * (a_ + b_) + np.sqrt(0.25 * (a_ - b_) ** 2 + c_ * c_)

    ex_kept = ex[keep]

    def section(xs: float) -> tuple[float, float]:
        """``(N, M)`` of sigma_xx through the slab on the node line nearest ``xs`` (m from the cut end);
        ``M`` about the slab's mid-depth, positive with the surface in tension."""
        i = int(round((xs if cut_from == "upslope" else length - xs) / (hx / 2.0)))
        col = min(i // 2, nex - 1)
        xi = float(i - 2 * col - 1)
        zc = 0.5 * (zf[-1] + zf[nez - np.count_nonzero(row_layer > 0)])
        N = M = 0.0
        for j in np.unique(row_layer.nonzero()[0]):
            e = np.flatnonzero((ez == j) & (ex_kept == col))[0]
            hz = zf[j + 1] - zf[j]
            for eta, w in zip(*_GAUSS, strict=True):
                B, _ = _b_matrix(xi, eta, hx, hz, shear)
                sxx = (D_rows[j] @ B @ ue[e])[0]
                N += sxx * w * hz / 2.0
                M += sxx * (zf[j] + (eta + 1.0) * hz / 2.0 - zc) * w * hz / 2.0
        return N, M

    return ColumnFE(x=s, from_end_face=s_face, depth=top - z, layer=lay, sigma=S, sigma_1=s1, dofs=free.size,
                    dx=hx, _section=section)
