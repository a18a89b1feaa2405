"""The constitutive update: one Warp function per (dimension, scalar type, material model).

P2G (``kernels/p2g.py``) and the material-point driver (``mpm_warp/material_point.py``) both call
:func:`constitutive_update_func`, so the driver is the engine's update bit for bit. From the trial
displacement gradient ``H_tr = F_tr - I`` it gives the new elastic state, the Kirchhoff stress and the
hardening; small strains take a decomposition-free path, the rest the principal strains (docs/model.md §4).
Flags returned with the update: :data:`YIELDED` (the return projected), :data:`FLOORED` (a singular value
was raised to the floor), :data:`INVERTED` (``det F_tr <= 0``: an element turned inside out, then floored).
"""

import functools
import math

import warp as wp

from .bonded_camclay import bonded_camclay_return_strain_func, bonded_p0_func
from .camclay import camclay_p0_func, camclay_project_axes_func, camclay_return_strain_func, camclay_yield_func
from .cracking import crack_func
from .elasticity import hencky_strain_func
from .logstrain import expm1_func, expm1_order, expm1_small_func, expm1_sym_func, log1p_func, log_strain_func
from .principal import principal_strain_func
from .types import mat, vec

__all__ = ["MODELS", "PLASTIC_MODELS", "YIELDED", "FLOORED", "INVERTED", "material_struct", "trial_func",
           "constitutive_update_func"]

#: material models with a kernel-side update
MODELS = ("elastic", "camclay", "bonded_camclay", "tensile_cracking")
#: the models with a return mapping (plastic state ``log_jp``)
PLASTIC_MODELS = ("camclay", "bonded_camclay")
YIELDED = 1
FLOORED = 2
INVERTED = 4

_SQRT6 = math.sqrt(6.0)


@functools.cache
def material_struct(T):
    """Kernel-side material parameters (one struct for every model; unused fields are 0).

    Fields: ``mu``, ``lam`` (Lame parameters, Pa); ``M`` (critical-state slope, -);
    ``beta`` (cohesion ratio, -); ``xi`` (hardening factor, -); ``p0_floor`` (Pa);
    ``s_floor`` (singular-value floor, -); ``p_bond`` (bonded consolidation pressure, Pa) and
    ``kappa_s`` (plastic strain at which the bond is gone, -) of the bonded weak layer; ``t_strength`` and
    ``t_fail`` (Pa) of tensile cracking (``kernels/cracking.py``): the strength and the effective stress at
    which the crack carries no tension;
    ``log_jp_ref`` (-): the hardening state of the material as placed, so that the plastic change of
    volume since then is ``exp(log_jp - log_jp_ref)`` (``log_jp`` starts at a consolidation's state,
    not at 0) and the Cauchy stress is ``tau / (J_E exp(log_jp - log_jp_ref))``.

    Derived constants (the engine fills them from the fields above, ``mpm_warp.particle_groups.material_params``):
    ``K`` (bulk modulus ``lam + 2 mu / 3``, Pa) and ``inv_K`` (1/Pa); ``ell_rho``, ``ell_inv_rho``, ``ell_c``,
    ``ell_inv_c`` (-): Cam-Clay's scaled yield ellipse (``kernels.camclay.ellipse_axes``), so that a yielding
    particle's return forms no square root or reciprocal of material constants.
    """

    @wp.struct
    class MaterialParams:
        mu: T
        lam: T
        M: T
        beta: T
        xi: T
        p0_floor: T
        s_floor: T
        p_bond: T
        kappa_s: T
        log_jp_ref: T
        t_strength: T
        t_fail: T
        K: T
        inv_K: T
        ell_rho: T
        ell_inv_rho: T
        ell_c: T
        ell_inv_c: T

    return MaterialParams


@functools.cache
def trial_func(T, dim=3):
    """Return ``trial(H, L) -> H_tr``: the trial displacement gradient ``(I + L)(I + H) - I = H + L + L H``."""
    M = mat(dim, T)

    @wp.func
    def trial(H: M, L: M):
        return H + L + L * H

    return trial


