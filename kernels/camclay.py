"""Modified Cam-Clay with cohesion: yield function, hardening and the closest-point return mapping.

Implements docs/model.md §2-4 (Gaume et al. 2018, Supplementary Note 1). Stresses are Kirchhoff (Pa),
compression positive; strains are principal Hencky strains. Every device function comes from a cached
factory of the scalar type ``T`` (``wp.float32`` or ``wp.float64``). The projection onto the ellipse
(``kernels/ellipse.py``) is shared with the bonded weak layer (``kernels/bonded_camclay.py``).
"""

import functools
import math

import warp as wp

from .ellipse import ellipse_axes, ellipse_point_axes_func, ellipse_point_func
from .types import vec3

__all__ = [
    "SINGULAR_VALUE_FLOOR",
    "camclay_p0_func",
    "camclay_pq_func",
    "camclay_project_axes_func",
    "camclay_project_func",
    "ellipse_axes",
    "ellipse_point_func",
    "camclay_return_strain_func",
    "camclay_yield_func",
    "initial_log_jp",
]

SINGULAR_VALUE_FLOOR = 1.0e-6
"""Floor on singular values before ``ln`` (dimensionless; fixed, not tunable): an inverted or nearly singular
``F_E`` gives finite strains, ``|eps_i| <= 13.8`` (docs/model.md §4). The engine passes the same value as
``s_floor``; ``p0`` is capped at the pressure of the most compressed representable state, ``-3 K ln(floor)``."""

_SQRT6 = math.sqrt(6.0)
_P0_CAP_OVER_K = -3.0 * math.log(SINGULAR_VALUE_FLOOR)


def initial_log_jp(p0_ini, K, xi):
    """Initial hardening state for a consolidation pressure (docs/model.md §3).

    Parameters
    ----------
    p0_ini : float
        Initial consolidation pressure ``p0(0)`` (Pa, >= 0).
    K : float
        Bulk modulus (Pa, > 0).
    xi : float
        Hardening coefficient (dimensionless, > 0).

    Returns
    -------
    float
        ``log_Jp(0) = -asinh(p0_ini / K) / xi`` (dimensionless, <= 0).
    """
    return -math.asinh(float(p0_ini) / float(K)) / float(xi)


@functools.cache
def camclay_yield_func(T):
    """Build ``camclay_yield(p, q, p0, M, beta) -> T`` (Pa^2).

    ``y = (1 + 2 beta) q^2 + M^2 (p + beta p0)(p - p0)`` (docs/model.md §2);
    ``y <= 0`` inside the ellipse through ``p = -beta p0`` and ``p = p0``.
    """

    @wp.func
    def camclay_yield(p: T, q: T, p0: T, M: T, beta: T):
        return (T(1.0) + T(2.0) * beta) * q * q + M * M * (p + beta * p0) * (p - p0)

    return camclay_yield


@functools.cache
def camclay_p0_func(T):
    """Build ``camclay_p0(log_jp, K, xi, p0_floor) -> T``: consolidation pressure (Pa).

    ``p0 = max(K sinh(xi max(-log_jp, 0)), p0_floor)`` (docs/model.md §3),
    capped at ``-3 K ln(SINGULAR_VALUE_FLOOR)`` (about 41.4 K) so it stays finite.
    ``sinh x`` of an argument up to 1/4 (most snow: ``xi |log_jp|`` of a few 1e-3) by its
    Taylor series to ``x^9`` (float32; ``x^15`` float64): the first omitted term is below
    ``x 4^-10 / 11! = 2e-14 x`` (``4^-16 / 17! = 6e-25 x``), far below rounding, at a fifth of
    the cost of the library ``sinh``, which takes larger arguments.
    """
    cap = _P0_CAP_OVER_K
    x_cap = math.asinh(cap)
    # Horner in x^2: sinh x = x (1 + x^2/(2 3) (1 + x^2/(4 5) (1 + ...)))
    n_terms = 4 if T == wp.float32 else 7
    inv = [1.0 / ((2 * k) * (2 * k + 1)) for k in range(n_terms, 0, -1)]

    @wp.func
    def camclay_p0(log_jp: T, K: T, xi: T, p0_floor: T):
        x = wp.min(xi * wp.max(-log_jp, T(0.0)), T(x_cap))
        sh = T(0.0)
        if x <= T(0.25):
            x2 = x * x
            e = T(1.0)
            for j in range(wp.static(n_terms)):  # unrolled: constant bounds
                e = T(1.0) + (x2 * e) * T(wp.static(inv[j]))
            sh = x * e
        else:
            sh = wp.sinh(x)
        return wp.max(K * sh, p0_floor)

    return camclay_p0


@functools.cache
def camclay_pq_func(T):
    """Build ``camclay_pq(sig, mu, lam) -> (p, q)`` from singular values of ``F_E``.

    ``sig`` (vec3, dimensionless) is floored at ``SINGULAR_VALUE_FLOOR``;
    returns ``p = -K tr(eps)`` and ``q = sqrt(6) mu |dev eps|`` (Pa, docs/model.md
    section 1), equal to ``-tr(tau)/3`` and ``sqrt(3/2)|dev tau|`` of the Hencky law.
    """
    v3 = vec3(T)
    s_floor = SINGULAR_VALUE_FLOOR
    sqrt6 = _SQRT6

    @wp.func
    def camclay_pq(sig: v3, mu: T, lam: T):
        sf = T(s_floor)
        eps = v3(wp.log(wp.max(sig[0], sf)), wp.log(wp.max(sig[1], sf)), wp.log(wp.max(sig[2], sf)))
        tr = eps[0] + eps[1] + eps[2]
        m = tr / T(3.0)
        dev = v3(eps[0] - m, eps[1] - m, eps[2] - m)
        if eps[0] == eps[1] and eps[1] == eps[2]:
            dev = v3(T(0.0), T(0.0), T(0.0))
        K = lam + T(2.0) / T(3.0) * mu
        return -K * tr, T(sqrt6) * mu * wp.length(dev)

    return camclay_pq


