"""The laminate closure at material interfaces (docs/model.md §5b): the strain rate of a particle near one.

Launched before P2G over the particles of a layered stack whose grid cells mix materials (their list and
factors come from ``mpm_warp/interfaces.py``). With ``n`` the stack's axis (normal to its layers) and ``t``
the tangential axes, the symmetric part ``D`` of the particle's ``C`` becomes the laminate's::

    D_nn <- r_n D_nn + c_p sum_t D_tt,    D_nt <- r_s D_nt,    the skew part kept,

``r_n = M_eff / M_p`` and ``r_s = G_eff / G_p`` (the grid's smeared stiffness over the particle's own,
constrained modulus ``M = lambda + 2 mu`` and shear modulus ``G = mu``), ``c_p = (r_n - 1) lambda_p / M_p``.
The trial update in P2G then strains the particle as its layer in a laminate; the scatter's affine momentum
``m C (x_i - x_p)`` sums to zero over the stencil for any ``C``, so momentum is conserved.
"""

import functools

import warp as wp

from .types import mat


@functools.cache
def closure_kernel(dim, T):
    """Build the closure kernel (one thread per listed particle) for dimension ``dim`` and scalar type ``T``.

    Inputs: ``idx`` (int32, the particles), ``fac`` (3-vectors ``(r_n, r_s, c_p)``, one per listed particle),
    ``axis`` (the stack's axis ``n``), ``C`` (all particles', updated in place), ``dt_arr`` (the step size: a
    step of size 0, a padding step of a captured batch, leaves ``C`` alone, as P2G does).
    """
    M = mat(dim, T)
    F = wp.types.vector(3, T)

    @wp.kernel(enable_backward=False, module="unique")
    def closure(idx: wp.array(dtype=wp.int32), fac: wp.array(dtype=F), axis: wp.int32, C: wp.array(dtype=M),
                dt_arr: wp.array(dtype=T)):
        k = wp.tid()
        if dt_arr[0] <= T(0.0):
            return
        i = idx[k]
        f = fac[k]
        c = C[i]
        out = c
        tt = T(0.0)
        for a in range(wp.static(dim)):
            if a != axis:
                tt += c[a, a]
                d = T(0.5) * (c[a, axis] + c[axis, a])
                w = T(0.5) * (c[a, axis] - c[axis, a])
                out[a, axis] = f[1] * d + w
                out[axis, a] = f[1] * d - w
        out[axis, axis] = f[0] * c[axis, axis] + f[2] * tt
        C[i] = out

    return closure
