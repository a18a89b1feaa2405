"""The constitutive update: one Warp function per (dimension, scalar type, material model).

P2G (``kernels/p2g.py``) and the material-point driver (``mpm_warp/material_point.py``)
both call :func:`constitutive_update_func`, so the driver is the engine's update bit
for bit. Per particle and step (MODEL.md 1 and 4, SI Note 1):

1. trial state ``F_tr = (I + dt C) F_E``. The elastic state is stored as the
   displacement gradient ``H = F_E - I`` and the trial is formed as
   ``H_tr = H + L + L H`` with ``L = dt C`` (:func:`trial_func`): an increment far
   below float32's resolution of 1 (1e-9 in a settling layer) is kept, where
   ``(I + L) F`` would round it away and a settled column would creep forever;
2. small elastic strain (and, for plastic models, a state inside the yield
   surface): Hencky strain by its series, no SVD (``kernels/logstrain.py``);
3. otherwise the principal stretches: the eigen-decomposition ``X = U diag(lambda) U^T``
   of ``X = F F^T - I = H + H^T + H H^T`` (formed from ``H``, so a strain of 1e-6 keeps
   its relative precision; ``U`` are the left singular vectors of ``F``) gives the
   principal Hencky strains ``eps_i = 1/2 log1p(lambda_i)``. A stretch below 1e-2 or
   ``det F_tr <= 0`` takes the SVD instead, with the singular-value floor. For
   plastic models the return mapping acts on ``eps`` (``kernels/camclay.py``), and
   the new state is written as a correction of the trial,
   ``F_new = U diag(exp(eps_new - eps)) U^T F_tr``, i.e.
   ``H_new = H_tr + U diag(expm1(eps_new - eps)) U^T (I + H_tr)``, so untouched
   digits stay and a settled layer does not ratchet;
4. Kirchhoff stress ``tau = U diag(2 mu eps_new + lam tr(eps_new)) U^T``.

Plane strain (``dim = 2``): ``F_E = diag(F_2, F_zz)`` is block diagonal; the
in-plane block is stored as a 2x2 ``H`` and the out-of-plane stretch as
``h_zz = F_zz - 1``. The total ``F_zz`` stays 1, but plastic flow changes the
elastic ``F_zz``, so the return and the Hencky law act on the three principal
stretches ``(s_1, s_2, 1 + h_zz)`` exactly as in 3D (q with d = 3); only the
in-plane stress block drives the grid.

Flags returned with the update: :data:`YIELDED` (the return projected),
:data:`FLOORED` (a singular value was raised to the floor), :data:`INVERTED`
(``det F_tr <= 0``: an element turned inside out, then floored).
"""

import functools
import math

import warp as wp

from .camclay import SINGULAR_VALUE_FLOOR, camclay_p0_func, camclay_return_strain_func, camclay_yield_func
from .elasticity import hencky_strain_func
from .logstrain import expm1_func, log1p_func, log_strain_func
from .types import mat, vec

__all__ = ["MODELS", "YIELDED", "FLOORED", "INVERTED", "material_struct", "trial_func", "svd2_func",
           "sym_eig_func", "principal_func", "principal_strain_func", "constitutive_update_func"]

#: material models with a kernel-side update
MODELS = ("elastic", "camclay")
YIELDED = 1
FLOORED = 2
INVERTED = 4

_SQRT6 = math.sqrt(6.0)