@functools.cache
def _model_funcs(T, model):
    """``(yield_check, principal_return, invariant_return)`` of a plastic model (None each for elastic).

    ``yield_check(p, q, lj, kappa, mat) -> (y, p0)``: ``y > 0`` outside the surface, and the
    consolidation pressure it used (Pa; Cam-Clay: passed on to ``invariant_return``, which
    then need not compute it again);
    ``principal_return(eps, lj, kappa, mat) -> (eps_new, lj_new, kappa_new, yielded)`` in principal
    Hencky strains;
    ``invariant_return(tr, r, p0, lj, kappa, mat) -> (s, tr_new, lj_new, kappa_new, yielded)``: the
    same return for a trial given by its invariants ``tr = tr(eps)``, ``r = |dev eps|`` (the return
    is isotropic and keeps the direction of ``dev eps``), as ``dev eps_new = s dev eps`` and
    ``tr(eps_new)``. Cam-Clay runs its projection on ``(p, q)`` directly and carries ``kappa``
    through unchanged; the bonded layer runs its principal-strain return on the principal strains
    ``(m + r sqrt(2/3), m - r/sqrt(6), m - r/sqrt(6))``, ``m = tr/3``, which have those invariants.
    """
    if model not in MODELS:
        raise ValueError(f"unknown material model {model!r}; expected one of {MODELS}")
    if model not in PLASTIC_MODELS:
        return None, None, None
    P = material_struct(T)
    V3 = vec(3, T)
    yf = camclay_yield_func(T)
    sqrt6 = _SQRT6
    sqrt2_3 = math.sqrt(2.0 / 3.0)  # Python floats: a math call inside a kernel would round through float32
    inv_sqrt6 = 1.0 / _SQRT6
    if model == "camclay":
        p0f = camclay_p0_func(T)
        ret = camclay_return_strain_func(T)
        project = camclay_project_axes_func(T)

        @wp.func
        def yield_check(p: T, q: T, lj: T, kappa: T, m: P):
            p0 = p0f(lj, m.K, m.xi, m.p0_floor)
            return yf(p, q, p0, m.M, m.beta), p0

        @wp.func
        def principal_return(eps: V3, lj: T, kappa: T, m: P):
            e, l2, y = ret(eps, lj, m.mu, m.lam, m.M, m.beta, m.xi, m.p0_floor)
            return e, l2, kappa, y

        @wp.func
        def invariant_return(tr: T, r: T, p0: T, lj: T, kappa: T, m: P):
            # camclay_return_strain's projection and bookkeeping, on the invariants, with the material's
            # ellipse constants and the deviatoric scale from the projection (no division on the invariants)
            q_tr = T(sqrt6) * m.mu * r
            p_new, q_new, scale = project(-m.K * tr, q_tr, p0, m.beta, m.ell_rho, m.ell_inv_rho, m.ell_c,
                                          m.ell_inv_c)
            if q_tr <= T(0.0):
                scale = T(0.0)
            tr_new = -p_new * m.inv_K
            return scale, tr_new, lj + tr - tr_new, kappa, int(1)

    else:
        bp0 = bonded_p0_func(T)
        bret = bonded_camclay_return_strain_func(T)

        @wp.func
        def yield_check(p: T, q: T, lj: T, kappa: T, m: P):
            p0, b = bp0(lj, kappa, m.K, m.xi, m.p0_floor, m.p_bond, m.kappa_s)
            return yf(p, q, p0, m.M, m.beta * b), p0

        @wp.func
        def principal_return(eps: V3, lj: T, kappa: T, m: P):
            return bret(eps, lj, kappa, m.mu, m.lam, m.M, m.beta, m.xi, m.p0_floor, m.p_bond, m.kappa_s)

        @wp.func
        def invariant_return(tr: T, r: T, p0: T, lj: T, kappa: T, m: P):
            mean = tr / T(3.0)
            e_hi = mean + r * T(sqrt2_3)
            e_lo = mean - r * T(inv_sqrt6)
            e_new, lj_new, kap_new, y = bret(V3(e_hi, e_lo, e_lo), lj, kappa, m.mu, m.lam, m.M, m.beta, m.xi,
                                             m.p0_floor, m.p_bond, m.kappa_s)
            scale = T(0.0)  # from the principal values (0 for a pure volumetric trial)
            if e_hi > e_lo:
                scale = (e_new[0] - e_new[1]) / (e_hi - e_lo)
            return scale, e_new[0] + e_new[1] + e_new[2], lj_new, kap_new, int(y)

    return yield_check, principal_return, invariant_return


