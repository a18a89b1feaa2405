"""The material-point driver's kernel: the engine's constitutive update on independent points, no grid.

One thread per point loops over its increments. An increment is either a velocity-gradient
increment ``L = dt grad v`` (``total = 0``) or the total deformation gradient ``F_k`` reached
(``total = 1``; then ``L = F_k F_{k-1}^-1 - I``). Every increment runs the trial
``H_tr = H + L + L H`` (:func:`~.constitutive.trial_func`) and the update
(:func:`~.constitutive.constitutive_update_func`), the very functions P2G calls.

Mixed control: on the axes flagged in ``axes`` the normal Cauchy stress is held at its target of
the increment (``targets``; NaN: not controlled at that increment) and the matching diagonal entry
of the increment (``L_aa``, or ``ln F_aa`` of a total path) is the unknown. One controlled axis:
a search outward from the previous value (steps doubling from 1e-6) until the residual changes
sign, then regula falsi (Illinois); it finds the equilibrium
nearest to the previous one, so a collapse under a held load (a debonded weak layer under its
slab) happens within the increment. Several axes: Newton iterations with the elastic tangent
``d sigma_aa / d u_b = lam + 2 mu delta_ab``. The Cauchy stress is ``tau / J`` with the volume
ratio ``J = J_E exp(log_jp - log_jp_ref)`` (the elastic and the plastic change of volume since
the material was placed), evaluated in float64 from the stored state. Host side:
:mod:`mpm_warp.material_point`.
"""

import functools

import warp as wp

from .bonded_camclay import bonded_p0_func
from .camclay import camclay_p0_func
from .constitutive import PLASTIC_MODELS, constitutive_update_func, material_struct, trial_func
from .cracking import crack_principal_func
from .elasticity import cauchy_from_principal_func, hencky_strain_func
from .principal import principal_strain_func
from .types import mat, vec

__all__ = ["drive_kernel", "MAX_CONTROL_ITERATIONS"]

#: evaluations of the stress control per increment, at most
MAX_CONTROL_ITERATIONS = 200


