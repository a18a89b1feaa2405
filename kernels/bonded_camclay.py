"""Bonded (structured) Cam-Clay of the weak layer: bond, surface and the implicit return mapping.

The weak layer's yield ellipse carries a bonded part that decays with the plastic work done, so the layer
is strong while its bonds hold and collapses once they break (docs/model.md §3b). Stresses are Kirchhoff
(Pa), compression positive. The return is implicit in both state variables, two nested scalar root finds
around camclay's closest-point projection (docs/model.md §3b, the projection §4); the column mean is in
``kernels/crack_band.py``.
"""

import functools
import math

import warp as wp

from .camclay import SINGULAR_VALUE_FLOOR, camclay_p0_func, camclay_yield_func, ellipse_point_func
from .types import vec3

__all__ = ["bond_func", "bonded_camclay_return_strain_func", "bonded_p0_func", "bonded_yield_func"]

_SQRT6 = math.sqrt(6.0)
_X_CAP = math.asinh(-3.0 * math.log(SINGULAR_VALUE_FLOOR))  # xi (-log_jp) where camclay caps p0_int
_MAX_ITERATIONS = 100


def _eps(T):
    return 2.0**-23 if T == wp.float32 else 2.0**-52


@functools.cache
def bond_func(T):
    """Build ``bond(kappa, kappa_s) -> b``: ``max(0, 1 - kappa/kappa_s)`` (dimensionless).

    ``kappa_s = inf`` keeps the bond (``b = 1``); ``kappa_s = 0`` means no bond.
    """

    @wp.func
    def bond(kappa: T, kappa_s: T):
        if kappa >= kappa_s:
            return T(0.0)
        return T(1.0) - kappa / kappa_s

    return bond


@functools.cache
def bonded_p0_func(T):
    """Build ``bonded_p0(log_jp, kappa, K, xi, p0_floor, p_bond, kappa_s) -> (p0, b)``.

    ``p0 = p0_int(log_jp) + b p_bond`` (Pa) with ``p0_int`` of
    :func:`mpm_warp.kernels.camclay.camclay_p0_func` and ``b`` of :func:`bond_func`.
    The cohesion ratio of that surface is ``beta b``.
    """
    p0_int = camclay_p0_func(T)
    bond = bond_func(T)

    @wp.func
    def bonded_p0(log_jp: T, kappa: T, K: T, xi: T, p0_floor: T, p_bond: T, kappa_s: T):
        b = bond(kappa, kappa_s)
        return p0_int(log_jp, K, xi, p0_floor) + b * p_bond, b

    return bonded_p0


@functools.cache
def bonded_yield_func(T):
    """Build ``bonded_yield(p, q, log_jp, kappa, K, M, beta, xi, p0_floor, p_bond, kappa_s) -> y`` (Pa^2).

    ``y = (1 + 2 beta b) q^2 + M^2 (p + beta b p0)(p - p0)`` with ``(p0, b)`` of :func:`bonded_p0_func` at
    the state ``(log_jp, kappa)`` (docs/model.md §3b); ``y <= 0`` inside.
    """
    p0_fn = bonded_p0_func(T)
    yield_fn = camclay_yield_func(T)

    @wp.func
    def bonded_yield(p: T, q: T, log_jp: T, kappa: T, K: T, M: T, beta: T, xi: T, p0_floor: T, p_bond: T,
                     kappa_s: T):
        p0, b = p0_fn(log_jp, kappa, K, xi, p0_floor, p_bond, kappa_s)
        return yield_fn(p, q, p0, M, beta * b)

    return bonded_yield


