"""Crack band of the bonded weak layer: the plastic work ``kappa`` averaged over each lattice column.

After every step the engine replaces the ``kappa`` of each weak-layer particle by the mean of its column
(the particles seeded at one bed position, across the layer), so the bond lives on the work done on the
whole thickness per unit area and the energy to debond does not depend on the cell size (docs/model.md §3b).
"""

import functools

import warp as wp

__all__ = ["kappa_column_sum_kernel", "kappa_column_mean_kernel", "column_sums_zero_kernel"]


@functools.cache
def kappa_column_sum_kernel(T):
    """Kernel ``kappa_column_sum(kappa, column, sums)``: ``sums[column[i]] += (kappa[i], 1)``.

    One thread per weak-layer particle. ``kappa`` (T, ``(n,)``): the group's
    plastic work (J/m^3); ``column`` (int32, ``(n,)``): the index of the
    particle's lattice column (particles seeded at the same bed position,
    across the layer thickness), in ``[0, n_columns)``; ``sums`` (``wp.vec2d``,
    ``(n_columns,)``, zeroed before the launch): float64 sum and count.
    Accumulating in float64 makes the float32 column mean exact and
    independent of the order of the atomic adds (up to 2^29 particles a column).

    Launch sequence after every step (graph-capturable): ``sums.zero_()``,
    this kernel, then :func:`kappa_column_mean_kernel`.
    """

    @wp.kernel(enable_backward=False, module="unique")
    def kappa_column_sum(kappa: wp.array(dtype=T), column: wp.array(dtype=wp.int32),
                         sums: wp.array(dtype=wp.vec2d)):
        i = wp.tid()
        wp.atomic_add(sums, column[i], wp.vec2d(wp.float64(kappa[i]), wp.float64(1.0)))

    return kappa_column_sum


@functools.cache
def kappa_column_mean_kernel(T):
    """Kernel ``kappa_column_mean(sums, column, kappa)``: ``kappa[i] = sum / count`` of its column.

    One thread per weak-layer particle, after :func:`kappa_column_sum_kernel`.
    Every particle of a column then carries the column mean, so the bond
    ``b = 1 - kappa/kappa_s`` is that of the work done on the layer's thickness at
    its bed position (crack band = the layer, module docstring). Idempotent:
    a second pass leaves ``kappa`` unchanged (exactly in float32).
    """

    @wp.kernel(enable_backward=False, module="unique")
    def kappa_column_mean(sums: wp.array(dtype=wp.vec2d), column: wp.array(dtype=wp.int32),
                          kappa: wp.array(dtype=T)):
        i = wp.tid()
        s = sums[column[i]]
        kappa[i] = T(s[0] / s[1])

    return kappa_column_mean


@functools.cache
def column_sums_zero_kernel():
    """Kernel ``column_sums_zero(sums)``: ``sums[c] = (0, 0)``, one thread per column (a recordable launch
    that clears the buffer of :func:`kappa_column_sum_kernel` before every step's sums)."""

    @wp.kernel(enable_backward=False, module="unique")
    def column_sums_zero(sums: wp.array(dtype=wp.vec2d)):
        sums[wp.tid()] = wp.vec2d(wp.float64(0.0), wp.float64(0.0))

    return column_sums_zero
