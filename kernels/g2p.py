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

from .g2p_rows import gather_rows_func
from .shape import NONNEG, in_grid_func, stencil_func
from .types import mat, vec


def _fma_options(dim):
    """Module options of G2P for dimension ``dim``: in 2D the CPU compiler may fuse a product and a sum into one FMA.

    Warp's CPU code writes every operation as its own C++ statement, which the compiler's
    default contraction (``-ffp-contract=on``: within one expression) never fuses;
    ``-ffp-contract=fast`` fuses across statements: one rounding instead of two per multiply-add
    (round-off only, the same answer on every run and thread count). The 2D G2P is bound by
    scalar floating-point throughput on the CPU (1.50 -> 1.25 ms with FMAs at 65k particles; its stencil
    sums then as four-lane operations, ``kernels/g2p_rows.py``: 1.21 -> 0.92 ms).
    P2G keeps Warp's default: it evaluates the constitutive update, which must stay bit for bit
    the material-point driver's (``tests/test_constitutive.py``), and the compiler's fusion
    choices depend on the code around the update; only its 2D scatter fuses, inside its snippet
    (``kernels/p2g_rows.py``). The 3D kernels keep the default too.
    """
    if dim != 2:
        return {}
    flags = wp.config.cpu_compiler_flags or "-march=native"  # Warp's default when unset
    return {"cpu_compiler_flags": f"{flags} -ffp-contract=fast"}


@functools.cache
def g2p_kernel(dim, T):
    """Build the G2P kernel (launched over all particles) for dimension ``dim`` (2 or 3)."""
    V = vec(dim, T)
    M = mat(dim, T)
    Vi = wp.types.vector(dim, wp.int32)
    stencil = stencil_func(T, dim)
    in_grid = in_grid_func(dim)
    gather_rows = gather_rows_func(T) if dim == 2 else None

    @wp.kernel(enable_backward=False, module="unique", module_options=_fma_options(dim))
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
        if wp.static(dim == 2):
            # (masking the sign bit, a no-op on the in-grid indices, tells the compiler they are not negative: no
            # negative-index wrap per access)
            s0 = strides[0] & NONNEG
            n0 = (b[0] * s0 + b[1] * strides[1]) & NONNEG
            # separable sums (algebraically the 3D loop below), kernels/g2p_rows.py
            rows = gather_rows(grid_v, n0, s0, W, fx)
            vn = V(rows[0, 0], rows[0, 1])
            cs = T(4.0) * inv_dx * inv_dx * dx
            C[i] = M(cs * rows[1, 0], cs * rows[2, 0], cs * rows[1, 1], cs * rows[2, 1])
        else:
            B = M()
            n0 = b[0] * strides[0] + b[1] * strides[1] + b[2]
            for a in range(3):
                for c in range(3):
                    for d in range(3):
                        w = W[a, 0] * W[c, 1] * W[d, 2]
                        g = grid_v[n0 + a * strides[0] + c * strides[1] + d]
                        dpos = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                        vn += w * g
                        B += wp.outer(w * g, dpos)
            C[i] = (T(4.0) * inv_dx * inv_dx) * B
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
        x[i] = xn

    return g2p
