"""Grid-to-particle transfer (APIC / MLS-MPM) and advection.

``v_p = sum_i w_ip v_i``, ``C_p = D^-1 sum_i w_ip v_i (x_i - x_p)^T`` with
``D^-1 = 4 / dx^2`` for quadratic B-splines, ``x_p += dt v_p``.

Edge policy: a particle whose new position leaves the safe interior of the
grid (where its 3x3x3 stencil still fits) is clamped to it and counted in
``edge_count[0]``; the driver reports the count. A particle whose stencil is
not inside the grid at all (only possible for a non-finite position) is
skipped and counted in ``edge_count[1]``; the health check then stops the run.
No write can go out of bounds.
"""

import functools

import warp as wp

from .shape import in_grid, stencil_func
from .types import mat33, vec3


@functools.cache
def g2p_kernel(T):
    """Build the G2P kernel (launched over all particles)."""
    V = vec3(T)
    M = mat33(T)
    stencil = stencil_func(T)

    @wp.kernel(enable_backward=False)
    def g2p(
        x: wp.array(dtype=V),
        v: wp.array(dtype=V),
        C: wp.array(dtype=M),
        grid_v: wp.array3d(dtype=V),
        dt_arr: wp.array(dtype=T),
        origin: V,
        inv_dx: T,
        dx: T,
        x_lo: V,
        x_hi: V,
        edge_count: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        b, fx, W = stencil(x[i], origin, inv_dx)
        if not in_grid(b, grid_v.shape[0], grid_v.shape[1], grid_v.shape[2]):
            # only a non-finite position gets here (positions are clamped below)
            wp.atomic_add(edge_count, 1, 1)
            return
        vn = V(T(0.0), T(0.0), T(0.0))
        B = M()
        for a in range(3):
            for c in range(3):
                for d in range(3):
                    w = W[a, 0] * W[c, 1] * W[d, 2]
                    g = grid_v[b[0] + a, b[1] + c, b[2] + d]
                    dpos = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                    vn += w * g
                    B += w * wp.outer(g, dpos)
        xn = x[i] + dt * vn
        clamped = 0
        for a in range(3):
            if xn[a] < x_lo[a]:
                xn[a] = x_lo[a]
                clamped = 1
            elif xn[a] > x_hi[a]:
                xn[a] = x_hi[a]
                clamped = 1
        if clamped != 0:
            wp.atomic_add(edge_count, 0, 1)
        v[i] = vn
        C[i] = (T(4.0) * inv_dx * inv_dx) * B
        x[i] = xn

    return g2p
