"""Frame-time diagnostics: energies, stresses, health check.

None of these run inside the substep loop except the health check, which the
driver launches every few steps. Each is built per (dimension, scalar type);
the elastic state is ``H = F_E - I`` (and ``h_zz`` in plane strain), read
through ``kernels.principal.principal_strain_func``. Energies and stresses are
evaluated in float64 from the stored state whatever its precision (they run
once per frame): ``I + H`` rounded to float32 would add a rounding of its own
to the state's.
"""

import functools

import warp as wp

from .constitutive import material_struct
from .cracking import crack_principal_func
from .elasticity import cauchy_from_principal_func, hencky_strain_energy_func, hencky_strain_func
from .principal import principal_strain_func
from .types import mat, vec

INT_MAX = 2147483647


@functools.cache
def energy_kernel(dim, T):
    """Kinetic ``0.5 m |v|^2`` and elastic ``V0 psi(F_E)`` energy (J; J/m in plane strain) of one group.

    Accumulates into ``out[0]`` (kinetic) and ``out[1]`` (elastic), float64.
    ``psi = mu |eps|^2 + lam/2 tr(eps)^2`` (Hencky, docs/model.md §1); a cracked particle (``kappa`` given,
    cracking groups only, else an empty array) stores ``psi = tau' : eps / 2`` with its softened stress.
    """
    V = vec(dim, T)
    M = mat(dim, T)
    MD = mat(dim, wp.float64)
    VD = vec(dim, wp.float64)
    D = wp.float64
    P = material_struct(T)
    principal_strain = principal_strain_func(D, dim)
    psi_fn = hencky_strain_energy_func(D)
    hencky = hencky_strain_func(D)
    crack64 = crack_principal_func(D, dim)

    @wp.kernel(enable_backward=False, module="unique")
    def energy(v: wp.array(dtype=V), H: wp.array(dtype=M), hzz: wp.array(dtype=T), kappa: wp.array(dtype=T),
               mass: T, vol0: T, m: P, out: wp.array(dtype=wp.float64)):
        i = wp.tid()
        h = D(0.0)
        if wp.static(dim == 2):
            if hzz.shape[0] > 0:  # a plastic group's F_E,zz - 1 (elastic: 0, not stored)
                h = D(hzz[i])
        U, eps, Vm, s, svd = principal_strain(MD(H[i]), h, D(m.s_floor))
        psi = psi_fn(eps, D(m.mu), D(m.lam))
        if kappa.shape[0] > 0:  # a cracking group (kernels/cracking.py): the energy its softened stress stores
            if D(kappa[i]) > D(m.t_strength):
                tau = crack64(hencky(eps, D(m.mu), D(m.lam)), D(kappa[i]), D(m.t_strength), D(m.t_fail))
                psi = D(0.5) * wp.dot(tau, eps)
        vi = v[i]
        wp.atomic_add(out, 0, D(0.5) * D(mass) * wp.dot(VD(vi), VD(vi)))
        wp.atomic_add(out, 1, D(vol0) * psi)

    return energy


@functools.cache
def stress_kernel(dim, T):
    """Cauchy stress ``sigma = tau / J`` (Pa, 3x3, tension positive), pressure ``p = -tr(tau)/3`` and Mises
    ``q = sqrt(3/2)|dev tau|`` (Pa, Kirchhoff, compression positive) of one group.

    ``J = J_E exp(log_jp - log_jp_ref)`` is the volume ratio since the material was placed (``log_jp``
    an empty array for elastic groups; ``kappa`` an empty array but for cracking groups, whose stress is the
    softened one). In plane strain ``sigma`` holds the in-plane block and ``sigma_zz`` (the
    out-of-plane stress the constraint ``F_zz = 1`` carries); ``sigma_xz =
    sigma_yz = 0``. Any of the outputs may be None-sized arrays not written.
    """
    M = mat(dim, T)
    M3 = mat(3, T)
    D = wp.float64
    MD = mat(dim, D)
    V3 = vec(3, D)
    P = material_struct(T)
    principal_strain = principal_strain_func(D, dim)
    hencky = hencky_strain_func(D)
    cauchy_of = cauchy_from_principal_func(T, dim)
    crack64 = crack_principal_func(D, dim)

    @wp.kernel(enable_backward=False, module="unique")
    def stress(H: wp.array(dtype=M), hzz: wp.array(dtype=T), log_jp: wp.array(dtype=T), kappa: wp.array(dtype=T), m: P,
               want_sigma: int, p_out: wp.array(dtype=T), q_out: wp.array(dtype=T), sigma_out: wp.array(dtype=M3)):
        i = wp.tid()
        h = D(0.0)
        if wp.static(dim == 2):
            if hzz.shape[0] > 0:  # a plastic group's F_E,zz - 1 (elastic: 0, not stored)
                h = D(hzz[i])
        sf = D(m.s_floor)
        U, eps, Vm, s, svd = principal_strain(MD(H[i]), h, sf)
        tau = hencky(eps, D(m.mu), D(m.lam))
        if kappa.shape[0] > 0:  # a cracking group: the softened stress (kernels/cracking.py)
            tau = crack64(tau, D(kappa[i]), D(m.t_strength), D(m.t_fail))
        p = -(tau[0] + tau[1] + tau[2]) / D(3.0)
        dev = tau + V3(p, p, p)
        p_out[i] = T(p)
        q_out[i] = T(wp.sqrt(D(1.5) * wp.dot(dev, dev)))
        if want_sigma != 0:
            # volume ratio since the material was placed: J_E (of the floored stretches) times the plastic change
            ln_j = eps[0] + eps[1] + eps[2]
            if log_jp.shape[0] > 0:
                ln_j += D(log_jp[i]) - D(m.log_jp_ref)
            sigma_out[i] = cauchy_of(U, tau, wp.exp(ln_j))

    return stress


@functools.cache
def health_kernel(dim, T):
    """Health check over all particles.

    Writes the smallest offending particle index per cause into ``bad``:
    ``bad[0]`` non-finite x, v or F_E; ``bad[1]`` a particle moving more than
    ``max_cells`` cells in one step (``|v| dt > max_cells dx`` with ``dt`` the
    last real step, ``clock[3]``, so the check also holds at frame ends and under
    CUDA graphs). Entries stay ``INT_MAX`` when healthy. Inversions and
    singular-value floor events are counted by P2G (``kernels/p2g.py``).
    """
    V = vec(dim, T)
    M = mat(dim, T)

    @wp.kernel(enable_backward=False, module="unique")
    def health(x: wp.array(dtype=V), v: wp.array(dtype=V), H: wp.array(dtype=M),
               clock: wp.array(dtype=wp.float64), dx: T, max_cells: T, bad: wp.array(dtype=wp.int32)):
        i = wp.tid()
        vi = v[i]
        finite = wp.isfinite(x[i]) and wp.isfinite(vi) and wp.isfinite(H[i])
        if not finite:
            wp.atomic_min(bad, 0, i)
            return
        if wp.length(vi) * T(clock[3]) > max_cells * dx:
            wp.atomic_min(bad, 1, i)

    return health


@functools.cache
def health_zz_kernel(T):
    """Health check of one plastic group's out-of-plane stretches ``hzz`` (plane strain): a non-finite one
    counts as a non-finite ``F_E`` (``bad[0]``) of particle ``start + i``."""

    @wp.kernel(enable_backward=False, module="unique")
    def health_zz(hzz: wp.array(dtype=T), start: int, bad: wp.array(dtype=wp.int32)):
        i = wp.tid()
        if not wp.isfinite(hzz[i]):
            wp.atomic_min(bad, 0, start + i)

    return health_zz
