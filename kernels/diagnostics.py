"""Frame-time diagnostics: energies, health check and derived output fields.

None of these run inside the substep loop except the health check, which the
driver launches every few steps.
"""

import functools

import warp as wp

from .elasticity import hencky_func
from .types import mat33, vec3

INT_MAX = 2147483647


@functools.cache
def energy_kernel(T):
    """Kinetic ``0.5 m |v|^2`` and elastic ``V0 psi(F_E)`` energy (J) of one group.

    Accumulates into ``out[0]`` (kinetic) and ``out[1]`` (elastic), float64.
    ``psi = mu |eps|^2 + lam/2 tr(eps)^2`` (Hencky, MODEL.md 1).
    """
    V = vec3(T)
    M = mat33(T)
    hencky = hencky_func(T)

    @wp.kernel(enable_backward=False)
    def energy(
        v: wp.array(dtype=V),
        F: wp.array(dtype=M),
        mass: T,
        vol0: T,
        mu: T,
        lam: T,
        s_floor: T,
        out: wp.array(dtype=wp.float64),
    ):
        i = wp.tid()
        U = M()
        s = V()
        Vt = M()
        wp.svd3(F[i], U, s, Vt)
        tau = hencky(s, mu, lam, s_floor)
        eps = V(wp.log(wp.max(s[0], s_floor)), wp.log(wp.max(s[1], s_floor)), wp.log(wp.max(s[2], s_floor)))
        # psi = 1/2 tau : eps for the quadratic Hencky energy
        psi = T(0.5) * wp.dot(tau, eps)
        wp.atomic_add(out, 0, wp.float64(T(0.5) * mass * wp.dot(v[i], v[i])))
        wp.atomic_add(out, 1, wp.float64(vol0 * psi))

    return energy


@functools.cache
def stress_invariants_kernel(T):
    """Pressure ``p = -tr(tau)/3`` and Mises ``q = sqrt(3/2)|dev tau|`` (Pa, Kirchhoff) of one group."""
    V = vec3(T)
    M = mat33(T)
    hencky = hencky_func(T)

    @wp.kernel(enable_backward=False)
    def stress_invariants(
        F: wp.array(dtype=M),
        mu: T,
        lam: T,
        s_floor: T,
        p_out: wp.array(dtype=T),
        q_out: wp.array(dtype=T),
    ):
        i = wp.tid()
        U = M()
        s = V()
        Vt = M()
        wp.svd3(F[i], U, s, Vt)
        tau = hencky(s, mu, lam, s_floor)
        p = -(tau[0] + tau[1] + tau[2]) / T(3.0)
        dev = tau + V(p, p, p)
        p_out[i] = p
        q_out[i] = wp.sqrt(T(1.5) * wp.dot(dev, dev))

    return stress_invariants


@functools.cache
def stress_kernel(T):
    """Cauchy stress tensor ``sigma = tau / J_E`` (Pa, tension positive) of one group, per particle.

    ``F_E = U diag(s) V^T`` (``wp.svd3``), ``tau = U diag(tau_i) U^T`` with the principal Hencky
    stresses of :func:`mpm_warp.kernels.elasticity.hencky_func` (singular values floored at
    ``s_floor``) and ``J_E = prod_i max(s_i, s_floor)`` (MODEL.md 1). The host mirror is
    :func:`mpm_warp.stress.cauchy_stress`; normal and shear stresses on any plane follow from
    ``sigma`` without recomputing it from ``F_E``.
    """
    V = vec3(T)
    M = mat33(T)
    hencky = hencky_func(T)

    @wp.kernel(enable_backward=False)
    def stress(
        F: wp.array(dtype=M),
        mu: T,
        lam: T,
        s_floor: T,
        sigma_out: wp.array(dtype=M),
    ):
        i = wp.tid()
        U = M()
        s = V()
        Vt = M()
        wp.svd3(F[i], U, s, Vt)
        tau = hencky(s, mu, lam, s_floor)
        J = wp.max(s[0], s_floor) * wp.max(s[1], s_floor) * wp.max(s[2], s_floor)
        sigma_out[i] = U * wp.diag(tau / J) * wp.transpose(U)

    return stress


@functools.cache
def health_kernel(T):
    """Health check over all particles.

    Writes the smallest offending particle index per cause into ``bad``:
    ``bad[0]`` non-finite x, v or F; ``bad[1]`` a particle moving more than
    ``max_cells`` cells in one step (``|v| dt > max_cells dx``); ``bad[2]``
    ``det F_E <= 0``. Entries stay ``INT_MAX`` when healthy.
    """
    V = vec3(T)
    M = mat33(T)

    @wp.kernel(enable_backward=False)
    def health(
        x: wp.array(dtype=V),
        v: wp.array(dtype=V),
        F: wp.array(dtype=M),
        clock: wp.array(dtype=wp.float64),
        dx: T,
        max_cells: T,
        bad: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        xi = x[i]
        vi = v[i]
        Fi = F[i]
        finite = wp.isfinite(xi) and wp.isfinite(vi) and wp.isfinite(Fi)
        if not finite:
            wp.atomic_min(bad, 0, i)
            return
        if wp.length(vi) * T(clock[1]) > max_cells * dx:
            wp.atomic_min(bad, 1, i)
        # float64: a floored F (singular values down to 1e-6) has det ~ 1e-12, below float32 rounding
        if wp.determinant(wp.mat33d(Fi)) <= wp.float64(0.0):
            wp.atomic_min(bad, 2, i)

    return health