@functools.cache
def constitutive_update_func(dim, T, model, decomposition_free=True):
    """Build the constitutive update of ``model`` for dimension ``dim`` and scalar type ``T``.

    ``decomposition_free``: a yielding trial whose series strain is known takes the
    return without a decomposition (``coaxial`` below); False builds the update that
    takes the principal-strain path for every yielding trial (the reference of the tests).

    Signatures of the returned ``wp.func`` (``mat``/``vec`` of size ``dim``)::

        3D: update(H_tr, log_jp, kappa, m) -> (H_new, tau, log_jp_new, kappa_new, flags)
        2D: update(H_tr, hzz_tr, log_jp, kappa, m) -> (H_new, hzz_new, tau, log_jp_new, kappa_new, flags)

    Parameters
    ----------
    H_tr : mat
        Trial displacement gradient ``F_tr - I`` (-), from :func:`trial_func`.
    hzz_tr : T
        Out-of-plane trial stretch minus one (-), plane strain only.
    log_jp : T
        Hardening state ``ln det F_P`` (-); passed through by elastic models.
    kappa : T
        The softening state: the plastic work of the bonded weak layer (J/m^3), the largest effective tensile
        stress of tensile cracking (Pa); passed through by the other models.
    m : MaterialParams
        See :func:`material_struct`.

    Returns
    -------
    H_new, hzz_new : new elastic state (-); ``tau`` : in-plane (2D) or full (3D)
    Kirchhoff stress (Pa, tension positive); ``log_jp_new``, ``kappa_new``; ``flags`` : bits
    :data:`YIELDED`, :data:`FLOORED`, :data:`INVERTED`.
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    P = material_struct(T)
    plastic = model in PLASTIC_MODELS
    cracking = model == "tensile_cracking"
    crack = crack_func(T, dim)
    yield_check, principal_return, invariant_return = _model_funcs(T, model)
    log_strain = log_strain_func(T, dim)
    log1p = log1p_func(T)
    principal_strain = principal_strain_func(T, dim)
    hencky_strain = hencky_strain_func(T)
    expm1 = expm1_func(T)
    expm1_sym = expm1_sym_func(T, dim)
    expm1_small = expm1_small_func(T)
    tiny = 1.0 / 256.0  # |D| up to which the exponential series takes fewer terms (expm1_order)
    expm1_sym_tiny = expm1_sym_func(T, dim, expm1_order(T, tiny))
    expm1_small_tiny = expm1_small_func(T, expm1_order(T, tiny))
    sqrt6 = _SQRT6
    third = 1.0 / 3.0  # a Python float: a multiply (a division by 3 stays a division without fast math)

    @wp.func
    def small_strain(H_tr: M, hzz: T, lj: T, kap: T, m: P):
        """Hencky strain by the series; ``ok``: the series applies (small, not inverted); ``yld``: the trial lies
        outside the yield surface (plastic models). Also ``eps_zz`` (2D), the trace, ``|dev eps|`` and the
        consolidation pressure of the yield check."""
        eps, ok = log_strain(H_tr)
        ezz = T(0.0)
        tr = wp.trace(eps)
        if wp.static(dim == 2):
            if hzz <= T(-1.0):
                ok = 0
            else:
                ezz = log1p(hzz)
                tr = tr + ezz
        r = T(0.0)
        p0 = T(0.0)
        yld = int(0)
        if wp.static(plastic):
            if ok != 0:
                mean = tr * T(third)
                dev = eps - mean * wp.identity(dim, dtype=T)
                dev2 = wp.ddot(dev, dev)
                if wp.static(dim == 2):
                    dev2 = dev2 + (ezz - mean) * (ezz - mean)
                r = wp.sqrt(dev2)
                y, p0 = yield_check(-m.K * tr, T(sqrt6) * m.mu * r, lj, kap, m)
                if y > T(0.0):
                    yld = 1
        return eps, ezz, tr, r, p0, ok, yld

    @wp.func
    def coaxial(H_tr: M, hzz: T, eps: M, ezz: T, tr: T, r: T, p0: T, lj: T, kap: T, m: P):
        """Return mapping without a decomposition, for a yielding trial whose series strain ``eps`` is known.

        The return is isotropic and radial in the deviatoric plane, so it needs only ``tr eps`` and
        ``r = |dev eps|`` and keeps the eigenvectors (``invariant_return``): ``eps_new = s dev(eps) +
        tr(eps_new)/3 I``. ``eps_new`` is coaxial with ``eps``, hence ``F_new = exp(eps_new - eps) F_tr``
        (the general path's ``U diag(exp(eps_new - eps)) U^T F_tr`` without ``U``), with ``exp - I`` by
        its series. ``done = 0`` when the correction is too large for that series
        (``|eps_new - eps|_F > 1/4``): the caller then takes the general path.
        """
        I = wp.identity(dim, dtype=T)
        scale, tr_new, lj_new, kap_new, y = invariant_return(tr, r, p0, lj, kap, m)
        if y == 0:  # inside the surface after all (rounding of the invariants): elastic
            return H_tr, hzz, T(2.0) * m.mu * eps + (m.lam * tr) * I, lj, kap, int(0), int(1)
        mean = tr * T(third)
        mean_new = tr_new * T(third)
        eps_new = scale * (eps - mean * I) + mean_new * I
        D = eps_new - eps
        Dzz = T(0.0)
        if wp.static(dim == 2):
            Dzz = (scale * (ezz - mean) + mean_new) - ezz
        d2 = wp.ddot(D, D) + Dzz * Dzz
        if d2 > T(0.0625):
            return H_tr, hzz, M(), lj, kap, int(0), int(0)
        E = M()
        ezz_m1 = T(0.0)
        if d2 <= T(wp.static(tiny * tiny)):  # a step's correction: a few terms of the series
            E = expm1_sym_tiny(D)
            ezz_m1 = expm1_small_tiny(Dzz)
        else:
            E = expm1_sym(D)
            ezz_m1 = expm1_small(Dzz)
        H_new = H_tr + E * (I + H_tr)
        hzz_new = hzz
        if wp.static(dim == 2):
            hzz_new = hzz + (T(1.0) + hzz) * ezz_m1
        return H_new, hzz_new, T(2.0) * m.mu * eps_new + (m.lam * tr_new) * I, lj_new, kap_new, YIELDED, int(1)

    @wp.func
    def strain_update(eps: V3, lj: T, kap: T, m: P):
        """Return mapping (plastic models) and Kirchhoff principal stresses of the new strains."""
        eps_new = eps
        lj_new = lj
        kap_new = kap
        y = int(0)
        if wp.static(plastic):
            e2, l2, k2, yy = principal_return(eps, lj, kap, m)
            eps_new = e2
            lj_new = l2
            kap_new = k2
            y = int(yy)
        return eps_new, lj_new, kap_new, y, hencky_strain(eps_new, m.mu, m.lam)

    @wp.func
    def general(H_tr: M, hzz: T, lj: T, kap: T, m: P):
        """Principal-strain path: principal strains, return mapping, state as a correction of the trial, stress."""
        I = wp.identity(dim, dtype=T)
        U, eps, Vm, s, svd = principal_strain(H_tr, hzz, m.s_floor)
        flags = int(0)
        floored = int(0)
        if svd != 0:
            for a in range(3):
                if s[a] < m.s_floor:
                    floored = 1
            if floored != 0:
                flags = FLOORED
                if s[1] <= T(0.0) or s[2] <= T(0.0):
                    flags = flags | INVERTED
        eps_new, lj_new, kap_new, y, tau_p = strain_update(eps, lj, kap, m)
        if y != 0:
            flags = flags | YIELDED
        H_new = H_tr
        hzz_new = hzz
        if floored != 0:
            Dg = M()
            for a in range(dim):
                Dg[a, a] = wp.exp(eps_new[a])
            H_new = U * Dg * wp.transpose(Vm) - I
            hzz_new = wp.exp(eps_new[2]) - T(1.0)
        elif y != 0:
            # F_new = U diag(exp(eps_new - eps)) U^T F_tr, written as a correction of the trial so that untouched
            # digits stay (rebuilding from float32 factors puts round-off back outside the yield surface: creep)
            Dr = M()
            for a in range(dim):
                Dr[a, a] = expm1(eps_new[a] - eps[a])
            H_new = H_tr + (U * Dr * wp.transpose(U)) * (I + H_tr)
            hzz_new = hzz + (T(1.0) + hzz) * expm1(eps_new[2] - eps[2])
        Dt = M()
        for a in range(dim):
            Dt[a, a] = tau_p[a]
        return H_new, hzz_new, U * Dt * wp.transpose(U), lj_new, kap_new, flags

    @wp.func
    def update_any(H_tr: M, hzz: T, lj: T, kap: T, m: P):
        eps, ezz, tr, r, p0, ok, yld = small_strain(H_tr, hzz, lj, kap, m)
        if ok != 0:
            if yld == 0:
                return H_tr, hzz, T(2.0) * m.mu * eps + (m.lam * tr) * wp.identity(dim, dtype=T), lj, kap, int(0)
            if wp.static(plastic and decomposition_free):
                H_new, hzz_new, tau, lj_new, kap_new, flags, done = coaxial(H_tr, hzz, eps, ezz, tr, r, p0, lj, kap, m)
                if done != 0:
                    return H_new, hzz_new, tau, lj_new, kap_new, flags
        return general(H_tr, hzz, lj, kap, m)

    @wp.func
    def update_cracking(H_tr: M, hzz: T, lj: T, kap: T, m: P):
        """Elastic update, then the tensile cracking of the stress (``kernels/cracking.py``): ``YIELDED`` flags a
        grown ``kappa``."""
        H_new, hzz_new, tau, lj_new, kap_new, flags = update_any(H_tr, hzz, lj, kap, m)
        if wp.static(cracking):
            tau2, kap2, grew = crack(tau, kap, m.t_strength, m.t_fail)
            if grew != 0:
                flags = flags | YIELDED
            return H_new, hzz_new, tau2, lj_new, kap2, flags
        return H_new, hzz_new, tau, lj_new, kap_new, flags

    if dim == 2:

        @wp.func
        def update(H_tr: M, hzz: T, lj: T, kap: T, m: P):
            if wp.static(cracking):
                return update_cracking(H_tr, hzz, lj, kap, m)
            return update_any(H_tr, hzz, lj, kap, m)

    else:

        @wp.func
        def update(H_tr: M, lj: T, kap: T, m: P):
            if wp.static(cracking):
                H_new, hzz_new, tau, lj_new, kap_new, flags = update_cracking(H_tr, T(0.0), lj, kap, m)
                return H_new, tau, lj_new, kap_new, flags
            H_new, hzz_new, tau, lj_new, kap_new, flags = update_any(H_tr, T(0.0), lj, kap, m)
            return H_new, tau, lj_new, kap_new, flags

    return update
