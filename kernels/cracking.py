"""Tensile cracking of an elastic slab: Rankine onset, linear softening over a crack band (docs/model.md §9).

The effective (undamaged) Kirchhoff stress ``tau`` comes from Hencky elasticity; its largest
principal value, over its history, is ``kappa`` (Pa, 0 while it never exceeded the tensile strength
``t_strength``). The damage ``d(kappa)`` softens the stress linearly from the strength at ``kappa =
t_strength`` to nothing at ``kappa = t_fail``; only the tensile principal stresses lose it:

    tau' = tau - d(kappa) sum_i max(tau_i, 0) n_i n_i^T,
    d(k) = 1 - (t_strength / k) (t_fail - k) / (t_fail - t_strength)   for t_strength < k < t_fail.

A crack closes again in compression. ``t_fail = 2 E G_f / (t_strength h)`` spends the fracture energy
``G_f`` over a band of width ``h`` (Bazant and Oh 1983): the host computes it
(:class:`mpm_warp.materials.CrackingSnow`). A particle whose stress never reached the strength returns
the elastic stress bit for bit.
"""

import functools

import warp as wp

from .principal import jacobi_eig3_func
from .types import mat, vec3

__all__ = ["damage_func", "crack_func", "crack_principal_func"]


@functools.cache
def damage_func(T):
    """Build ``damage(kappa, t_strength, t_fail) -> d`` (dimensionless, in [0, 1])."""

    @wp.func
    def damage(kappa: T, t_strength: T, t_fail: T):
        if kappa <= t_strength:
            return T(0.0)
        if kappa >= t_fail:
            return T(1.0)
        return T(1.0) - (t_strength / kappa) * (t_fail - kappa) / (t_fail - t_strength)

    return damage


@functools.cache
def crack_func(T, dim):
    """Build ``crack(tau, kappa, t_strength, t_fail) -> (tau', kappa_new, grew)`` on a ``dim x dim`` Kirchhoff stress.

    ``grew = 1`` when ``kappa`` rose (the state to store). In 2D (plane strain) the criterion and the
    softening act on the in-plane principal stresses (closed form); in 3D on those of the converged Jacobi of
    ``kernels/principal.py``, which runs only where Gershgorin's bound on the largest principal stress exceeds
    the threshold.
    """
    M = mat(dim, T)
    V3 = vec3(T)
    damage = damage_func(T)
    eig3 = jacobi_eig3_func(T)

    @wp.func
    def soften(tau: M, pos: M, s1: T, kappa: T, threshold: T, t_strength: T, t_fail: T):
        """``tau`` less the damage of the grown ``kappa`` times its tensile part ``pos``."""
        k_new = kappa
        grew = int(0)
        if s1 > threshold:
            k_new = s1
            grew = 1
        return tau - damage(k_new, t_strength, t_fail) * pos, k_new, grew

    @wp.func
    def crack(tau: M, kappa: T, t_strength: T, t_fail: T):
        threshold = wp.max(kappa, t_strength)
        pos = M()
        if wp.static(dim == 2):
            mean = T(0.5) * (tau[0, 0] + tau[1, 1])
            half = T(0.5) * (tau[0, 0] - tau[1, 1])
            rad = wp.sqrt(half * half + tau[0, 1] * tau[0, 1])
            s1 = mean + rad
            s2 = mean - rad
            if s1 <= threshold and kappa <= t_strength:
                return tau, kappa, int(0)
            if s2 >= T(0.0):
                pos = tau
            elif s1 > T(0.0):       # the tensile principal part s1 n n^T, n n^T = (tau - s2 I) / (s1 - s2)
                pos = (s1 / (s1 - s2)) * (tau - s2 * wp.identity(2, dtype=T))
            return soften(tau, pos, s1, kappa, threshold, t_strength, t_fail)
        else:
            bound = tau[0, 0] + wp.abs(tau[0, 1]) + wp.abs(tau[0, 2])
            bound = wp.max(bound, tau[1, 1] + wp.abs(tau[0, 1]) + wp.abs(tau[1, 2]))
            bound = wp.max(bound, tau[2, 2] + wp.abs(tau[0, 2]) + wp.abs(tau[1, 2]))
            if bound <= threshold and kappa <= t_strength:
                return tau, kappa, int(0)
            Q, lam = eig3(tau)
            for a in range(3):
                if lam[a] > T(0.0):
                    q = V3(Q[0, a], Q[1, a], Q[2, a])
                    pos = pos + lam[a] * wp.outer(q, q)
            return soften(tau, pos, wp.max(lam[0], wp.max(lam[1], lam[2])), kappa, threshold, t_strength, t_fail)

    return crack


@functools.cache
def crack_principal_func(T, dim):
    """Build ``crack_principal(tau, kappa, t_strength, t_fail) -> tau'`` on principal stresses (vec3, Pa; in 2D the
    first two are the in-plane ones, and only they soften, as in :func:`crack_func`), for the diagnostics and the
    material-point driver (``kappa`` as stored: no growth)."""
    V3 = vec3(T)
    damage = damage_func(T)

    @wp.func
    def crack_principal(tau: V3, kappa: T, t_strength: T, t_fail: T):
        d = damage(kappa, t_strength, t_fail)
        out = tau
        if d > T(0.0):
            for a in range(dim):
                if tau[a] > T(0.0):
                    out[a] = tau[a] * (T(1.0) - d)
        return out

    return crack_principal