@functools.cache
def material_struct(T):
    """Kernel-side material parameters (one struct for every model; unused fields are 0).

    Fields: ``mu``, ``lam`` (Lame parameters, Pa); ``M`` (critical-state slope, -);
    ``beta`` (cohesion ratio, -); ``xi`` (hardening factor, -); ``p0_floor`` (Pa);
    ``s_floor`` (singular-value floor, -).
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
def svd2_func(T):
    """Return ``svd2(F) -> (U, s, V)`` of a 2x2 matrix, ``F = U diag(s) V^T``.

    ``U`` and ``V`` are rotations and ``s[1]`` carries the sign of ``det F``, the
    convention of ``wp.svd3`` (``wp.svd2`` returns a reflection in ``U`` for
    ``det F < 0`` and fails on symmetric reflections such as ``[[0, 1], [1, 0]]``).
    Closed form: the polar rotation ``R`` of ``F = R S`` (angle ``atan2(F10 - F01,
    F00 + F11)``), then the eigenvectors ``Q`` of the symmetric ``S``:
    ``U = R Q``, ``V = Q``, ``s`` the eigenvalues of ``S``, descending.
    """
    M2 = mat(2, T)
    V2 = vec(2, T)

    @wp.func
    def svd2(F: M2):
        x = F[0, 0] + F[1, 1]
        y = F[1, 0] - F[0, 1]
        h = wp.sqrt(x * x + y * y)
        c = T(1.0)
        sn = T(0.0)
        if h > T(0.0):
            c = x / h
            sn = y / h
        R = M2(c, -sn, sn, c)
        S = wp.transpose(R) * F
        s12 = T(0.5) * (S[0, 1] + S[1, 0])
        d = T(0.5) * (S[0, 0] - S[1, 1])
        m = T(0.5) * (S[0, 0] + S[1, 1])
        r = wp.sqrt(d * d + s12 * s12)
        t = T(0.5) * wp.atan2(s12, d)
        cq = wp.cos(t)
        sq = wp.sin(t)
        Q = M2(cq, -sq, sq, cq)
        return R * Q, V2(m + r, m - r), Q

    return svd2


@functools.cache
def sym_eig_func(T, dim=3):
    """Return ``sym_eig(X) -> (Q, lam)``: eigenvectors (columns of ``Q``) and eigenvalues of a symmetric matrix.

    3D: ``wp.eig3`` (Jacobi; eigenvalues to a few rounding units of ``|X|``). 2D:
    closed form, ``lam = m +- r`` with ``m = tr/2``, ``r = sqrt(((X00 - X11)/2)^2 + X01^2)``,
    ``Q`` the rotation by ``1/2 atan2(2 X01, X00 - X11)``.
    """
    M = mat(dim, T)
    V = vec(dim, T)

    @wp.func
    def sym_eig(X: M):
        if wp.static(dim == 2):
            d = T(0.5) * (X[0, 0] - X[1, 1])
            o = T(0.5) * (X[0, 1] + X[1, 0])
            m = T(0.5) * (X[0, 0] + X[1, 1])
            r = wp.sqrt(d * d + o * o)
            t = T(0.5) * wp.atan2(o, d)
            c = wp.cos(t)
            sn = wp.sin(t)
            return M(c, -sn, sn, c), V(m + r, m - r)
        else:
            Q = M()
            lam = V()
            wp.eig3(X, Q, lam)
            return Q, lam

    return sym_eig


@functools.cache
def principal_func(T, dim=3):
    """Return ``principal(H, h_zz) -> (U, s: vec3, V)``: SVD of ``F_E = I + H`` (``dim x dim`` ``U``, ``V``).

    In 3D ``h_zz`` is ignored; in plane strain ``s[2] = 1 + h_zz``. The last
    in-plane singular value carries the sign of ``det`` (rotations ``U``, ``V``).
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    svd2 = svd2_func(T)

    @wp.func
    def principal(H: M, hzz: T):
        F = wp.identity(dim, dtype=T) + H
        if wp.static(dim == 2):
            U, s2, Vm = svd2(F)
            return U, V3(s2[0], s2[1], T(1.0) + hzz), Vm
        else:
            U = M()
            s = V3()
            Vm = M()
            wp.svd3(F, U, s, Vm)
            return U, s, Vm

    return principal


