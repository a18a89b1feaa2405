"""The Cam-Clay return of the Taichi peer (:mod:`.taichi_mpm`): ``ti.func``'s over one scene's constants.

The Cam-Clay return is the same algorithm as mpm_warp's (docs/model.md §4): the
point of the yield ellipse closest to the trial ``(p, q)`` in the energy metric
``dp^2/K + dq^2/(3 mu)``, found in scaled coordinates by Eberly's
parametrisation with Halley steps from the left end of the root bracket, Newton
steps once one has passed the root, bisection after that (the same stopping
rule: ``0 <= f <= 4 eps``, a bracket below ``4 eps (1 + s)``, no progress, at
most 100 iterations), then
``log_Jp += tr eps_tr - tr eps_new`` and ``p0 = K sinh(xi max(-log_Jp, 0))``
(explicit hardening).
"""

from __future__ import annotations

import math
from typing import Any

from .. import plastic_block as pb

#: Singular-value floor before ln (as mpm_warp's).
S_FLOOR = 1.0e-6
#: Root iterations at most (Halley, Newton, bisection), and the float32 tolerance, of the ellipse root.
MAX_ROOT_ITERATIONS = 100
ROOT_EPS = 4.0 * 2.0**-23


def camclay_return_func(ti: Any, mu: float, K: float):
    """``camclay_return(s, log_jp) -> (s_new, log_jp_new, yielded)``, a ``ti.func`` (docs/model.md §4).

    ``s`` are the three principal stretches, ``mu`` and ``K`` the shear and bulk moduli (Pa) of the
    scene; M, beta, xi and the p0 floor are those of :mod:`mpm_warp.studies.plastic_block`.
    """
    s_floor = S_FLOOR
    M_csl, beta, xi = pb.M_CSL, pb.BETA, pb.XI
    p0_floor = pb.P0_FLOOR_RATIO * K
    x_cap = math.asinh(-3.0 * math.log(S_FLOOR))
    rho_m = math.sqrt(3.0 * mu / K)  # q = a rho_m v in the scaled coordinates
    c_axis = M_csl / (math.sqrt(1.0 + 2.0 * beta) * rho_m)
    sqrt6 = math.sqrt(6.0)
    inv_3K = 1.0 / (3.0 * K)
    root_eps = ROOT_EPS
    max_it = MAX_ROOT_ITERATIONS

    @ti.func
    def ellipse_root_f(s, n0, r0, z1):
        """f, f', f'' and the reciprocals 1/(s + r0), 1/(s + 1)."""
        i0 = 1.0 / (s + r0)
        i1 = 1.0 / (s + 1.0)
        a2 = (n0 * i0) * (n0 * i0)
        b2 = (z1 * i1) * (z1 * i1)
        return ti.Vector([a2 + b2 - 1.0, -2.0 * (a2 * i0 + b2 * i1), 6.0 * (a2 * i0 * i0 + b2 * i1 * i1), i0, i1])

    @ti.func
    def ellipse_closest(e0, e1, ie0, ie1, y0, y1):
        """Closest point of (x0/e0)^2 + (x1/e1)^2 = 1 to (y0, y1) >= 0, outside, e0 >= e1 > 0 (Eberly's
        parametrisation; Halley, then Newton, then bisection steps from the bracket's lower end; a step past the
        root by rounding only ends it), and the factors x0/y0, x1/y1 (the root's reciprocals)."""
        res = ti.Vector([y0, y1, 1.0, 1.0])
        if y1 <= 0.0:
            res = ti.Vector([e0, 0.0, e0 / y0, 0.0])
        elif y0 <= 0.0:
            res = ti.Vector([0.0, e1, 0.0, e1 / y1])
        else:
            z0 = y0 * ie0
            z1 = y1 * ie1
            if z0 * z0 + z1 * z1 > 1.0:
                r0 = (e0 * ie1) * (e0 * ie1)
                n0 = r0 * z0
                lo = ti.max(0.0, ti.max(z1 - 1.0, n0 - r0))
                hi = ti.max(lo, ti.sqrt(n0 * n0 + z1 * z1) - 1.0)
                fd = ellipse_root_f(lo, n0, r0, z1)
                mode = 2
                it = 0
                while it < max_it and fd[0] > root_eps and hi - lo > root_eps * (1.0 + lo):
                    it += 1
                    f = fd[0]
                    df = fd[1]
                    den = 2.0 * df * df - f * fd[2]
                    s = 0.5 * (lo + hi)
                    if mode == 2 and den > 0.0:
                        s = ti.min(lo - 2.0 * f * df / den, hi)
                    elif mode >= 1 and df < 0.0:
                        s = ti.min(lo - f / df, hi)
                    if not s > lo:
                        break
                    fs = ellipse_root_f(s, n0, r0, z1)
                    if fs[0] >= -root_eps:
                        lo = s
                        fd = fs
                    else:
                        hi = s
                        mode = ti.max(mode - 1, 0)
                res = ti.Vector([(r0 * y0) * fd[3], y1 * fd[4], r0 * fd[3], fd[4]])
        return res

    @ti.func
    def camclay_return(s, ljp):
        """Principal stretches s (3) and log_Jp -> (s_new, log_Jp_new, yielded) (docs/model.md §4)."""
        eps = ti.Vector([ti.log(ti.max(s[0], s_floor)), ti.log(ti.max(s[1], s_floor)),
                         ti.log(ti.max(s[2], s_floor))])
        tr = eps[0] + eps[1] + eps[2]
        dev = eps - tr / 3.0
        p_tr = -K * tr
        q_tr = sqrt6 * mu * dev.norm()
        h = ti.min(xi * ti.max(-ljp, 0.0), x_cap)
        p0 = ti.max(K * 0.5 * (ti.exp(h) - ti.exp(-h)), p0_floor)  # K sinh(h): Taichi has no sinh
        y = (1.0 + 2.0 * beta) * q_tr * q_tr + M_csl * M_csl * (p_tr + beta * p0) * (p_tr - p0)
        s_new = s
        ljp_new = ljp
        hit = 0
        if y > 0.0:
            hit = 1
            a = 0.5 * p0 * (1.0 + beta)
            pc = 0.5 * p0 * (1.0 - beta)
            du = p_tr - pc
            u = ti.abs(du) / a
            w = q_tr / (a * rho_m)
            xu = 0.0
            fv = 0.0
            if ti.static(c_axis <= 1.0):
                r = ellipse_closest(1.0, c_axis, 1.0, 1.0 / c_axis, u, w)
                xu = r[0]
                fv = r[3]
            else:
                r = ellipse_closest(c_axis, 1.0, 1.0 / c_axis, 1.0, w, u)
                xu = r[1]
                fv = r[2]
            p_new = p0 - a * (1.0 - xu)
            if du < 0.0:
                p_new = -beta * p0 + a * (1.0 - xu)
            scale = 0.0
            if q_tr > 0.0:
                scale = ti.min(fv, 1.0)  # q_new / q_tr = xv / w, the root's reciprocal
            m_new = -p_new * inv_3K
            s_new = ti.exp(dev * scale + m_new)
            ljp_new = ljp + tr - 3.0 * m_new
        return s_new, ljp_new, hit

    return camclay_return
