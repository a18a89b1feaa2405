"""Device action of the weak layer: collapse reference and the brittle first-yield failure rule.

This file and :mod:`.params` hold the weak layer's scene physics; replace them to change it.
The kernel reads the device clock ``[t, dt, t_end]`` (float64, s): no host work inside the step loop.
"""

import functools

import warp as wp

from ...kernels.camclay import camclay_p0_func, camclay_pq_func, camclay_yield_func
from ...kernels.types import mat33, vec3

__all__ = ["weak_layer_kernel"]


@functools.cache
def weak_layer_kernel(T):
    """Weak-layer bookkeeping and brittle cohesion loss, one thread per weak-layer particle, every step.

    ``ref`` is the hardening state collapse is measured from: a copy of
    ``log_jp`` until ``t_ref`` (the settled layer), then fixed. ``failed`` is 0
    (intact), 1 (failed) or 2 (sawn, see :func:`mpm_warp.scenes.pst.kernels.pst_action_kernel`).

    With ``brittle != 0``, from ``t_ref`` on, an intact particle whose stress
    has reached the yield surface (``y >= -tol M^2 a^2``, ``a = p0 (1 + beta)/2``;
    shear, tension or compression: MODEL.md 2) loses its cohesion at once:
    ``log_jp = max(log_jp, log_jp_failed)`` (0: ``p0`` at its floor), ``failed = 1``
    and ``ref`` is reset to that state. The engine's Cam-Clay return then
    compacts it under the slab load until the hardening law carries the load
    again: the collapse of the anticrack, ``1 - J_P = 1 - exp(-asinh(p/K)/xi)``
    on the cap. A particle fails once; before ``t_ref`` (settling) only the
    engine's model acts.
    Stress from the SVD of ``F_E = I + H`` (Hencky, Kirchhoff, Pa); ``H = F_E - I`` is the engine's
    elastic state (3D scenes: the snow scenes are one cell thick, not plane-strain 2D).
    """
    V = vec3(T)
    M33 = mat33(T)
    pq = camclay_pq_func(T)
    p0_fn = camclay_p0_func(T)
    yield_fn = camclay_yield_func(T)

    @wp.kernel(enable_backward=False)
    def weak_layer(H: wp.array(dtype=M33), log_jp: wp.array(dtype=T), ref: wp.array(dtype=T),
                   failed: wp.array(dtype=wp.uint8), clock: wp.array(dtype=wp.float64), t_ref: wp.float64,
                   brittle: wp.int32, mu: T, lam: T, M: T, beta: T, xi: T, p0_floor: T, log_jp_failed: T,
                   tol: T):
        i = wp.tid()
        lj = log_jp[i]
        if brittle != 0 and failed[i] == wp.uint8(0) and clock[0] >= t_ref:
            U = M33()
            sig = V()
            Vt = M33()
            wp.svd3(wp.identity(3, dtype=T) + H[i], U, sig, Vt)
            p, q = pq(sig, mu, lam)
            K = lam + T(2.0) / T(3.0) * mu
            p0 = p0_fn(lj, K, xi, p0_floor)
            a = T(0.5) * p0 * (T(1.0) + beta)
            if yield_fn(p, q, p0, M, beta) >= -tol * M * M * a * a:
                failed[i] = wp.uint8(1)
                lj = wp.max(lj, log_jp_failed)
                log_jp[i] = lj
                ref[i] = lj
        if clock[0] < t_ref and failed[i] == wp.uint8(0):
            ref[i] = lj

    return weak_layer
