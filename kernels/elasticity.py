"""Hencky St Venant-Kirchhoff elasticity in principal form (docs/model.md §1).

With the SVD ``F_E = U diag(s) V^T`` (``wp.svd3``: ``U``, ``V`` rotations, ``s``
sorted by decreasing magnitude, the last one carrying the sign of ``det F_E``)
the principal Hencky strains are ``eps_i = ln s_i`` and

    tau_i = 2 mu eps_i + lam tr(eps)                      (Kirchhoff stress, Pa)
    psi   = mu |eps|^2 + lam / 2 tr(eps)^2                (J/m^3 of reference volume)

The Kirchhoff stress is ``tau = U diag(tau_i) U^T``. Singular values are floored
at ``s_floor`` before the logarithm, so a nearly singular or inverted ``F_E``
gives a finite, strongly compressive stress instead of NaN. Every function is
built by a cached factory of the scalar type ``T`` (``wp.float32`` or
``wp.float64``).
"""

import functools

import warp as wp

from .types import mat, vec, vec3

__all__ = ["clamp_singular_func", "hencky_func", "hencky_energy_func", "hencky_strain_func",
           "hencky_strain_energy_func"]


@functools.cache
def clamp_singular_func(T):
    """Build ``clamp_singular(sig, s_floor) -> vec3`` for scalar type ``T``.

    Returns ``max(sig_i, s_floor)`` componentwise (dimensionless). The engine
    uses it to rebuild ``F_E = U diag(clamp_singular(s)) V^T`` when ``F_E`` was
    inverted (``s_2 < 0``) or nearly singular, which keeps ``det F_E > 0``.
    """
    v3 = vec3(T)

    @wp.func
    def clamp_singular(sig: v3, s_floor: T):
        return v3(wp.max(sig[0], s_floor), wp.max(sig[1], s_floor), wp.max(sig[2], s_floor))

    return clamp_singular


@functools.cache
def hencky_func(T):
    """Build ``hencky_kirchhoff_principal(sig, mu, lam, s_floor) -> vec3``.

    Parameters (of the returned ``wp.func``)
    ----------------------------------------
    sig : vec3
        Singular values of ``F_E`` (dimensionless, any sign; floored at ``s_floor``).
    mu, lam : T
        Lame parameters (Pa).
    s_floor : T
        Floor on the singular values (dimensionless, > 0), e.g. 1e-6.

    Returns
    -------
    vec3
        Principal Kirchhoff stresses ``tau_i = 2 mu eps_i + lam tr(eps)`` (Pa),
        ``eps_i = ln max(sig_i, s_floor)`` (docs/model.md §1), tension positive.
    """
    v3 = vec3(T)
    clamp = clamp_singular_func(T)

    @wp.func
    def hencky_kirchhoff_principal(sig: v3, mu: T, lam: T, s_floor: T):
        s = clamp(sig, s_floor)
        eps = v3(wp.log(s[0]), wp.log(s[1]), wp.log(s[2]))
        tr = eps[0] + eps[1] + eps[2]
        two_mu = T(2.0) * mu
        return v3(two_mu * eps[0] + lam * tr, two_mu * eps[1] + lam * tr, two_mu * eps[2] + lam * tr)

    return hencky_kirchhoff_principal


@functools.cache
def hencky_energy_func(T):
    """Build ``hencky_energy(sig, mu, lam, s_floor) -> T``.

    Returns the strain energy density ``psi = mu |eps|^2 + lam/2 tr(eps)^2``
    (J/m^3 of reference volume, docs/model.md §1) with the same floored
    strains ``eps_i = ln max(sig_i, s_floor)`` as :func:`hencky_func`, so that
    ``d psi / d eps_i = tau_i``.
    """
    v3 = vec3(T)
    clamp = clamp_singular_func(T)

    @wp.func
    def hencky_energy(sig: v3, mu: T, lam: T, s_floor: T):
        s = clamp(sig, s_floor)
        eps = v3(wp.log(s[0]), wp.log(s[1]), wp.log(s[2]))
        tr = eps[0] + eps[1] + eps[2]
        return mu * wp.dot(eps, eps) + T(0.5) * lam * tr * tr

    return hencky_energy


@functools.cache
def hencky_strain_func(T):
    """Build ``hencky_strain(eps, mu, lam) -> vec3``: principal Kirchhoff stresses ``2 mu eps_i + lam tr(eps)`` (Pa)
    of principal Hencky strains ``eps`` (-) (docs/model.md §1), the form :func:`hencky_func` takes after the log."""
    v3 = vec3(T)

    @wp.func
    def hencky_strain(eps: v3, mu: T, lam: T):
        tr = eps[0] + eps[1] + eps[2]
        two_mu = T(2.0) * mu
        return v3(two_mu * eps[0] + lam * tr, two_mu * eps[1] + lam * tr, two_mu * eps[2] + lam * tr)

    return hencky_strain


@functools.cache
def cauchy_from_principal_func(T, dim):
    """Build ``cauchy(U, tau, J) -> mat33 of T``: the Cauchy stress ``U diag(tau) U^T / J`` (Pa).

    ``U`` (float64, ``dim x dim``) holds the principal directions, ``tau`` (float64, 3) the principal
    Kirchhoff stresses (Pa), ``J`` (float64) the volume ratio. In plane strain (``dim == 2``) the
    in-plane block is rotated and ``sigma_zz = tau_z / J``; ``sigma_xz = sigma_yz = 0``.
    """
    D = wp.float64
    MD = mat(dim, D)
    V3 = vec(3, D)
    M3 = mat(3, T)

    @wp.func
    def cauchy(U: MD, tau: V3, J: D):
        sig = M3()
        for a in range(dim):
            for b in range(dim):
                acc = D(0.0)
                for k in range(dim):
                    acc += U[a, k] * tau[k] * U[b, k]
                sig[a, b] = T(acc / J)
        if wp.static(dim == 2):
            sig[2, 2] = T(tau[2] / J)
        return sig

    return cauchy


@functools.cache
def hencky_strain_energy_func(T):
    """Build ``hencky_strain_energy(eps, mu, lam) -> T``: ``psi = mu |eps|^2 + lam/2 tr(eps)^2`` (J/m^3)."""
    v3 = vec3(T)

    @wp.func
    def hencky_strain_energy(eps: v3, mu: T, lam: T):
        tr = eps[0] + eps[1] + eps[2]
        return mu * wp.dot(eps, eps) + T(0.5) * lam * tr * tr

    return hencky_strain_energy