@functools.cache
def drive_kernel(dim, T, model):
    """One thread per material point, looping over its increments (see the module docstring)."""
    M = mat(dim, T)
    M3 = mat(3, T)
    V3 = vec(3, T)
    Vd = vec(dim, T)
    P = material_struct(T)
    update = constitutive_update_func(dim, T, model)
    trial = trial_func(T, dim)
    D = wp.float64
    MD = mat(dim, D)
    principal64 = principal_strain_func(D, dim)
    hencky64 = hencky_strain_func(D)
    cauchy_of = cauchy_from_principal_func(T, dim)
    p0f = camclay_p0_func(T)
    bp0f = bonded_p0_func(T)
    plastic = model in PLASTIC_MODELS
    cracking = model == "tensile_cracking"
    crack64 = crack_principal_func(D, dim)
    max_it = MAX_CONTROL_ITERATIONS

    @wp.func
    def step(H: M, hzz: T, lj: T, kap: T, L: M, m: P):
        H_tr = trial(H, L)
        if wp.static(dim == 2):
            H_new, hzz_new, tau, lj_new, kap_new, flags = update(H_tr, hzz, lj, kap, m)
            return H_tr, H_new, hzz_new, lj_new, kap_new, flags
        else:
            H_new, tau, lj_new, kap_new, flags = update(H_tr, lj, kap, m)
            return H_tr, H_new, hzz, lj_new, kap_new, flags

    @wp.func
    def cauchy(H: M, hzz: T, lj: T, kap: T, m: P):
        """Cauchy stress (tau / J), principal strains and Kirchhoff principal stresses of a state (float64); a
        cracking material's stress softened by its ``kappa`` (``kernels/cracking.py``)."""
        U, eps, Vm, s, svd = principal64(MD(H), D(hzz), D(m.s_floor))
        tau = hencky64(eps, D(m.mu), D(m.lam))
        if wp.static(cracking):
            tau = crack64(tau, D(kap), D(m.t_strength), D(m.t_fail))
        J = wp.exp(eps[0] + eps[1] + eps[2] + D(lj) - D(m.log_jp_ref))
        return cauchy_of(U, tau, J), V3(eps), V3(tau)

    @wp.func
    def p0_of(lj: T, kap: T, m: P):
        K = m.lam + (T(2.0) / T(3.0)) * m.mu
        if wp.static(model == "bonded_camclay"):
            p0, b = bp0f(lj, kap, K, m.xi, m.p0_floor, m.p_bond, m.kappa_s)
            return p0
        return p0f(lj, K, m.xi, m.p0_floor)

    @wp.func
    def increment(given: M, F_prev: M, u: Vd, mask: Vd, total: int):
        """``(L, F_k)`` of an increment with the controlled diagonal entries set to ``u``."""
        I = wp.identity(dim, dtype=T)
        L = given
        Fk = given
        if total != 0:
            for a in range(dim):
                if mask[a] != T(0.0):
                    Fk[a, a] = wp.exp(u[a])
            L = Fk * wp.inverse(F_prev) - I
        else:
            for a in range(dim):
                if mask[a] != T(0.0):
                    L[a, a] = u[a]
            Fk = (I + L) * F_prev
        return L, Fk

    @wp.func
    def residual(H: M, hzz: T, lj: T, kap: T, L: M, m: P, mask: Vd, target: Vd):
        H_tr, H_new, hzz_new, lj_new, kap_new, flags = step(H, hzz, lj, kap, L, m)
        sig, e, tau = cauchy(H_new, hzz_new, lj_new, kap_new, m)
        r = Vd()
        for a in range(dim):
            if mask[a] != T(0.0):
                r[a] = sig[a, a] - target[a]
        return r

    @wp.kernel(enable_backward=False, module="unique")
    def drive(path: wp.array2d(dtype=M), total: int, params: wp.array(dtype=P), H0: wp.array(dtype=M),
              hzz0: wp.array(dtype=T), lj0: wp.array(dtype=T), kap0: wp.array(dtype=T),
              axes: wp.array2d(dtype=T), targets: wp.array3d(dtype=T), stress_tol: T, H_out: wp.array2d(dtype=M),
              hzz_out: wp.array2d(dtype=T), lj_out: wp.array2d(dtype=T), kap_out: wp.array2d(dtype=T),
              yielded: wp.array2d(dtype=wp.int32), eps_trial: wp.array2d(dtype=V3), eps: wp.array2d(dtype=V3),
              sigma: wp.array2d(dtype=M3), p_out: wp.array2d(dtype=T), q_out: wp.array2d(dtype=T),
              p0_out: wp.array2d(dtype=T), L_used: wp.array2d(dtype=M), F_out: wp.array2d(dtype=M),
              res_out: wp.array2d(dtype=T)):
        i = wp.tid()
        m = params[i]
        H = H0[i]
        hzz = hzz0[i]
        lj = lj0[i]
        kap = kap0[i]
        H_tr = H
        F_prev = wp.identity(dim, dtype=T)
        for k in range(path.shape[1] + 1):
            flags = int(0)
            if k > 0:
                given = path[i, k - 1]
                # the axes controlled at this increment (a flagged axis with a finite target), elastic tangent
                mask = Vd()
                target = Vd()
                n_ctl = int(0)
                axis = int(0)
                for a in range(dim):
                    t = targets[i, k - 1, a]
                    if axes[i, a] != T(0.0) and wp.isfinite(t):
                        mask[a] = T(1.0)
                        target[a] = t
                        n_ctl += 1
                        axis = a
                Jac = M()
                for a in range(dim):
                    for b in range(dim):
                        if mask[a] != T(0.0) and mask[b] != T(0.0):
                            Jac[a, b] = m.lam
                            if a == b:
                                Jac[a, b] = m.lam + T(2.0) * m.mu
                        elif a == b:
                            Jac[a, b] = T(1.0)
                Jinv = wp.inverse(Jac)
                u = Vd()
                for a in range(dim):
                    u[a] = given[a, a]
                    if total != 0:
                        u[a] = wp.log(F_prev[a, a])  # start from the previous stretch
                res = T(0.0)
                if n_ctl == 1:
                    xa = u[axis]
                    L, Fk = increment(given, F_prev, u, mask, total)
                    rv = residual(H, hzz, lj, kap, L, m, mask, target)
                    ra = rv[axis]
                    xb = xa
                    rb = ra
                    h = T(1.0e-6)
                    direction = T(-1.0)
                    if ra < T(0.0):
                        direction = T(1.0)
                    it = int(0)
                    while it < max_it and wp.abs(rb) > stress_tol and rb * ra > T(0.0):
                        it += 1
                        xa = xb
                        ra = rb
                        xb = xa + direction * h
                        h = h * T(2.0)
                        u[axis] = xb
                        L, Fk = increment(given, F_prev, u, mask, total)
                        rv = residual(H, hzz, lj, kap, L, m, mask, target)
                        rb = rv[axis]
                    x = xb
                    rx = rb
                    side = int(0)
                    while it < max_it and wp.abs(rx) > stress_tol and xa != xb:
                        it += 1
                        x = (xa * rb - xb * ra) / (rb - ra)
                        if x == xa or x == xb:
                            x = T(0.5) * (xa + xb)
                            if x == xa or x == xb:
                                break
                        u[axis] = x
                        L, Fk = increment(given, F_prev, u, mask, total)
                        rv = residual(H, hzz, lj, kap, L, m, mask, target)
                        rx = rv[axis]
                        if rx * rb > T(0.0):
                            xb = x
                            rb = rx
                            if side == 1:
                                ra = ra * T(0.5)
                            side = 1
                        else:
                            xa = x
                            ra = rx
                            if side == -1:
                                rb = rb * T(0.5)
                            side = -1
                    u[axis] = x
                    res = wp.abs(rx)
                elif n_ctl > 1:
                    it = int(0)
                    while it < max_it:
                        L, Fk = increment(given, F_prev, u, mask, total)
                        r = residual(H, hzz, lj, kap, L, m, mask, target)
                        res = T(0.0)
                        for a in range(dim):
                            res = wp.max(res, wp.abs(r[a]))
                        if res <= stress_tol:
                            break
                        u = u - Jinv * r
                        it += 1
                L, Fk = increment(given, F_prev, u, mask, total)
                H_tr, H_new, hzz_new, lj_new, kap_new, flags = step(H, hzz, lj, kap, L, m)
                res_out[i, k] = res
                L_used[i, k - 1] = L
                F_prev = Fk
                H = H_new
                hzz = hzz_new
                lj = lj_new
                kap = kap_new
            F_out[i, k] = F_prev
            sig_t, e_t, tau_t = cauchy(H_tr, hzz, lj, kap, m)
            eps_trial[i, k] = e_t
            H_out[i, k] = H
            hzz_out[i, k] = hzz
            lj_out[i, k] = lj
            kap_out[i, k] = kap
            yielded[i, k] = flags & 1
            sig, e_k, tau = cauchy(H, hzz, lj, kap, m)
            sigma[i, k] = sig
            eps[i, k] = e_k
            p = -(tau[0] + tau[1] + tau[2]) / T(3.0)
            p_out[i, k] = p
            dv = tau + V3(p, p, p)
            q_out[i, k] = wp.sqrt(T(1.5) * wp.dot(dv, dv))
            if wp.static(plastic):
                p0_out[i, k] = p0_of(lj, kap, m)

    return drive
