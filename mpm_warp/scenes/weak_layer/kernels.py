"""Device action of the weak layer: the saw's kerf, the collapse reference and the damage arrival times.

The layer's physics is the engine's bonded Cam-Clay (``kernels/bonded_camclay.py``); this action only
acts as the saw and keeps the bookkeeping the fronts need. It reads the device clock ``[t, dt, t_end,
dt_last]`` (float64, s): no host work inside the step loop.
"""

import functools

import warp as wp

from ...kernels.types import vec

__all__ = ["weak_layer_kernel"]


@functools.cache
def weak_layer_kernel(dim, T):
    """Saw, collapse reference and damage arrival, one thread per weak-layer particle, every step (before P2G).

    - Reference: ``ref = log_jp`` while ``t < t_ref`` (the layer as it settled), then fixed; the
      collapse ``1 - exp(log_jp - ref)`` is measured from it.
    - Saw (``saw_speed > 0``): the blade sits at distance ``min(pre_cut + saw_speed max(t - t_saw, 0),
      blade_end[0])`` (m) from ``x_start`` along ``direction`` (+1 or -1): at the pre-cut's end from the
      start, advancing from ``t_saw``; a particle behind it loses its
      bond (``kappa = max(kappa, kappa_s)``: a kerf, the layer cohesionless there and free to collapse
      under the slab) and is flagged ``sawn = 1``. ``blade_end`` is a 1-element device array (m), read
      every step: the cut length, or where the host stopped the blade between frames (a captured CUDA
      graph reads the new value; a launch parameter would stay as captured).
    - Damage arrival: the first time (s, the step's start) the particle's bond ``1 - kappa/kappa_s``
      fell to ``damage_bond`` or below (``arrival = inf`` before).
    """
    V = vec(dim, T)

    @wp.kernel(enable_backward=False, module="unique")
    def weak_layer(x: wp.array(dtype=V), log_jp: wp.array(dtype=T), kappa: wp.array(dtype=T),
                   ref: wp.array(dtype=T), sawn: wp.array(dtype=wp.uint8), arrival: wp.array(dtype=wp.float64),
                   clock: wp.array(dtype=wp.float64), t_ref: wp.float64, kappa_s: T, damage_bond: T,
                   t_saw: wp.float64, saw_speed: wp.float64, blade_end: wp.array(dtype=wp.float64), x_start: wp.float64,
                   direction: wp.float64, pre_cut: wp.float64):
        i = wp.tid()
        t = clock[0]
        if t < t_ref:
            ref[i] = log_jp[i]
        k = kappa[i]
        reach = pre_cut
        if t >= t_saw:
            reach = pre_cut + saw_speed * (t - t_saw)
        if saw_speed > wp.float64(0.0) and (t >= t_saw or pre_cut > wp.float64(0.0)):
            s = (wp.float64(x[i][0]) - x_start) * direction
            if s <= wp.min(reach, blade_end[0]):
                if k < kappa_s:
                    k = kappa_s
                    kappa[i] = k
                sawn[i] = wp.uint8(1)
        if arrival[i] > t and k >= (T(1.0) - damage_bond) * kappa_s:  # inf until the first time
            arrival[i] = t

    return weak_layer
