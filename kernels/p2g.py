"""Particle-to-grid transfer (MLS-MPM, Hu et al. 2018) with the constitutive update.

One launch per particle group (a block of one material). Per particle, in
physical order:

1. trial elastic deformation gradient ``F_tr = (I + dt C) F_E`` (MODEL.md 4);
2. Hencky strain ``eps = 1/2 log(F F^T)`` by its series when the strain is
   small and, for Cam-Clay, the state inside the yield surface (no SVD:
   ``kernels/logstrain.py``);
3. otherwise the SVD ``F_tr = U diag(s) V^T``, the singular-value floor and,
   for plastic groups only, the Cam-Clay return;
4. Kirchhoff stress ``tau = 2 mu eps + lam tr(eps) I`` (= ``U diag(2 mu ln s +
   lam tr ln s) U^T``);
5. scatter of mass and of the MLS-MPM momentum
   ``m v + (m C - dt V0 D^-1 tau) (x_i - x_p)``, ``D^-1 = 4 / dx^2``.
"""

import functools
import math

import warp as wp

from .camclay import camclay_p0_func, camclay_return_func, camclay_yield_func
from .elasticity import clamp_singular_func, hencky_func
from .logstrain import log_strain_func
from .shape import in_grid, stencil_func
from .types import mat33, vec3

SQRT6 = math.sqrt(6.0)


@functools.cache
def p2g_kernel(T, plastic: bool, track_yield: bool):
    """Build the P2G kernel.

    Parameters
    ----------
    T : warp scalar type
        ``wp.float32`` or ``wp.float64``.
    plastic : bool
        Compile the Cam-Clay return (``log_jp`` is read and written).
    track_yield : bool
        Also set ``yielded[i] = 1`` where the return was active (output field).
    """
    V = vec3(T)
    M = mat33(T)
    stencil = stencil_func(T)
    hencky = hencky_func(T)
    clamp_sv = clamp_singular_func(T)
    camclay = camclay_return_func(T)
    camclay_p0 = camclay_p0_func(T)
    camclay_yield = camclay_yield_func(T)
    log_strain = log_strain_func(T)

    @wp.kernel(enable_backward=False)
    def p2g(
        x: wp.array(dtype=V),
        v: wp.array(dtype=V),
        C: wp.array(dtype=M),
        F: wp.array(dtype=M),
        log_jp: wp.array(dtype=T),
        yielded: wp.array(dtype=wp.uint8),
        mass: T,
        vol0: T,
        mu: T,
        lam: T,
        M_csl: T,
        beta: T,
        xi: T,
        p0_floor: T,
        s_floor: T,
        dt_arr: wp.array(dtype=T),
        origin: V,
        inv_dx: T,
        dx: T,
        grid_m: wp.array3d(dtype=T),
        grid_p: wp.array3d(dtype=V),
        lost: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        xp = x[i]
        Cp = C[i]
        F_tr = (wp.identity(3, dtype=T) + dt * Cp) * F[i]
        # fast path: small elastic strain, Hencky stress from the log series (no SVD)
        eps, ok = log_strain(F_tr)
        tr_eps = wp.trace(eps)
        if wp.static(plastic):
            if ok != 0:
                K = lam + T(2.0 / 3.0) * mu
                dev = eps - (tr_eps / T(3.0)) * wp.identity(3, dtype=T)
                q = T(SQRT6) * mu * wp.sqrt(wp.ddot(dev, dev))
                p0 = camclay_p0(log_jp[i], K, xi, p0_floor)
                if camclay_yield(-K * tr_eps, q, p0, M_csl, beta) > T(0.0):
                    ok = 0
        tau = T(2.0) * mu * eps + (lam * tr_eps) * wp.identity(3, dtype=T)
        if ok != 0:
            F[i] = F_tr
        else:
            # general path: SVD, singular-value floor, Cam-Clay return
            U = M()
            s = V()
            Vt = M()
            wp.svd3(F_tr, U, s, Vt)
            s_new = clamp_sv(s, s_floor)
            changed = int(0)
            floored = int(0)
            if s_new[2] != s[2]:
                changed = 1
                floored = 1
            if wp.static(plastic):
                s_ret, ljp, y = camclay(s_new, log_jp[i], mu, lam, M_csl, beta, xi, p0_floor)
                s_new = s_ret
                log_jp[i] = ljp
                changed = changed | int(y)
                if wp.static(track_yield):
                    if y != 0:
                        yielded[i] = wp.uint8(1)
            if floored != 0:
                F[i] = U * wp.diag(s_new) * wp.transpose(Vt)
            elif changed != 0:
                # U diag(s_new) V^T written as a correction of F_tr: rebuilding from the float32 SVD factors
                # puts round-off back outside the yield surface and ratchets a settled layer (creep)
                r = V((s_new[0] - s[0]) / s[0], (s_new[1] - s[1]) / s[1], (s_new[2] - s[2]) / s[2])
                F[i] = F_tr + F_tr * (Vt * wp.diag(r) * wp.transpose(Vt))
            else:
                F[i] = F_tr
            tau_p = hencky(s_new, mu, lam, s_floor)
            tau = U * wp.diag(tau_p) * wp.transpose(U)
        A = (-dt * vol0 * T(4.0) * inv_dx * inv_dx) * tau + mass * Cp
        mv = mass * v[i]
        b, fx, W = stencil(xp, origin, inv_dx)
        if not in_grid(b, grid_m.shape[0], grid_m.shape[1], grid_m.shape[2]):
            wp.atomic_add(lost, 0, 1)
            return
        for a in range(3):
            for c in range(3):
                for d in range(3):
                    w = W[a, 0] * W[c, 1] * W[d, 2]
                    dpos = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                    wp.atomic_add(grid_m, b[0] + a, b[1] + c, b[2] + d, w * mass)
                    wp.atomic_add(grid_p, b[0] + a, b[1] + c, b[2] + d, w * (mv + A * dpos))

    return p2g
