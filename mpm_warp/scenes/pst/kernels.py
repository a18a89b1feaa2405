"""Device action of the PST: the slab-deflection tracker (the saw is the weak layer's: ``scenes/weak_layer``).

Reads the device clock ``[t, dt, t_end, dt_last]`` (float64, s): no host work inside the step loop.
"""

import functools

import warp as wp

from ...kernels.types import vec

__all__ = ["deflection_kernel"]


@functools.cache
def deflection_kernel(dim, T):
    """Slab-base deflection arrival, one thread per slab-base particle (the lowest lattice row), every step.

    ``y_ref`` follows the particle's bed-normal position ``x[1]`` (m) while ``t < t_ref`` (settling),
    then stays; ``arrival`` (s) receives the first time the base has come down by ``threshold`` (m)
    or more, ``y_ref - y >= threshold`` (inf before).
    """
    V = vec(dim, T)

    @wp.kernel(enable_backward=False, module="unique")
    def deflection(x: wp.array(dtype=V), index: wp.array(dtype=wp.int32), y_ref: wp.array(dtype=wp.float64),
                   arrival: wp.array(dtype=wp.float64), clock: wp.array(dtype=wp.float64), t_ref: wp.float64,
                   threshold: wp.float64):
        i = wp.tid()
        t = clock[0]
        y = wp.float64(x[index[i]][1])
        if t < t_ref:
            y_ref[i] = y
        elif arrival[i] > t and y_ref[i] - y >= threshold:  # inf until the first time
            arrival[i] = t

    return deflection
