"""Hencky St Venant-Kirchhoff stress in NumPy: the host mirror of ``kernels/elasticity.py`` (docs/model.md §1).

The device computes the same stress in :func:`mpm_warp.kernels.elasticity.hencky_func` (P2G) and
:func:`mpm_warp.kernels.diagnostics.stress_kernel` (the ``stress`` output field); this module is the
one host-side copy, in float64, for analyses, validation and tests:

    F_E = U diag(s) V^T,  eps_i = ln max(s_i, s_floor),  tau_i = 2 mu eps_i + lam tr(eps)
    tau = U diag(tau_i) U^T (Kirchhoff, Pa),  sigma = tau / (J_E J_P),  J_E = prod_i max(s_i, s_floor)

Singular values follow ``wp.svd3``: the last one carries the sign of ``det F_E``, so an inverted
``F_E`` has its smallest singular value floored at ``s_floor`` exactly as on the device. Stresses
are tension positive; the pressure ``p = -tr(tau)/3`` is compression positive.
"""

from __future__ import annotations

import numpy as np

from .kernels.camclay import SINGULAR_VALUE_FLOOR

__all__ = ["principal_strains", "kirchhoff_stress", "cauchy_stress", "pressure_and_mises", "traction",
           "SINGULAR_VALUE_FLOOR"]


def principal_strains(F, s_floor: float = SINGULAR_VALUE_FLOOR) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Left singular vectors ``U`` (n, 3, 3), principal Hencky strains ``eps`` (n, 3) and ``J`` (n,) of ``F``.

    ``F`` is one (3, 3) or a stack (n, 3, 3) of elastic deformation gradients (-); ``eps_i =
    ln max(s_i, s_floor)`` with signed singular values (see the module docstring) and
    ``J = prod max(s_i, s_floor)``.
    """
    F = np.asarray(F, dtype=np.float64).reshape(-1, 3, 3)
    U, s, Vt = np.linalg.svd(F)
    s = s.copy()
    s[:, -1] *= np.sign(np.linalg.det(U) * np.linalg.det(Vt))     # the sign of det F on the last value
    s = np.maximum(s, s_floor)
    return U, np.log(s), np.prod(s, axis=1)


def kirchhoff_stress(F, mu: float, lam: float, s_floor: float = SINGULAR_VALUE_FLOOR) -> np.ndarray:
    """Kirchhoff stress ``tau = U diag(2 mu eps + lam tr eps) U^T`` (Pa), shape (n, 3, 3), float64."""
    U, eps, _ = principal_strains(F, s_floor)
    tau_p = 2.0 * mu * eps + lam * eps.sum(axis=1, keepdims=True)
    return np.einsum("nij,nj,nkj->nik", U, tau_p, U)


def cauchy_stress(F, mu: float, lam: float, s_floor: float = SINGULAR_VALUE_FLOOR, plastic_volume=1.0) -> np.ndarray:
    """Cauchy stress ``sigma = tau / (J_E J_P)`` (Pa, tension positive), shape (n, 3, 3), float64.

    ``plastic_volume`` is the plastic change of volume since the material was placed,
    ``J_P = exp(log_jp - log_jp_ref)`` (a float or one per stress; 1 for elastic materials).
    """
    U, eps, J = principal_strains(F, s_floor)
    J = J * np.broadcast_to(np.asarray(plastic_volume, dtype=np.float64), J.shape)
    tau_p = 2.0 * mu * eps + lam * eps.sum(axis=1, keepdims=True)
    return np.einsum("nij,nj,nkj->nik", U, tau_p / J[:, None], U)


def pressure_and_mises(stress) -> tuple[np.ndarray, np.ndarray]:
    """Pressure ``p = -tr(s)/3`` (compression positive) and Mises ``q = sqrt(3/2) |dev s|`` of stresses (n, 3, 3).

    Kirchhoff stresses give the Cam-Clay invariants of ``kernels/camclay.py`` (Pa).
    """
    s = np.asarray(stress, dtype=np.float64).reshape(-1, 3, 3)
    p = -np.trace(s, axis1=1, axis2=2) / 3.0
    dev = s + p[:, None, None] * np.eye(3)
    return p, np.sqrt(1.5 * np.einsum("nij,nij->n", dev, dev))


def traction(stress, normal) -> tuple[np.ndarray, np.ndarray]:
    """Normal and shear stress (Pa) on the plane of unit ``normal`` (3,) for stresses (n, 3, 3).

    Returns ``(sigma_n, tau)``: ``sigma_n = n . s n`` (tension positive) and the magnitude of
    the tangential traction ``|s n - sigma_n n|``.
    """
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    t = np.asarray(stress, dtype=np.float64).reshape(-1, 3, 3) @ n
    sn = t @ n
    return sn, np.linalg.norm(t - sn[:, None] * n, axis=1)
