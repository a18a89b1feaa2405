"""Grid-to-particle transfer (APIC / MLS-MPM) and advection.

``v_p = sum_i w_ip v_i``, ``C_p = D^-1 sum_i w_ip v_i (x_i - x_p)^T`` with
``D^-1 = 4 / dx^2`` for quadratic B-splines, ``x_p += dt v_p``.

The grid velocity is read from the flat layout of ``kernels/p2g.py`` (node
``(i, j[, k])`` at ``i s_0 + j s_1 [+ k]``).

Edge policy: a particle whose new position leaves the safe interior of the
grid (where its stencil still fits) is clamped to it and counted in
``counts[0]``; the driver reports the count. A particle whose stencil is not
inside the grid at all (only possible for a non-finite position) is skipped and
counted in ``counts[1]``; the health check then stops the run. No write can go
out of bounds.
"""

import functools

import warp as wp

from .shape import in_grid_func, stencil_func
from .types import mat, vec


@functools.cache
def g2p_kernel(dim, T):
    """Build the G2P kernel (launched over all particles) for dimension ``dim`` (2 or 3)."""
    V = vec(dim, T)
    M = mat(dim, T)
    Vi = wp.types.vector(dim, wp.int32)
    stencil = stencil_func(T, dim)
    in_grid = in_grid_func(dim)

    @wp.kernel(enable_backward=False, module="unique")
    def g2p(
        x: wp.array(dtype=V),
        v: wp.array(dtype=V),
        C: wp.array(dtype=M),
        grid_v: wp.array(dtype=V),
        dt_arr: wp.array(dtype=T),
        origin: V,
        inv_dx: T,
        dx: T,
        shape: Vi,
        strides: Vi,
        x_lo: V,
        x_hi: V,
        counts: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        b, fx, W = stencil(x[i], origin, inv_dx)
        if not in_grid(b, shape):
            # only a non-finite position gets here (positions are clamped below)
            wp.atomic_add(counts, 1, 1)
            return
        vn = V()
        B = M()
        n0 = b[0] * strides[0] + b[1] * strides[1]
        if wp.static(dim == 3):
            n0 += b[2]
        for a in range(3):
            for c in range(3):
                if wp.static(dim == 2):
                    w = W[a, 0] * W[c, 1]
                    g = grid_v[n0 + a * strides[0] + c]
                    dpos = (V(T(float(a)), T(float(c))) - fx) * dx
                    vn += w * g
                    B += wp.outer(w * g, dpos)
                else:
                    for d in range(3):
                        w = W[a, 0] * W[c, 1] * W[d, 2]
                        g = grid_v[n0 + a * strides[0] + c * strides[1] + d]
                        dpos = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                        vn += w * g
                        B += wp.outer(w * g, dpos)
        xn = x[i] + dt * vn
        clamped = 0
        for a in range(dim):
            if xn[a] < x_lo[a]:
                xn[a] = x_lo[a]
                clamped = 1
            elif xn[a] > x_hi[a]:
                xn[a] = x_hi[a]
                clamped = 1
        if clamped != 0:
            wp.atomic_add(counts, 0, 1)
        v[i] = vn
        C[i] = (T(4.0) * inv_dx * inv_dx) * B
        x[i] = xn

    return g2p
