"""Quadratic B-spline interpolation stencil (3 nodes per axis).

For a particle at grid coordinate ``X = (x - origin) / dx`` the stencil base
node is ``base = floor(X - 0.5)`` and the local offset ``f = X - base`` lies in
[0.5, 1.5). The 1D weights are

    w0 = 0.5 (1.5 - f)^2,  w1 = 0.75 - (f - 1)^2,  w2 = 0.5 (f - 0.5)^2,

which sum to one and reproduce linear functions exactly (Steffen et al. 2008;
Jiang et al. 2016, eq. 123).
"""

import functools

import warp as wp

from .types import mat33, vec3


@functools.cache
def stencil_func(T):
    """Return ``stencil(x, origin, inv_dx) -> (base: vec3i, fx: vec3, W: mat33)``.

    ``x`` and ``origin`` in m, ``inv_dx`` in 1/m. ``fx`` is the offset of the
    particle from the base node in cells; row ``k`` of ``W`` holds the 1D
    weights of stencil node ``base + k`` along x, y and z, so the weight of node
    (i, j, k) is ``W[i, 0] * W[j, 1] * W[k, 2]``.
    """
    V = vec3(T)
    M = mat33(T)

    @wp.func
    def stencil(x: V, origin: V, inv_dx: T):
        X = (x - origin) * inv_dx
        b = wp.vec3i(int(wp.floor(X[0] - T(0.5))), int(wp.floor(X[1] - T(0.5))), int(wp.floor(X[2] - T(0.5))))
        fx = X - V(T(b[0]), T(b[1]), T(b[2]))
        a = V(T(1.5), T(1.5), T(1.5)) - fx
        c = fx - V(T(1.0), T(1.0), T(1.0))
        d = fx - V(T(0.5), T(0.5), T(0.5))
        w0 = T(0.5) * wp.cw_mul(a, a)
        w1 = V(T(0.75), T(0.75), T(0.75)) - wp.cw_mul(c, c)
        w2 = T(0.5) * wp.cw_mul(d, d)
        W = M(w0[0], w0[1], w0[2], w1[0], w1[1], w1[2], w2[0], w2[1], w2[2])
        return b, fx, W

    return stencil


@wp.func
def in_grid(b: wp.vec3i, nx: int, ny: int, nz: int):
    """True when the 3x3x3 stencil based at node ``b`` lies inside a grid of ``nx * ny * nz`` nodes.

    Also false for the garbage index a non-finite position produces, so kernels
    never read or write out of bounds.
    """
    return b[0] >= 0 and b[1] >= 0 and b[2] >= 0 and b[0] <= nx - 3 and b[1] <= ny - 3 and b[2] <= nz - 3
