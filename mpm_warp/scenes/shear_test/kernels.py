"""Device action of the shear test: the displacement-controlled push of the loading block."""

import functools

import warp as wp

from ...kernels.types import mat, vec

__all__ = ["push_kernel"]


@functools.cache
def push_kernel(dim, T):
    """Displacement-controlled push of a particle group, every step before P2G.

    Sets ``v_x = 0`` before ``t_start`` and ``v_x = speed`` (m/s) after, zeroes the
    first row of the affine matrix ``C`` (no ``x``-velocity gradient: the group
    translates rigidly in ``x``) and, after the first pushing step, adds the impulse
    given, ``m (v_x,new - v_x)`` (N s), to ``impulse[0]`` (float64): the layer's
    resistance over the step (the jump from rest to ``speed`` at the first step is
    the block's own inertia, not a reaction, and is left out).
    """
    V = vec(dim, T)
    M = mat(dim, T)

    @wp.kernel(enable_backward=False, module="unique")
    def push(v: wp.array(dtype=V), C: wp.array(dtype=M), clock: wp.array(dtype=wp.float64),
             t_start: wp.float64, speed: T, mass: T, impulse: wp.array(dtype=wp.float64)):
        i = wp.tid()
        vx = T(0.0)
        vi = v[i]
        if clock[0] >= t_start:
            vx = speed
            if clock[0] - clock[1] >= t_start:  # not the first pushing step: no start-up jump counted
                wp.atomic_add(impulse, 0, wp.float64(mass * (vx - vi[0])))
        vi[0] = vx
        v[i] = vi
        c = C[i]
        for b in range(dim):
            c[0, b] = T(0.0)
        C[i] = c

    return push