@functools.cache
def _project_func(T):
    """Closest point of the filled ellipse ``(p0, beta_e)`` to ``(p_tr, q_tr)`` in the energy metric.

    Returns ``(p, q, dp_dp0)``: the point (the trial itself when inside) and the
    derivative of its ``p`` with respect to ``p0`` at fixed ``beta_e`` (the
    homothety derivative, docs/model.md §3b; 0 inside). Same scaled
    coordinates and tip handling as camclay's projection: ``u = (p - pc)/a``,
    ``v = q/(a rho)``, ellipse ``u^2 + v^2/c^2 = 1``, ``c = M/(rho sqrt(1 + 2 beta_e))``.
    """
    ellipse_point = ellipse_point_func(T)
    yield_fn = camclay_yield_func(T)

    @wp.func
    def project(p_tr: T, q_tr: T, p0: T, beta_e: T, M: T, K: T, mu: T):
        if yield_fn(p_tr, q_tr, p0, M, beta_e) <= T(0.0):
            return p_tr, q_tr, T(0.0)
        a = T(0.5) * p0 * (T(1.0) + beta_e)
        if a <= T(0.0):
            return T(0.0), T(0.0), T(0.0)
        p, q, xu, xv, c, rho, a, sgn = ellipse_point(p_tr, q_tr, p0, K, mu, M, beta_e)
        # homothety derivative in the Euclidean coordinates (P, Q) = (p, q/rho):
        # normal ~ (sgn xu, xv/c^2), tangent t ~ (-xv/c^2, sgn xu), curvature 1/(a c^2 (xu^2 + xv^2/c^4)^(3/2))
        n2 = xv / (c * c)
        nn = wp.sqrt(xu * xu + n2 * n2)
        tP = -n2 / nn
        tQ = sgn * xu / nn
        d = wp.sqrt((p_tr - p) * (p_tr - p) + (q_tr - q) * (q_tr - q) / (rho * rho))
        dk = d / (a * c * c * nn * nn * nn)
        tz = tP * p + tQ * q / rho
        return p, q, (p - tP * tz / (T(1.0) + dk)) / p0

    return project


@functools.cache
def _volumetric_solve_func(T):
    """Implicit volumetric hardening at a fixed bond ``b``: root ``L`` of ``g`` (docs/model.md §3b).

    Returns ``(L, p, q)`` with ``(p, q)`` the closest point on the surface of
    ``(L, b)``. Newton from ``L_guess`` kept in the bracket (bisection when a step
    leaves it; doubling steps where ``g`` decreases); stops when ``|g|`` is at
    its rounding level ``2 eps (1 + |L| + |L_n| + (|p| + |p_tr|)/K)``, or the
    bracket or the step vanish.
    """
    project = _project_func(T)
    p0_int = camclay_p0_func(T)
    eps = _eps(T)
    two_eps = 2.0 * eps
    x_cap = _X_CAP
    max_it = _MAX_ITERATIONS

    @wp.func
    def p0_int_and_slope(L: T, K: T, xi: T, p0_floor: T):
        """camclay's ``p0_int`` (Pa) and its slope ``d p0_int / d L`` (Pa; 0 at the floor and the cap)."""
        p = p0_int(L, K, xi, p0_floor)
        x = xi * wp.max(-L, T(0.0))
        slope = T(0.0)
        if x < T(x_cap) and K * wp.sinh(x) > p0_floor:
            slope = -K * xi * wp.cosh(x)
        return p, slope

    @wp.func
    def volumetric_solve(p_tr: T, q_tr: T, L_n: T, L_guess: T, b: T, K: T, mu: T, M: T, beta: T, xi: T,
                         p0_floor: T, p_bond: T):
        beta_e = beta * b
        bp = b * p_bond
        d = (T(0.5) * (p0_int(L_n, K, xi, p0_floor) + bp) * (T(1.0) - beta_e) - p_tr) / K
        lo = L_n + wp.min(d, T(0.0))
        hi = L_n + wp.max(d, T(0.0))
        x = wp.min(wp.max(L_guess, lo), hi)
        p = p_tr
        q = q_tr
        walk = T(0.0)
        it = int(0)  # noqa: UP018 (a mutable Warp int)
        while it < max_it:
            it += 1
            p0i, slope = p0_int_and_slope(x, K, xi, p0_floor)
            p, q, dp = project(p_tr, q_tr, p0i + bp, beta_e, M, K, mu)
            g = x - L_n - (p - p_tr) / K
            # g is the mismatch between the state the surface was built from and the plastic volume of the
            # returned point: converged at its rounding level (strains resolve eps (1 + |eps|) from ln sig)
            if wp.abs(g) <= T(two_eps) * (T(1.0) + wp.abs(x) + wp.abs(L_n) + (wp.abs(p) + wp.abs(p_tr)) / K):
                break
            if g < T(0.0):
                lo = x
            else:
                hi = x
            # Newton; where g decreases (dilation softening faster than the elasticity: several roots) a walk
            # towards the sign change with doubling steps from |g|, which finds the root nearest the start
            dg = T(1.0) - dp * slope / K
            x_new = x - g / dg
            if dg <= T(0.0):
                walk = wp.max(wp.abs(g), T(2.0) * walk)
                x_new = x - wp.sign(g) * walk
            if not (x_new > lo and x_new < hi):
                x_new = T(0.5) * (lo + hi)
            if x_new == x or hi - lo <= T(eps) * (wp.abs(lo) + wp.abs(hi)):
                break
            x = x_new
        return x, p, q

    return volumetric_solve


