"""Bonded (structured) Cam-Clay for the weak layer: bond, yield, implicit return, column averaging.

The weak layer of a snowpack is strong while its bonds hold and collapses once
they break (Gaume et al. 2018: "cohesion loss coupled with volumetric
collapse"). Gaume's Cam-Clay (:mod:`mpm_warp.kernels.camclay`) has one
hardening variable and cannot do both (docs/model.md §3b), so the weak layer carries
a bonded part in its yield ellipse that decays with the plastic work done, as in
structured / destructuring Cam-Clay (Rouainia and Muir Wood 2000; Liu and
Carter 2002). Stresses are Kirchhoff (Pa), compression positive (docs/model.md §1):

    y(p, q)  = (1 + 2 beta_e) q^2 + M^2 (p + beta_e p0)(p - p0)   (<= 0; docs/model.md §2)
    p0       = p0_int(log_Jp) + b p_bond                          (consolidation, Pa)
    beta_e   = beta b                                             (cohesion ratio)
    p0_int   = max(K sinh(xi max(-log_Jp, 0)), p0_floor)          (intrinsic: camclay_p0)
    b        = max(0, 1 - kappa / kappa_s)                        (bond, 1 intact, 0 gone)

State per particle: ``log_Jp = ln det F_P`` (as camclay) and ``kappa`` (J/m^3),
the plastic work the layer has done per unit volume,

    kappa += tau_new : d = p_new (p_tr - p_new)/K + sqrt(2/3) q_new |dev d|,   d = eps_tr - eps_new,

the work of the returned (new) Kirchhoff stress on the principal plastic Hencky
strain increment of the return. Why this measure: a bond costs the same energy
however it breaks. Bonds break in shear and in compaction; a weak layer's
measured toughnesses in the two modes are of one order (G_Ic = 0.56 and G_IIc
= 0.79 J/m^2, Weissgraeber and Rosendahl 2023, WEAC), and in a PST the layer
at the crack tip fails mostly in compaction under the bending slab. The
plastic strain norm (the "damage strain" of Rouainia and Muir Wood 2000, an
earlier version of this module) makes compaction about twice as costly as
shear for the same bond loss (a PST's compacting process zone then dissipated
~5 J/m^2 against 1.4 in shear; measured on the PST scene); the work makes the
energy to debond one number, ``kappa_s D_wl`` per unit area, in every mode. It
is invariant and non-negative: with the associative flow the work of the new
stress on ``d`` is ``dgamma (p y_p + q y_q) >= -dgamma y(0) >= 0`` (the origin
lies inside the ellipse); round-off below zero is cut. In plastic simple shear
it is ``tau gamma_p``: the shear stress times the plastic slip over the
thickness. The bond is linear in ``kappa`` (Rouainia and Muir Wood use an
exponential decay) so that it ends at a finite work, as the linear softening
of a cohesive crack (Bazant and Oh 1983).

Regularisation (crack band, Bazant and Oh 1983). ``kappa`` is meant to be the
mean over the layer thickness at one bed position: after every step the
engine replaces the ``kappa`` of each weak-layer particle by the mean of its
lattice column (:func:`kappa_column_sum_kernel`, :func:`kappa_column_mean_kernel`).
The bond then lives on the work done on the whole thickness per unit area,
``D_wl kappa`` (J/m^2): the layer is debonded once it has dissipated ``D_wl
kappa_s``, however many cells span it and however the strain localises inside
it, so the energy per unit crack area does not depend on dx (the band is the
layer). Within a step a particle's return sees its own increment; the mean
comes after the step (a difference of the order of one step's increment).
``kappa_s`` from a fracture energy or a softening displacement:
:mod:`mpm_warp.scenes.weak_layer.calibration`.

Return mapping (docs/model.md §4, SI Note 1), fully implicit. The discrete flow rule
``eps_tr - eps_new = dgamma dy/dtau`` is solved with the surface of the *new*
state ``(log_Jp_new, kappa_new)``: the new ``(p, q)`` is the point of the
ellipse of the new state closest to the trial in the energy metric
``dp^2/K + dq^2/(3 mu)``. Two nested scalar root finds around camclay's
closest-point solver:

* volumetric (bond fixed): ``g(L) = L - L_n - (p*(L) - p_tr)/K = 0``, ``p*(L)``
  the closest point on the ellipse of ``p0_int(L) + b p_bond``. A root lies
  between ``L_n`` and ``L_n + (pc(L_n) - p_tr)/K`` (``p*`` lies between the trial
  and the apex ``pc = p0 (1 - beta_e)/2``, which moves the right way when
  ``beta <= 1``). Newton with the exact derivative, kept in that bracket: with
  the bond fixed the ellipse is a homothety of ``p0`` about the origin, so in
  the Euclidean coordinates ``(p, q/rho)``, ``rho = sqrt(3 mu/K)``,
  ``dZ/dp0 = [Z - t (t.Z)/(1 + d k)]/p0`` (``Z`` the closest point, ``t`` its
  unit tangent, ``d`` its distance to the trial, ``k`` the curvature there).
  Where ``g`` decreases (dilation softening faster than the elasticity,
  ``(1 - beta)/2 xi cosh(xi x) > 1`` on the dry side: several roots), doubling
  steps walk to the sign change nearest the start instead;
* bond: ``f(kappa) = kappa - kappa_n - dkappa(kappa) = 0`` with the volumetric
  problem solved inside, ``dkappa`` the work of the increment to the surface of
  ``kappa`` (a weaker surface is farther, its stress lower: ``f`` rises from
  ``-dkappa(kappa_n) <= 0`` at ``kappa_n``, and its slope stays positive unless
  the softening outruns the elasticity, a material snap-back, which the
  calibration of :mod:`mpm_warp.scenes.weak_layer.calibration` does not
  produce). Secant steps from ``kappa_n`` and the explicit estimate (the
  projection on the current surface), kept in ``[kappa_n, max(kappa_s, kappa_n
  + dkappa(b = 0))]`` (``f >= 0`` at the upper end) with bisection as the
  fall-back.

Both stop on their residual (``g``, ``f``) at its rounding level, about
``2 eps (1 + |state|)``, so the returned state lies on its own surface: no
period-2 cycling of an explicit hardening (camclay cycles when ``(1 - beta)/2
xi cosh(xi x) > 1`` and the increment is large), projecting again changes
nothing, and the bond drops by the work the increment costs. A
yielding point costs a projection plus two or three (bond) times two
(volumetric) Newton evaluations: 5.2x camclay's return at a crack tip, 2.5x
once the bond is gone (CPU, float32, ``benchmarks/perf/bonded_return_cost.py``). The
elastic trial is one yield check and returns its inputs bit for bit.

Numerical constants (fixed, not model parameters): ``SINGULAR_VALUE_FLOOR``
and the ``p0_int`` cap as camclay; at most :data:`_MAX_ITERATIONS` iterations
per root find.
"""

