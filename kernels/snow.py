"""Device actions of the snow experiments, launched by the stepper every step.

- :func:`weak_layer_kernel`: weak-layer bookkeeping (collapse reference) and the
  brittle cohesion loss of ``mpm_warp.pst``;
- :func:`pst_action_kernel`: the saw of a Propagation Saw Test and the crack-front
  arrival times;
- :func:`push_kernel`: the displacement-controlled push of the shear test.

They read the device clock ``[t, dt, t_end]`` (float64, s), so no host work is
needed inside the substep loop.
"""

import functools

import warp as wp

from .camclay import camclay_p0_func, camclay_pq_func, camclay_yield_func
from .types import mat33, vec3


@functools.cache
def weak_layer_kernel(T):
    """Weak-layer bookkeeping and brittle cohesion loss, one thread per weak-layer particle, every step.

    ``ref`` is the hardening state collapse is measured from: a copy of
    ``log_jp`` until ``t_ref`` (the settled layer), then fixed. ``failed`` is 0
    (intact), 1 (failed) or 2 (sawn, see :func:`pst_action_kernel`).

    With ``brittle != 0``, from ``t_ref`` on, an intact particle whose stress
    has reached the yield surface (``y >= -tol M^2 a^2``, ``a = p0 (1 + beta)/2``;
    shear, tension or compression: MODEL.md 2) loses its cohesion at once:
    ``log_jp = max(log_jp, log_jp_failed)`` (0: ``p0`` at its floor), ``failed = 1``
    and ``ref`` is reset to that state. The engine's Cam-Clay return then
    compacts it under the slab load until the hardening law carries the load
    again: the collapse of the anticrack, ``1 - J_P = 1 - exp(-asinh(p/K)/xi)``
    on the cap. A particle fails once; before ``t_ref`` (settling) only the
    engine's model acts.
    Stress from the SVD of ``F_E`` (Hencky, Kirchhoff, Pa).
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


@functools.cache
def pst_action_kernel(T):
    """Saw and crack-front tracker, one thread per weak-layer particle, every step.

    From ``t_start`` the blade sits at distance ``min(speed (t - t_start),
    cut_length)`` from ``x_start`` along ``direction`` (+1 or -1); particles
    behind it get ``log_jp = max(log_jp, log_jp_cut)`` and ``failed = 2``.
    ``arrival_collapse[bin]`` (s) receives the first time one of the bin's
    particles was sawn or collapsed (``log_jp - ref <= collapse_log``, i.e.
    ``1 - J_P/J_P,ref >= threshold``); ``arrival_failure[bin]`` the first time one
    was sawn or failed. Times are the step's start ``clock[0]`` (float64, s).
    """
    V = vec3(T)

    @wp.kernel(enable_backward=False)
    def pst_action(x: wp.array(dtype=V), log_jp: wp.array(dtype=T), ref: wp.array(dtype=T),
                   failed: wp.array(dtype=wp.uint8), clock: wp.array(dtype=wp.float64), t_start: wp.float64,
                   x_start: wp.float64, direction: wp.float64, speed: wp.float64, cut_length: wp.float64,
                   log_jp_cut: T, collapse_log: T, bin_width: wp.float64,
                   arrival_collapse: wp.array(dtype=wp.float64), arrival_failure: wp.array(dtype=wp.float64)):
        i = wp.tid()
        t = clock[0]
        if t < t_start:
            return
        lj = log_jp[i]
        s = (wp.float64(x[i][0]) - x_start) * direction
        if s <= wp.min(speed * (t - t_start), cut_length):
            log_jp[i] = wp.max(lj, log_jp_cut)
            failed[i] = wp.uint8(2)
        f = failed[i]
        b = int(wp.floor(s / bin_width))
        if b >= 0 and b < arrival_collapse.shape[0]:
            if f != wp.uint8(0):
                wp.atomic_min(arrival_failure, b, t)
            if f == wp.uint8(2) or lj - ref[i] <= collapse_log:
                wp.atomic_min(arrival_collapse, b, t)

    return pst_action


@functools.cache
def push_kernel(T):
    """Displacement-controlled push of a particle group, every step before P2G.

    Sets ``v_x = 0`` before ``t_start`` and ``v_x = speed`` (m/s) after, zeroes the
    first row of the affine matrix ``C`` (no ``x``-velocity gradient: the group
    translates rigidly in ``x``) and, after the first pushing step, adds the impulse
    given, ``m (v_x,new - v_x)`` (N s), to ``impulse[0]`` (float64): the layer's
    resistance over the step (the jump from rest to ``speed`` at the first step is
    the block's own inertia, not a reaction, and is left out).
    """
    V = vec3(T)
    M33 = mat33(T)

    @wp.kernel(enable_backward=False)
    def push(v: wp.array(dtype=V), C: wp.array(dtype=M33), clock: wp.array(dtype=wp.float64),
             t_start: wp.float64, speed: T, mass: T, impulse: wp.array(dtype=wp.float64)):
        i = wp.tid()
        vx = T(0.0)
        vi = v[i]
        if clock[0] >= t_start:
            vx = speed
            if clock[0] - clock[1] >= t_start:  # not the first pushing step: no start-up jump counted
                wp.atomic_add(impulse, 0, wp.float64(mass * (vx - vi[0])))
        v[i] = V(vx, vi[1], vi[2])
        c = C[i]
        C[i] = M33(T(0.0), T(0.0), T(0.0), c[1, 0], c[1, 1], c[1, 2], c[2, 0], c[2, 1], c[2, 2])

    return push
