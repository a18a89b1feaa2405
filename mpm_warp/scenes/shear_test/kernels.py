"""Device action of the shear test: the displacement-controlled push of the loading block."""

import functools

import warp as wp

from ...kernels.types import mat33, vec3

__all__ = ["push_kernel"]


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