import functools
import math

import warp as wp

from .camclay import SINGULAR_VALUE_FLOOR, camclay_p0_func, camclay_yield_func, ellipse_point_func
from .types import vec3

__all__ = [
    "bond_func",
    "bonded_camclay_return_func",
    "bonded_camclay_return_strain_func",
    "bonded_p0_func",
    "bonded_yield_func",
    "kappa_column_mean_kernel",
    "kappa_column_sum_kernel",
    "column_sums_zero_kernel",
]

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

    The yield function of the module docstring at the state ``(log_jp, kappa)``;
    ``y <= 0`` inside.
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
    homothety derivative of the module docstring; 0 inside). Same scaled
    coordinates and tip handling as ``camclay_return``: ``u = (p - pc)/a``,
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
    """Implicit volumetric hardening at a fixed bond ``b``: root ``L`` of ``g`` (module docstring).

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
def bonded_camclay_return_func(T):
    """Build the bonded Cam-Clay return mapping ``bonded_camclay_return`` for scalar type ``T``.

    Signature of the returned ``wp.func``::

        bonded_camclay_return(sig: vec3, log_jp: T, kappa: T, mu: T, lam: T, M: T, beta: T, xi: T,
                              p0_floor: T, p_bond: T, kappa_s: T)
            -> (sig_new: vec3, log_jp_new: T, kappa_new: T, yielded: int32)

    Parameters
    ----------
    sig : vec3
        Singular values of the trial elastic deformation gradient (dimensionless,
        as from ``wp.svd3``: descending, the last possibly negative or tiny;
        floored at ``SINGULAR_VALUE_FLOOR`` before ``ln``). ``U``, ``V`` are kept.
    log_jp : T
        ``ln det F_P`` (dimensionless): intrinsic hardening state.
    kappa : T
        Plastic work done per unit volume (J/m^3, >= 0), the layer-column mean.
    mu, lam : T
        Lame parameters (Pa).
    M, beta, xi : T
        Critical-state slope (> 0), cohesion ratio of the intact layer (in
        [0, 1]), hardening coefficient (> 0); dimensionless.
    p0_floor : T
        Floor of ``p0_int`` (Pa, > 0; e.g. 1e-5 K).
    p_bond : T
        Bonded part of the consolidation pressure of the intact layer (Pa, >= 0).
    kappa_s : T
        ``kappa`` at which the bond is gone (J/m^3, > 0; ``inf`` keeps it).

    Returns
    -------
    sig_new : vec3
        Singular values of the new ``F_E``; the input ``sig`` bit for bit when
        the trial is elastic (``y <= 0``).
    log_jp_new : T
        ``log_jp + tr(eps_tr) - tr(eps_new)``.
    kappa_new : T
        ``kappa`` plus the work of the new stress on ``eps_tr - eps_new`` (J/m^3).
    yielded : int32
        1 if the state was returned, 0 otherwise.

    Notes
    -----
    Implicit in both state variables (module docstring): ``(p_new, q_new)``
    is the energy-metric closest point on the ellipse of ``(log_jp_new,
    kappa_new)`` up to the root-find tolerance (a few rounding units).
    ``dev(eps)`` keeps its direction (scaled by ``q_new/q_tr``); ``q_tr = 0``
    goes to a tip with ``dev eps = 0``. ``q_new <= q_tr``, ``p_new`` is
    bounded by the trial and the apex, so ``sig_new`` is finite and positive.
    """
    v3 = vec3(T)
    s_floor = SINGULAR_VALUE_FLOOR
    core = bonded_camclay_return_strain_func(T)

    @wp.func
    def bonded_camclay_return(sig: v3, log_jp: T, kappa: T, mu: T, lam: T, M: T, beta: T, xi: T, p0_floor: T,
                              p_bond: T, kappa_s: T):
        sf = T(s_floor)
        e = v3(wp.log(wp.max(sig[0], sf)), wp.log(wp.max(sig[1], sf)), wp.log(wp.max(sig[2], sf)))
        e_new, lj_new, k_new, y = core(e, log_jp, kappa, mu, lam, M, beta, xi, p0_floor, p_bond, kappa_s)
        if y == 0:
            return sig, log_jp, kappa, y
        return v3(wp.exp(e_new[0]), wp.exp(e_new[1]), wp.exp(e_new[2])), lj_new, k_new, y

    return bonded_camclay_return


@functools.cache
def bonded_camclay_return_strain_func(T):
    """Build the return in principal Hencky strains, the core of :func:`bonded_camclay_return_func`.

    Signature of the returned ``wp.func``::

        bonded_camclay_return_strain(eps: vec3, log_jp: T, kappa: T, mu: T, lam: T, M: T, beta: T, xi: T,
                                     p0_floor: T, p_bond: T, kappa_s: T)
            -> (eps_new: vec3, log_jp_new: T, kappa_new: T, yielded: int32)

    ``eps`` are the principal Hencky strains of the trial (-), e.g. ``1/2 log1p`` of the
    eigenvalues of ``F F^T - I`` (``kernels/constitutive.py``), which keeps the relative
    precision of small strains; everything else as :func:`bonded_camclay_return_func`.
    An elastic trial returns ``eps`` itself.
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




# ----------------------------------------------------------------------------- column averaging
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
