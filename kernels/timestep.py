"""Device-side time control: the step size and the clock live on the device.

The automatic step is ``dt = cfl dx / (c_p + |v|_max)`` (docs/model.md §5) with
``|v|_max`` the largest nodal speed of the previous step, capped by ``dt_max``
and by the time left to the end of the current frame, so frames end exactly
on their times without any host read-back inside the substep loop.
"""

import functools

import warp as wp


@functools.cache
def begin_step_kernel(T):
    """Build the one-thread kernel that sets the step size of the coming step.

    ``clock`` (float64, s) holds ``[t, dt, t_end, dt_last]`` (``dt_last``: the last step size
    that was not a no-op, for the health check); ``dt_arr[0]`` receives ``dt`` in the
    kernels' scalar type. The clock stays float64 whatever the precision, so long
    runs in float32 keep exact frame times.

    ``dt_fixed > 0`` selects a fixed step; otherwise the CFL rule applies.
    A step that would leave less than a tenth of a step before ``t_end`` is
    stretched to land on ``t_end``. ``dt[0] = 0`` once ``t_end`` is reached, which
    turns the remaining launches of a batch into no-ops.
    """

    @wp.kernel(enable_backward=False, module="unique")
    def begin_step(
        clock: wp.array(dtype=wp.float64),
        vmax: wp.array(dtype=T),
        cfl: wp.float64,
        dx: wp.float64,
        c_p: wp.float64,
        dt_fixed: wp.float64,
        dt_max: wp.float64,
        dt_arr: wp.array(dtype=T),
    ):
        vm = vmax[0]
        for k in range(1, vmax.shape[0]):
            vm = wp.max(vm, vmax[k])
        d = dt_fixed
        if d <= wp.float64(0.0):
            d = cfl * dx / (c_p + wp.float64(vm))
        d = wp.min(d, dt_max)
        rem = clock[2] - clock[0]
        if rem <= wp.float64(1.0e-9) * d:
            d = wp.float64(0.0)
        elif rem < wp.float64(1.1) * d:
            d = rem
        clock[1] = d
        dt_arr[0] = T(d)
        if d > wp.float64(0.0):  # a no-op step (frame end reached) keeps the speed bound for the next frame
            clock[3] = d
            for k in range(vmax.shape[0]):
                vmax[k] = T(0.0)

    return begin_step


@functools.cache
def end_step_kernel():
    """Build the one-thread kernel that advances the clock and the step counter."""

    @wp.kernel(enable_backward=False, module="unique")
    def end_step(clock: wp.array(dtype=wp.float64), steps: wp.array(dtype=wp.int64)):
        d = clock[1]
        if d > wp.float64(0.0):
            clock[0] = clock[0] + d
            steps[0] = steps[0] + wp.int64(1)

    return end_step
