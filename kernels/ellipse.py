"""The point of a Cam-Clay yield ellipse closest to a trial stress, in the energy metric (docs/model.md §4).

Eberly's parametrisation of the closest point of an ellipse, solved by Halley steps from the lower end of the
root's bracket (:func:`_ellipse_closest_func`), and the Cam-Clay projection built on it: per trial
(:func:`ellipse_point_func`, the bonded weak layer, whose ``beta`` softens) or from a material's constants
(:func:`ellipse_axes`, Cam-Clay's hot path). Stresses in Pa, compression positive; device functions come from
cached factories of the scalar type ``T``.
"""

import functools
import math

import warp as wp

__all__ = ["ellipse_axes", "ellipse_point_func", "ellipse_point_axes_func"]

_MAX_ROOT_ITERATIONS = 100


@functools.cache
def _ellipse_closest_func(T):
    """Closest point ``(x0, x1)`` of the ellipse ``(x0/e0)^2 + (x1/e1)^2 = 1`` to ``(y0, y1)`` (docs/model.md §4)
    and the factors ``f0 = x0/y0``, ``f1 = x1/y1`` (0 on a zero coordinate); ``ie0``, ``ie1`` are ``1/e0``, ``1/e1``
    (the caller has them: one axis is 1). The factors are the root's reciprocals ``r0/(s + r0)``, ``1/(s + 1)``:
    a caller that needs ``x/y`` (the return's deviatoric scale) gets it without a division.

    First quadrant only (``y0, y1 >= 0``), ``e0 >= e1 >= 0``, the point outside or on the ellipse:
    ``x0 = r0 y0 / (s + r0)``, ``x1 = y1 / (s + 1)``, ``r0 = (e0/e1)^2``, with ``s >= 0`` the root of
    ``F(s) = (r0 z0 / (s + r0))^2 + (z1 / (s + 1))^2 - 1``, ``z = y / e``. From the bracket's lower end
    ``max(0, z1 - 1, r0 z0 - r0)``: Halley steps (cubic convergence); after one has passed the root,
    Newton steps, which cannot pass it (``F`` is convex and decreasing for ``s >= 0``) but by rounding;
    after that, bisection. Stops when ``0 <= F <= 4 eps``, the bracket is below ``4 eps (1 + s)``, a step
    makes no progress, or after 100 iterations. On the struck block's trials (``benchmarks/perf``) three
    evaluations of ``F``, where the safeguarded Newton-bisection before it took seven. A Halley step inside the
    bracket forms the next reciprocals as ``den / ((lo + r0) den - g)`` (``s = lo - g / den``), so that the
    division for ``s`` stays off the chain of dependent operations (the loop is latency-bound); ``F`` is
    evaluated from the reciprocals, and the point returned is the one whose ``F`` ended the search.
    """
    eps = 4.0 * (2.0**-23 if T == wp.float32 else 2.0**-52)
    max_it = _MAX_ROOT_ITERATIONS

    @wp.func
    def root_f(i0: T, i1: T, n0: T, z1: T):
        """``F``, ``F'``, ``F''`` at ``s`` from the two reciprocals ``i0 = 1/(s + r0)``, ``i1 = 1/(s + 1)``."""
        a2 = (n0 * i0) * (n0 * i0)
        b2 = (z1 * i1) * (z1 * i1)
        return a2 + b2 - T(1.0), T(-2.0) * (a2 * i0 + b2 * i1), T(6.0) * (a2 * i0 * i0 + b2 * i1 * i1)

    @wp.func
    def ellipse_closest(e0: T, e1: T, ie0: T, ie1: T, y0: T, y1: T):
        if e1 <= T(0.0):  # degenerate ellipse: the segment [-e0, e0] x {0}
            x0 = wp.min(y0, e0)
            f0 = T(1.0)
            if y0 > e0:
                f0 = e0 / y0
            return x0, T(0.0), f0, T(0.0)
        if y1 <= T(0.0):  # on the major axis, outside: the vertex
            return e0, T(0.0), e0 / y0, T(0.0)
        if y0 <= T(0.0):  # on the minor axis, outside: the co-vertex
            return T(0.0), e1, T(0.0), e1 / y1
        z0 = y0 * ie0
        z1 = y1 * ie1
        if z0 * z0 + z1 * z1 <= T(1.0):  # on the ellipse within rounding
            return y0, y1, T(1.0), T(1.0)
        r0 = (e0 * ie1) * (e0 * ie1)
        n0 = r0 * z0
        lo = wp.max(T(0.0), wp.max(z1 - T(1.0), n0 - r0))
        hi = wp.max(lo, wp.sqrt(n0 * n0 + z1 * z1) - T(1.0))  # n0 < 1e11 on any representable trial
        i0 = T(1.0) / (lo + r0)
        i1 = T(1.0) / (lo + T(1.0))
        f, df, d2f = root_f(i0, i1, n0, z1)
        mode = int(2)  # 2: Halley, 1: Newton, 0: bisection
        it = int(0)  # noqa: UP018 (a mutable Warp int, not a constant)
        while it < max_it and f > T(eps) and hi - lo > T(eps) * (T(1.0) + lo):
            it += 1
            den = T(2.0) * df * df - f * d2f
            g = T(2.0) * f * df
            s = T(0.5) * (lo + hi)
            fused = int(0)
            if mode == 2 and den > T(0.0):
                s = lo - g / den
                if s < hi:  # s + r0 = ((lo + r0) den - g) / den, a sum of positives: no division by den first
                    fused = 1
                else:
                    s = hi
            elif mode >= 1 and df < T(0.0):
                s = wp.min(lo - f / df, hi)
            if not s > lo:  # no progress within rounding
                break
            i0s = T(0.0)
            i1s = T(0.0)
            if fused != 0:
                i0s = den / ((lo + r0) * den - g)
                i1s = den / ((lo + T(1.0)) * den - g)
            else:
                i0s = T(1.0) / (s + r0)
                i1s = T(1.0) / (s + T(1.0))
            fs, dfs, d2fs = root_f(i0s, i1s, n0, z1)
            if fs >= T(-eps):  # past the root by rounding only: that is the root too (and the loop ends)
                lo = s
                f = fs
                df = dfs
                d2f = d2fs
                i0 = i0s
                i1 = i1s
            else:  # past the root: Newton from the lower end cannot pass it but by rounding, bisection then
                hi = s
                mode = wp.max(mode - 1, 0)
        return (r0 * y0) * i0, y1 * i1, r0 * i0, i1

    return ellipse_closest


