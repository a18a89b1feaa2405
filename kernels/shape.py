"""Quadratic B-spline interpolation stencil (3 nodes per axis, 3^dim nodes).

For a particle at grid coordinate ``X = (x - origin) / dx`` the stencil base
node is ``base = floor(X - 0.5)`` and the local offset ``f = X - base`` lies in
[0.5, 1.5). The 1D weights are

    w0 = 0.5 (1.5 - f)^2,  w1 = 0.75 - (f - 1)^2,  w2 = 0.5 (f - 0.5)^2,

which sum to one and reproduce linear functions exactly (Steffen et al. 2008;
Jiang et al. 2016, eq. 123). The weight of node ``base + (a, c[, d])`` is
``W[a, 0] W[c, 1] [W[d, 2]]``.
"""

import functools

import warp as wp

from .types import vec, weights

#: int32 sign-bit mask: ``n & NONNEG == n`` for every index ``n >= 0``. A kernel that masks a flat grid index
#: it knows to be in the grid tells the compiler the index is not negative: Warp's array access then drops
#: its negative-index wrap (a compare and a select per access).
NONNEG = wp.constant(0x7FFFFFFF)


@functools.cache
def stencil_func(T, dim=3):
    """Return ``stencil(x, origin, inv_dx) -> (base: vec{dim}i, fx: vec, W: 3 x dim)``.

    ``x`` and ``origin`` in m, ``inv_dx`` in 1/m. ``fx`` is the offset of the
    particle from the base node in cells; row ``k`` of ``W`` holds the 1D
    weights of stencil node ``base + k`` along each axis.
    """
    V = vec(dim, T)
    Wt = weights(dim, T)
    Vi = wp.types.vector(dim, wp.int32)

    @wp.func
    def stencil(x: V, origin: V, inv_dx: T):
        X = (x - origin) * inv_dx
        b = Vi()
        fx = V()
        W = Wt()
        for a in range(dim):
            b[a] = int(wp.floor(X[a] - T(0.5)))
            f = X[a] - T(b[a])
            fx[a] = f
            W[0, a] = T(0.5) * (T(1.5) - f) * (T(1.5) - f)
            W[1, a] = T(0.75) - (f - T(1.0)) * (f - T(1.0))
            W[2, a] = T(0.5) * (f - T(0.5)) * (f - T(0.5))
        return b, fx, W

    return stencil


@functools.cache
def in_grid_func(dim):
    """Return ``in_grid(base, shape) -> bool``: the 3^dim stencil based at ``base`` lies inside the grid.

    ``shape`` is the node count per axis (``vec{dim}i``). Also false for the
    garbage index a non-finite position produces, so kernels never read or
    write out of bounds.
    """
    Vi = wp.types.vector(dim, wp.int32)

    @wp.func
    def in_grid(b: Vi, shape: Vi):
        ok = True
        for a in range(dim):
            if b[a] < 0 or b[a] > shape[a] - 3:
                ok = False
        return ok

    return in_grid