@functools.cache
def camclay_project_axes_func(T):
    """Build ``camclay_project_axes(p_tr, q_tr, p0, beta, rho, inv_rho, c, inv_c) -> (p_new, q_new, scale)``.

    :func:`camclay_project_func` for the ellipse constants of the material (:func:`ellipse_axes`), and
    ``scale = min(q_new / q_tr, 1)`` (-), the factor of the deviatoric strain, from the root's reciprocal
    instead of a division. Stress-free (and ``scale = 0``) for ``p0 <= 0``.
    """
    point = ellipse_point_axes_func(T)

    @wp.func
    def camclay_project_axes(p_tr: T, q_tr: T, p0: T, beta: T, rho: T, inv_rho: T, c: T, inv_c: T):
        p_new = T(0.0)
        q_new = T(0.0)
        scale = T(0.0)
        if T(0.5) * p0 * (T(1.0) + beta) > T(0.0):
            p_new, q_new, xu, xv, a, sgn, fv = point(p_tr, q_tr, p0, beta, rho, inv_rho, c, inv_c)
            scale = wp.min(fv, T(1.0))
        return p_new, q_new, scale

    return camclay_project_axes


@functools.cache
def camclay_project_func(T):
    """Build ``camclay_project(p_tr, q_tr, p0, K, mu, M, beta) -> (p_new, q_new)`` (Pa).

    The point of the yield ellipse of ``p0`` closest to a trial ``(p_tr, q_tr)`` outside it, in the
    energy metric ``dp^2/K + dq^2/(3 mu)`` (:func:`ellipse_point_func`); stress-free for ``p0 <= 0``.
    """
    ellipse_point = ellipse_point_func(T)

    @wp.func
    def camclay_project(p_tr: T, q_tr: T, p0: T, K: T, mu: T, M: T, beta: T):
        p_new = T(0.0)
        q_new = T(0.0)
        if T(0.5) * p0 * (T(1.0) + beta) > T(0.0):
            p_new, q_new, xu, xv, c, rho, a, sgn = ellipse_point(p_tr, q_tr, p0, K, mu, M, beta)
        return p_new, q_new

    return camclay_project


@functools.cache
def camclay_return_strain_func(T):
    """Build the Cam-Clay return mapping in principal Hencky strains (docs/model.md §4).

    Signature of the returned ``wp.func``::

        camclay_return_strain(eps: vec3, log_jp: T, mu: T, lam: T, M: T, beta: T, xi: T,
                              p0_floor: T) -> (eps_new: vec3, log_jp_new: T, yielded: int32)

    Parameters
    ----------
    eps : vec3
        Principal Hencky strains of the trial elastic state (-): ``1/2 log1p`` of the eigenvalues of
        ``F F^T - I`` (``kernels/principal.py``) or ``ln max(s, SINGULAR_VALUE_FLOOR)`` of its singular values.
    log_jp : T
        Hardening state ``ln det F_P`` (-).
    mu, lam : T
        Lame parameters (Pa).
    M, beta, xi : T
        Slope of the critical state line (> 0), cohesion ratio (>= 0), hardening coefficient (> 0); (-).
    p0_floor : T
        Floor of ``p0`` (Pa; e.g. 1e-5 K, above ~1e-20 K so that the scaled trial stays representable).

    Returns
    -------
    eps_new : vec3
        Principal Hencky strains of the new elastic state (-), in the trial's principal directions:
        ``dev(eps_new) = dev(eps) q_new/q_tr``, ``tr(eps_new) = -p_new/K``. ``eps`` itself, bit for bit,
        for an elastic trial (``y <= 0``).
    log_jp_new : T
        ``log_jp + tr(eps) - tr(eps_new)`` (-): hardening applied after the projection, explicit in ``p0``.
    yielded : int32
        1 if the trial was projected, 0 otherwise.
    """
    v3 = vec3(T)
    sqrt6 = _SQRT6
    yield_fn = camclay_yield_func(T)
    p0_fn = camclay_p0_func(T)
    project = camclay_project_func(T)

    @wp.func
    def camclay_return_strain(eps: v3, log_jp: T, mu: T, lam: T, M: T, beta: T, xi: T, p0_floor: T):
        tr = eps[0] + eps[1] + eps[2]
        m = tr / T(3.0)
        dev = v3(eps[0] - m, eps[1] - m, eps[2] - m)
        if eps[0] == eps[1] and eps[1] == eps[2]:
            dev = v3(T(0.0), T(0.0), T(0.0))  # repeated singular values: tr/3 may round off eps
        K = lam + T(2.0) / T(3.0) * mu
        p_tr = -K * tr
        q_tr = T(sqrt6) * mu * wp.length(dev)
        p0 = p0_fn(log_jp, K, xi, p0_floor)
        if yield_fn(p_tr, q_tr, p0, M, beta) <= T(0.0):
            return eps, log_jp, wp.int32(0)

        p_new, q_new = project(p_tr, q_tr, p0, K, mu, M, beta)
        scale = T(0.0)
        if q_tr > T(0.0):
            scale = wp.min(q_new / q_tr, T(1.0))
        m_new = -p_new / (T(3.0) * K)
        eps_new = v3(dev[0] * scale + m_new, dev[1] * scale + m_new, dev[2] * scale + m_new)
        return eps_new, log_jp + tr - T(3.0) * m_new, wp.int32(1)

    return camclay_return_strain