@functools.cache
def bonded_camclay_return_strain_func(T):
    """Build the bonded Cam-Clay return mapping in principal Hencky strains (docs/model.md §3b, §4).

    Signature of the returned ``wp.func``::

        bonded_camclay_return_strain(eps: vec3, log_jp: T, kappa: T, mu: T, lam: T, M: T, beta: T, xi: T,
                                     p0_floor: T, p_bond: T, kappa_s: T)
            -> (eps_new: vec3, log_jp_new: T, kappa_new: T, yielded: int32)

    Parameters
    ----------
    eps : vec3
        Principal Hencky strains of the trial elastic state (-), e.g. ``1/2 log1p`` of the eigenvalues of
        ``F F^T - I`` (``kernels/principal.py``), which keeps the relative precision of small strains.
    log_jp : T
        ``ln det F_P`` (-): the intrinsic hardening state.
    kappa : T
        Plastic work done per unit volume (J/m^3, >= 0), the layer-column mean.
    mu, lam : T
        Lame parameters (Pa).
    M, beta, xi : T
        Critical-state slope (> 0), cohesion ratio of the intact layer (in [0, 1]), hardening
        coefficient (> 0); (-).
    p0_floor : T
        Floor of ``p0_int`` (Pa, > 0; e.g. 1e-5 K).
    p_bond : T
        Bonded part of the consolidation pressure of the intact layer (Pa, >= 0).
    kappa_s : T
        ``kappa`` at which the bond is gone (J/m^3, > 0; ``inf`` keeps it).

    Returns
    -------
    eps_new : vec3
        New principal Hencky strains (-): ``dev(eps)`` scaled by ``q_new/q_tr``, ``tr = -p_new/K``;
        ``(p_new, q_new)`` the energy-metric closest point on the ellipse of the *new* state, to a few
        rounding units. ``eps`` itself, bit for bit, for an elastic trial (``y <= 0``).
    log_jp_new : T
        ``log_jp + tr(eps) - tr(eps_new)`` (-).
    kappa_new : T
        ``kappa`` plus the work of the new stress on ``eps - eps_new`` (J/m^3).
    yielded : int32
        1 if the state was returned, 0 otherwise.
    """
    v3 = vec3(T)
    sqrt6 = _SQRT6
    sqrt2_3 = math.sqrt(2.0 / 3.0)
    eps = _eps(T)
    two_eps = 2.0 * eps
    max_it = _MAX_ITERATIONS
    yield_fn = camclay_yield_func(T)
    p0_fn = bonded_p0_func(T)
    bond = bond_func(T)
    solve = _volumetric_solve_func(T)
    project = _project_func(T)

    @wp.func
    def dkappa(p: T, q: T, p_tr: T, q_tr: T, K: T, mu: T):
        # plastic work of the new stress (p, q) on the increment to it from the trial (J/m^3)
        ed = (q_tr - q) / (T(sqrt6) * mu)
        return wp.max(p * (p_tr - p) / K + T(sqrt2_3) * q * ed, T(0.0))

    @wp.func
    def bonded_camclay_return_strain(e: v3, log_jp: T, kappa: T, mu: T, lam: T, M: T, beta: T, xi: T,
                                     p0_floor: T, p_bond: T, kappa_s: T):
        tr = e[0] + e[1] + e[2]
        m = tr / T(3.0)
        dev = v3(e[0] - m, e[1] - m, e[2] - m)
        if e[0] == e[1] and e[1] == e[2]:
            dev = v3(T(0.0), T(0.0), T(0.0))
        K = lam + T(2.0) / T(3.0) * mu
        p_tr = -K * tr
        q_tr = T(sqrt6) * mu * wp.length(dev)
        p0, b_n = p0_fn(log_jp, kappa, K, xi, p0_floor, p_bond, kappa_s)
        if yield_fn(p_tr, q_tr, p0, M, beta * b_n) <= T(0.0):
            return e, log_jp, kappa, wp.int32(0)

        L = log_jp
        p = p_tr
        q = q_tr
        if b_n <= T(0.0):  # bond gone: the volumetric problem alone
            L, p, q = solve(p_tr, q_tr, log_jp, log_jp, b_n, K, mu, M, beta, xi, p0_floor, p_bond)
        else:
            # the explicit estimate dk0 of the increment: projection on the current surface
            p, q, dp = project(p_tr, q_tr, p0, beta * b_n, M, K, mu)
            dk0 = dkappa(p, q, p_tr, q_tr, K, mu)
            # secant on f(k) = k - kappa - dkappa(k) from (kappa, -dk0) and kappa + dk0, kept in the
            # bracket [lo, hi] (f(lo) <= 0 <= f(hi)); the upper end max(kappa_s, kappa + dkappa(b = 0))
            # is computed only when a secant step leaves the bracket; bisection then
            lo = kappa
            hi = kappa
            hi_known = int(0)  # noqa: UP018 (a mutable Warp int)
            x0 = kappa
            f0 = -dk0
            x1 = kappa + dk0
            it = int(0)  # noqa: UP018
            while it < max_it:
                it += 1
                L, p, q = solve(p_tr, q_tr, log_jp, L, bond(x1, kappa_s), K, mu, M, beta, xi, p0_floor, p_bond)
                dk1 = dkappa(p, q, p_tr, q_tr, K, mu)
                f1 = x1 - kappa - dk1
                if wp.abs(f1) <= T(two_eps) * (T(1.0) + x1 + kappa + dk1):  # the rounding level of f
                    break
                if f1 < T(0.0):
                    lo = x1
                else:
                    hi = x1
                    hi_known = 1
                x2 = x1
                if f1 != f0:
                    x2 = x1 - f1 * (x1 - x0) / (f1 - f0)
                if not (x2 > lo and (hi_known == 0 or x2 < hi)):
                    if hi_known == 0:
                        Lh, ph, qh = solve(p_tr, q_tr, log_jp, L, T(0.0), K, mu, M, beta, xi, p0_floor, p_bond)
                        hi = wp.max(kappa_s, kappa + dkappa(ph, qh, p_tr, q_tr, K, mu))
                        hi_known = 1
                        if hi > kappa_s:  # f(hi) = 0: the bond is gone within this increment
                            x1 = hi
                            L = Lh
                            p = ph
                            q = qh
                            break
                    x2 = T(0.5) * (lo + hi)
                if x2 == x1 or (hi_known != 0 and hi - lo <= T(eps) * (lo + hi)):
                    break
                x0 = x1
                f0 = f1
                x1 = x2

        scale = T(0.0)
        if q_tr > T(0.0):
            scale = wp.min(q / q_tr, T(1.0))
        m_new = -p / (T(3.0) * K)
        e_new = v3(dev[0] * scale + m_new, dev[1] * scale + m_new, dev[2] * scale + m_new)
        # bookkeeping from the stored strains themselves: d = eps_tr - eps_new; the work of the new stress on it
        dv = tr - T(3.0) * m_new
        dd = wp.length(dev) * (T(1.0) - scale)
        work = wp.max(-p * dv + T(sqrt2_3) * q * dd, T(0.0))
        return e_new, log_jp + dv, kappa + work, wp.int32(1)

    return bonded_camclay_return_strain