@functools.cache
def principal_strain_func(T, dim=3):
    """Return ``principal_strain(H, h_zz, s_floor) -> (U, eps: vec3, Vm, s: vec3, svd: int)``.

    Principal Hencky strains ``eps`` and left singular vectors ``U`` of
    ``F_E = I + H`` (plane strain: ``eps[2] = log1p(h_zz)``). Normally from the
    eigen-decomposition of ``X = F F^T - I = H + H^T + H H^T``:
    ``eps_i = 1/2 log1p(lambda_i)``, which keeps the relative precision of a
    strain of 1e-6 in float32 (the SVD of ``I + H`` resolves strains only to a
    rounding unit of 1); then ``svd = 0`` and ``Vm``, ``s`` are not computed. A
    stretch below 1e-2 or ``det F <= 0`` takes the SVD (``svd = 1``): ``s`` the
    signed singular values, ``eps = ln max(s, s_floor)``.
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    sym_eig = sym_eig_func(T, dim)
    principal = principal_func(T, dim)
    log1p = log1p_func(T)

    @wp.func
    def principal_strain(H: M, hzz: T, s_floor: T):
        det = wp.determinant(wp.identity(dim, dtype=T) + H)
        if wp.static(dim == 2):
            det = det * (T(1.0) + hzz)
        if det > T(0.0):
            Q, lam = sym_eig(H + wp.transpose(H) + H * wp.transpose(H))
            lam_min = lam[0]
            for a in range(dim):
                lam_min = wp.min(lam_min, lam[a])
            if lam_min > T(-0.9999):
                eps = V3()
                for a in range(dim):
                    eps[a] = T(0.5) * log1p(lam[a])
                if wp.static(dim == 2):
                    eps[2] = log1p(hzz)
                return Q, eps, M(), V3(), int(0)
        U, s, Vm = principal(H, hzz)
        eps = V3(wp.log(wp.max(s[0], s_floor)), wp.log(wp.max(s[1], s_floor)), wp.log(wp.max(s[2], s_floor)))
        return U, eps, Vm, s, int(1)

    return principal_strain


@functools.cache
def _model_funcs(T, model):
    """``(yield_check, principal_return)`` of a plastic model (None, None for elastic).

    ``yield_check(p, q, lj, mat) -> y`` (> 0 outside the surface);
    ``principal_return(eps, lj, mat) -> (eps_new, lj_new, yielded)`` in principal Hencky strains.
    """
    if model == "elastic":
        return None, None
    if model != "camclay":
        raise ValueError(f"unknown material model {model!r}; expected one of {MODELS}")
    P = material_struct(T)
    V3 = vec(3, T)
    p0f = camclay_p0_func(T)
    yf = camclay_yield_func(T)
    ret = camclay_return_strain_func(T)

    @wp.func
    def yield_check(p: T, q: T, lj: T, m: P):
        K = m.lam + (T(2.0) / T(3.0)) * m.mu
        return yf(p, q, p0f(lj, K, m.xi, m.p0_floor), m.M, m.beta)

    @wp.func
    def principal_return(eps: V3, lj: T, m: P):
        return ret(eps, lj, m.mu, m.lam, m.M, m.beta, m.xi, m.p0_floor)

    return yield_check, principal_return


@functools.cache
def constitutive_update_func(dim, T, model):
    """Build the constitutive update of ``model`` for dimension ``dim`` and scalar type ``T``.

    Signatures of the returned ``wp.func`` (``mat``/``vec`` of size ``dim``)::

        3D: update(H_tr, log_jp, m) -> (H_new, tau, log_jp_new, flags)
        2D: update(H_tr, hzz_tr, log_jp, m) -> (H_new, hzz_new, tau, log_jp_new, flags)

    Parameters
    ----------
    H_tr : mat
        Trial displacement gradient ``F_tr - I`` (-), from :func:`trial_func`.
    hzz_tr : T
        Out-of-plane trial stretch minus one (-), plane strain only.
    log_jp : T
        Hardening state ``ln det F_P`` (-); passed through by elastic models.
    m : MaterialParams
        See :func:`material_struct`.

    Returns
    -------
    H_new, hzz_new : new elastic state (-); ``tau`` : in-plane (2D) or full (3D)
    Kirchhoff stress (Pa, tension positive); ``log_jp_new``; ``flags`` : bits
    :data:`YIELDED`, :data:`FLOORED`, :data:`INVERTED`.
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    P = material_struct(T)
    plastic = model != "elastic"
    yield_check, principal_return = _model_funcs(T, model)
    log_strain = log_strain_func(T, dim)
    log1p = log1p_func(T)
    principal_strain = principal_strain_func(T, dim)
    hencky_strain = hencky_strain_func(T)
    expm1 = expm1_func(T)
    sqrt6 = _SQRT6

    @wp.func
    def small_strain(H_tr: M, hzz: T, lj: T, m: P):
        """Hencky strain by the series, and whether it applies (small, elastic, not inverted)."""
        eps, ok = log_strain(H_tr)
        ezz = T(0.0)
        tr = wp.trace(eps)
        if wp.static(dim == 2):
            if hzz <= T(-1.0):
                ok = 0
            else:
                ezz = log1p(hzz)
                tr = tr + ezz
        if wp.static(plastic):
            if ok != 0:
                mean = tr / T(3.0)
                dev = eps - mean * wp.identity(dim, dtype=T)
                dev2 = wp.ddot(dev, dev)
                if wp.static(dim == 2):
                    dev2 = dev2 + (ezz - mean) * (ezz - mean)
                K = m.lam + (T(2.0) / T(3.0)) * m.mu
                if yield_check(-K * tr, T(sqrt6) * m.mu * wp.sqrt(dev2), lj, m) > T(0.0):
                    ok = 0
        return eps, tr, ok

    @wp.func
    def strain_update(eps: V3, lj: T, m: P):
        """Return mapping (plastic models) and Kirchhoff principal stresses of the new strains."""
        eps_new = eps
        lj_new = lj
        y = int(0)
        if wp.static(plastic):
            e2, l2, yy = principal_return(eps, lj, m)
            eps_new = e2
            lj_new = l2
            y = int(yy)
        return eps_new, lj_new, y, hencky_strain(eps_new, m.mu, m.lam)

    @wp.func
    def general(H_tr: M, hzz: T, lj: T, m: P):
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
        eps_new, lj_new, y, tau_p = strain_update(eps, lj, m)
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
        return H_new, hzz_new, U * Dt * wp.transpose(U), lj_new, flags

    if dim == 2:

        @wp.func
        def update(H_tr: M, hzz: T, lj: T, m: P):
            eps, tr, ok = small_strain(H_tr, hzz, lj, m)
            if ok != 0:
                return H_tr, hzz, T(2.0) * m.mu * eps + (m.lam * tr) * wp.identity(dim, dtype=T), lj, int(0)
            return general(H_tr, hzz, lj, m)

    else:

        @wp.func
        def update(H_tr: M, lj: T, m: P):
            eps, tr, ok = small_strain(H_tr, T(0.0), lj, m)
            if ok != 0:
                return H_tr, T(2.0) * m.mu * eps + (m.lam * tr) * wp.identity(dim, dtype=T), lj, int(0)
            H_new, hzz_new, tau, lj_new, flags = general(H_tr, T(0.0), lj, m)
            return H_new, tau, lj_new, flags

    return update


def singular_value_floor() -> float:
    """The engine's singular-value floor (dimensionless): see ``kernels/camclay.py``."""
    return SINGULAR_VALUE_FLOOR
