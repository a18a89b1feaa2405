"""Device action of the PST: the saw and the crack-front tracker (read the device clock, float64 s)."""

import functools

import warp as wp

from ...kernels.types import vec3

__all__ = ["pst_action_kernel"]


@functools.cache
def pst_action_kernel(T):
    """Saw and crack-front tracker, one thread per weak-layer particle, every step.

    From ``t_start`` the blade sits at distance ``min(speed (t - t_start),
    cut_length)`` from ``x_start`` along ``direction`` (+1 or -1); particles
    behind it get ``log_jp = max(log_jp, log_jp_cut)`` and ``failed = 2`` (sawn).
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