def ellipse_axes(K, mu, M, beta):
    """Constants of a material's scaled yield ellipse (docs/model.md §4), in float64 for the material struct.

    Parameters
    ----------
    K, mu : float
        Bulk and shear modulus (Pa, > 0).
    M, beta : float
        Critical-state slope (> 0) and cohesion ratio (>= 0), (-).

    Returns
    -------
    rho, inv_rho, c, inv_c : float
        ``rho = sqrt(3 mu / K)`` (``q = a rho v``), ``1/rho``, the axis ratio ``c = M / (rho sqrt(1 + 2 beta))``
        of the ellipse ``u^2 + v^2/c^2 = 1`` and ``1/c`` (-); the same formulas as :func:`ellipse_point_func`.
    """
    rho = math.sqrt(3.0 * float(mu) / float(K))
    c = float(M) / (math.sqrt(1.0 + 2.0 * float(beta)) * rho)
    return rho, 1.0 / rho, c, 1.0 / c


@functools.cache
def ellipse_point_axes_func(T):
    """``ellipse_point_axes(p_tr, q_tr, p0, beta, rho, inv_rho, c, inv_c) -> (p, q, xu, xv, a, sgn, fv)``: the
    projection of :func:`ellipse_point_func` for the ellipse constants of :func:`ellipse_axes`, and
    ``fv = xv / v``, the factor by which it scales ``q`` (``q = fv q_tr``)."""
    closest = _ellipse_closest_func(T)

    @wp.func
    def ellipse_point_axes(p_tr: T, q_tr: T, p0: T, beta: T, rho: T, inv_rho: T, c: T, inv_c: T):
        a = T(0.5) * p0 * (T(1.0) + beta)
        pc = T(0.5) * p0 * (T(1.0) - beta)
        ia = T(1.0) / a
        du = p_tr - pc
        u = wp.abs(du) * ia
        v = (q_tr * ia) * inv_rho
        xu = T(0.0)
        xv = T(0.0)
        fu = T(0.0)
        fv = T(0.0)
        if c <= T(1.0):
            xu, xv, fu, fv = closest(T(1.0), c, T(1.0), inv_c, u, v)
        else:
            xv, xu, fv, fu = closest(c, T(1.0), inv_c, T(1.0), v, u)
        p = p0 - a * (T(1.0) - xu)
        sgn = T(1.0)
        if du < T(0.0):  # measured from the nearer tip: exact there, even for beta >> 1
            p = -beta * p0 + a * (T(1.0) - xu)
            sgn = T(-1.0)
        return p, a * rho * xv, xu, xv, a, sgn, fv

    return ellipse_point_axes


@functools.cache
def ellipse_point_func(T):
    """Build ``ellipse_point(p_tr, q_tr, p0, K, mu, M, beta) -> (p, q, xu, xv, c, rho, a, sgn)``.

    The point ``(p, q)`` (Pa) of the yield ellipse of ``p0`` closest to ``(p_tr, q_tr)`` in the energy
    metric ``dp^2/K + dq^2/(3 mu)`` (docs/model.md §4), for ``a = p0 (1 + beta)/2 > 0`` (the caller's
    check), with the scaled coordinates it was found in: ``(xu, xv)`` on the ellipse ``u^2 + v^2/c^2 = 1``
    (``u = |p - pc|/a``, ``v = q/(a rho)``, ``rho = sqrt(3 mu/K)``, ``c = M/(rho sqrt(1 + 2 beta))``) and
    ``sgn`` = -1 when the point is measured from the tensile tip (``p_tr < pc``), +1 else. The projection
    of the bonded return (which needs the scaled point for its homothety derivative, and whose ``beta``
    softens, so that it forms the axes per trial); Cam-Clay's hot path takes the constants from the
    material (:func:`camclay_project_axes_func`).
    """
    point = ellipse_point_axes_func(T)

    @wp.func
    def ellipse_point(p_tr: T, q_tr: T, p0: T, K: T, mu: T, M: T, beta: T):
        rho = wp.sqrt(T(3.0) * mu / K)  # q = a rho v
        s12 = wp.sqrt(T(1.0) + T(2.0) * beta)
        w = T(1.0) / (s12 * rho)
        c = M * w
        p, q, xu, xv, a, sgn, fv = point(p_tr, q_tr, p0, beta, rho, s12 * w, c, T(1.0) / c)
        return p, q, xu, xv, c, rho, a, sgn

    return ellipse_point
