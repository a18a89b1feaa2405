"""One step size for many independent columns stepped together (mpm_warp.column_batch).

Each column keeps its own clock ``[t, dt, t_end, dt_last]`` (float64, s) and chooses its own step as a
single run does (kernels/timestep.py). Between that choice and the rest of the step, :func:`offer_dt_kernel`
puts each active column's choice in the batch's list, :func:`least_dt_kernel` takes the least, and
:func:`take_dt_kernel` writes it back into every active column's clock and step size: all clocks stay equal.
"""

import functools

import warp as wp


@functools.cache
def offer_dt_kernel():
    """One thread: ``offers[column] = clock[1]``, the step the column chose (s)."""

    @wp.kernel(enable_backward=False, module="unique")
    def offer_dt(clock: wp.array(dtype=wp.float64), offers: wp.array(dtype=wp.float64), column: wp.int32):
        offers[column] = clock[1]

    return offer_dt


@functools.cache
def least_dt_kernel():
    """One thread: ``least[0]`` = the least offer of the active columns (s; ``active[k] != 0``)."""

    @wp.kernel(enable_backward=False, module="unique")
    def least_dt(offers: wp.array(dtype=wp.float64), active: wp.array(dtype=wp.int32),
                 least: wp.array(dtype=wp.float64)):
        d = wp.float64(1.0e30)
        for k in range(offers.shape[0]):
            if active[k] != 0:
                d = wp.min(d, offers[k])
        least[0] = d

    return least_dt


@functools.cache
def take_dt_kernel(T):
    """One thread: the column's clock and step size take the batch's step ``least[0]`` (s); the last step that
    was not a no-op (``clock[3]``) becomes it when it is one."""

    @wp.kernel(enable_backward=False, module="unique")
    def take_dt(least: wp.array(dtype=wp.float64), clock: wp.array(dtype=wp.float64), dt_arr: wp.array(dtype=T)):
        d = least[0]
        clock[1] = d
        dt_arr[0] = T(d)
        if d > wp.float64(0.0):
            clock[3] = d

    return take_dt
