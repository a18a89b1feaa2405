"""Material-point driver of the bonded Cam-Clay weak layer (no grid), with mixed control.

TEMPORARY: the smallest F-level driver that the weak-layer calibration
(:mod:`mpm_warp.scenes.weak_layer.calibration`) and its tests need. To be replaced by the shared
material-point driver (:mod:`mpm_warp.material_point`) once that supports
``bonded_camclay``; keep its interface small so the switch is easy.

Per point and increment, exactly as the engine does per particle and step:
``F_tr = F_inc F_E``, SVD, :func:`mpm_warp.kernels.bonded_camclay.bonded_camclay_return_func`,
``F_E = U diag(sig_new) V^T``. Paths are given as *total* deformation gradients
``F[k]`` (from the initial state, dimensionless), ``F_inc = F[k] F[k-1]^-1``.
Mixed control: where ``sigma_yy[k]`` is finite, the component ``F[k][1, 1]``
is not prescribed but solved so that the Cauchy normal stress
``sigma_yy = tau_yy / det F`` equals ``sigma_yy[k]`` (Pa, tension positive):
a search outward from the previous stretch in ``ln F_yy`` then regula falsi
(Illinois), to ``|residual| <= 1e-10 |target|`` (float64) or adjacent floats.
It finds the equilibrium nearest to the previous one, so a collapse under a
held load (the debonded layer under the slab) happens within one increment.

Stresses: Kirchhoff ``tau`` (Pa) and Cauchy ``sigma = tau / det F``; ``det F``
is the volume ratio to the initial state.
"""

import functools
import math
from dataclasses import replace

import numpy as np
import warp as wp

from .errors import InvalidArgument
from .kernels.bonded_camclay import bonded_camclay_return_func, bonded_p0_func
from .kernels.camclay import SINGULAR_VALUE_FLOOR
from .kernels.elasticity import clamp_singular_func, hencky_func
from .kernels.types import mat33, vec3
from .materials import BondedCamClay

__all__ = ["drive_bonded", "total_path"]

_DTYPES = {"float32": (wp.float32, np.float32), "float64": (wp.float64, np.float64)}
_MAX_CONTROL_ITERATIONS = 200


@functools.cache
def _drive_kernel(T):
    """Kernel: one thread per material point, looping over its increments."""
    m33 = mat33(T)
    v3 = vec3(T)
    ret = bonded_camclay_return_func(T)
    hencky = hencky_func(T)
    clamp = clamp_singular_func(T)
    p0_fn = bonded_p0_func(T)
    sf = SINGULAR_VALUE_FLOOR
    rtol = 1e-10 if T == wp.float64 else 1e-6
    max_it = _MAX_CONTROL_ITERATIONS

    @wp.func
    def update(F_new: m33, F_old_inv: m33, Fe: m33, ljp: T, kap: T, mu: T, lam: T, M: T, beta: T, xi: T,
               pf: T, pb: T, ks: T):
        F_tr = F_new * F_old_inv * Fe
        U = m33()
        sig = v3()
        V = m33()
        wp.svd3(F_tr, U, sig, V)
        s2, l2, k2, y = ret(sig, ljp, kap, mu, lam, M, beta, xi, pf, pb, ks)
        Fe2 = F_tr
        if y != 0 or sig[2] < T(sf):
            Fe2 = U * wp.diag(clamp(s2, T(sf))) * wp.transpose(V)
        t = hencky(s2, mu, lam, T(sf))
        tau = U * wp.diag(t) * wp.transpose(U)
        return Fe2, tau, l2, k2, y

    @wp.func
    def with_yy(F: m33, s: T):
        G = F
        G[1, 1] = s
        return G

    @wp.kernel(enable_backward=False)
    def drive(F_path: wp.array2d(dtype=m33), sigma_yy: wp.array2d(dtype=T), log_jp_ini: T, kappa_ini: T, mu: T,
              lam: T, M: T, beta: T, xi: T, pf: T, pb: T, ks: T,
              F_tot: wp.array2d(dtype=m33), F_E: wp.array2d(dtype=m33), tau: wp.array2d(dtype=m33),
              log_jp: wp.array2d(dtype=T), kappa: wp.array2d(dtype=T), p0: wp.array2d(dtype=T),
              bond: wp.array2d(dtype=T), yielded: wp.array2d(dtype=wp.int32)):
        i = wp.tid()
        K = lam + T(2.0) / T(3.0) * mu
        Fe = wp.identity(n=3, dtype=T)
        F_old = wp.identity(n=3, dtype=T)
        ljp = log_jp_ini
        kap = kappa_ini
        F_tot[i, 0] = F_old
        F_E[i, 0] = Fe
        log_jp[i, 0] = ljp
        kappa[i, 0] = kap
        p00, b0 = p0_fn(ljp, kap, K, xi, pf, pb, ks)
        p0[i, 0] = p00
        bond[i, 0] = b0
        for k in range(F_path.shape[1]):
            F_new = F_path[i, k]
            target = sigma_yy[i, k]
            inv = wp.inverse(F_old)
            if wp.isfinite(target):
                # r(s) = tau_yy / det F - target, s = ln F_yy: bracket outward from the previous stretch
                a = wp.log(F_old[1, 1])
                Fe2, t2, l2, k2, y = update(with_yy(F_new, wp.exp(a)), inv, Fe, ljp, kap, mu, lam, M, beta, xi,
                                            pf, pb, ks)
                ra = t2[1, 1] / wp.determinant(with_yy(F_new, wp.exp(a))) - target
                tol = T(rtol) * wp.abs(target)
                step = T(1.0e-6)
                direction = T(-1.0)
                if ra < T(0.0):
                    direction = T(1.0)
                b = a
                rb = ra
                it = int(0)  # noqa: UP018 (a mutable Warp int)
                while it < max_it and wp.abs(rb) > tol and rb * ra > T(0.0):
                    it += 1
                    a = b
                    ra = rb
                    b = a + direction * step
                    step = step * T(2.0)
                    Fb = with_yy(F_new, wp.exp(b))
                    Fe2, t2, l2, k2, y = update(Fb, inv, Fe, ljp, kap, mu, lam, M, beta, xi, pf, pb, ks)
                    rb = t2[1, 1] / wp.determinant(Fb) - target
                # Illinois on [a, b] (r changes sign), keeping the last evaluated point
                x = b
                rx = rb
                side = int(0)  # noqa: UP018
                while it < max_it and wp.abs(rx) > tol and a != b:
                    it += 1
                    x = (a * rb - b * ra) / (rb - ra)
                    if x == a or x == b:
                        x = T(0.5) * (a + b)
                        if x == a or x == b:
                            break
                    Fx = with_yy(F_new, wp.exp(x))
                    Fe2, t2, l2, k2, y = update(Fx, inv, Fe, ljp, kap, mu, lam, M, beta, xi, pf, pb, ks)
                    rx = t2[1, 1] / wp.determinant(Fx) - target
                    if rx * rb > T(0.0):
                        b = x
                        rb = rx
                        if side == 1:
                            ra = ra * T(0.5)
                        side = 1
                    else:
                        a = x
                        ra = rx
                        if side == -1:
                            rb = rb * T(0.5)
                        side = -1
                # the state of the last evaluated stretch x (an evaluated bracket end otherwise)
                F_new = with_yy(F_new, wp.exp(x))
                Fe2, t2, l2, k2, y = update(F_new, inv, Fe, ljp, kap, mu, lam, M, beta, xi, pf, pb, ks)
                Fe = Fe2
                ljp = l2
                kap = k2
                tau[i, k + 1] = t2
                yielded[i, k + 1] = y
            else:
                Fe2, t2, l2, k2, y = update(F_new, inv, Fe, ljp, kap, mu, lam, M, beta, xi, pf, pb, ks)
                Fe = Fe2
                ljp = l2
                kap = k2
                tau[i, k + 1] = t2
                yielded[i, k + 1] = y
            F_old = F_new
            F_tot[i, k + 1] = F_new
            F_E[i, k + 1] = Fe
            log_jp[i, k + 1] = ljp
            kappa[i, k + 1] = kap
            pk, bk = p0_fn(ljp, kap, K, xi, pf, pb, ks)
            p0[i, k + 1] = pk
            bond[i, k + 1] = bk

    return drive


def drive_bonded(material: BondedCamClay, F_path, sigma_yy=None, *, kappa_ini: float = 0.0,
                 dtype: str = "float64", device=None) -> dict:
    """Drive independent bonded Cam-Clay material points along total deformation paths.

    Parameters
    ----------
    material : BondedCamClay
        The weak-layer material (validated here); ``kappa_s`` may also be ``inf`` (the bond kept).
    F_path : array_like, shape (n_points, n_increments, 3, 3) or (n_increments, 3, 3)
        Total deformation gradient after each increment (dimensionless); its
        ``[1, 1]`` entry is only the starting guess where ``sigma_yy`` is given.
    sigma_yy : array_like or None, shape (n_points, n_increments) or (n_increments,)
        Cauchy normal stress to hold (Pa, tension positive; NaN: not controlled).
    kappa_ini : float
        Initial accumulated plastic strain (-), >= 0 (``>= kappa_s``: a debonded layer).
    dtype : {"float32", "float64"}
    device : warp device or None

    Returns
    -------
    dict of numpy.ndarray, index 0 the initial state, shape ``(n_points, n_increments + 1)``:
        ``F`` (total, ``(..., 3, 3)``), ``F_E`` (``(..., 3, 3)``), ``tau`` (Kirchhoff, Pa,
        ``(..., 3, 3)``), ``sigma`` (Cauchy, Pa), ``log_jp``, ``kappa``, ``p0`` (Pa), ``bond``,
        ``yielded`` (int32), ``p``, ``q`` (Kirchhoff, Pa).
    """
    if not isinstance(material, BondedCamClay):
        raise InvalidArgument("material", material, "a BondedCamClay")
    kept = material.kappa_s == math.inf  # a bond that never breaks: allowed here (tests of the return)
    (replace(material, kappa_s=1.0) if kept else material).validate("material")
    if not (np.isfinite(kappa_ini) and kappa_ini >= 0):
        raise InvalidArgument("kappa_ini", kappa_ini, "a finite number >= 0")
    if dtype not in _DTYPES:
        raise InvalidArgument("dtype", dtype, f"one of {sorted(_DTYPES)}")
    T, nt = _DTYPES[dtype]
    F = np.asarray(F_path, dtype=np.float64)
    if F.ndim == 3:
        F = F[None]
    if F.ndim != 4 or F.shape[2:] != (3, 3) or F.shape[1] < 1 or not np.all(np.isfinite(F)):
        raise InvalidArgument("F_path", f"array of shape {np.shape(F_path)}",
                              "finite, shape (n_points, n_increments, 3, 3) or (n_increments, 3, 3)")
    n_pts, n_inc = F.shape[:2]
    S = np.full((n_pts, n_inc), np.nan) if sigma_yy is None else np.broadcast_to(
        np.asarray(sigma_yy, dtype=np.float64).reshape((-1, n_inc)), (n_pts, n_inc))
    device = wp.get_device(device)
    m33 = mat33(T)
    shape = (n_pts, n_inc + 1)
    names = ("F", "F_E", "tau", "log_jp", "kappa", "p0", "bond", "yielded")
    out = {k: wp.zeros(shape, dtype=m33 if k in ("F", "F_E", "tau") else (wp.int32 if k == "yielded" else T),
                       device=device) for k in names}
    m = material
    wp.launch(_drive_kernel(T), dim=n_pts,
              inputs=[wp.array(F.astype(nt), dtype=m33, device=device),
                      wp.array(np.ascontiguousarray(S).astype(nt), dtype=T, device=device),
                      T(m.initial_log_jp), T(kappa_ini), T(m.mu), T(m.lam), T(m.M), T(m.beta), T(m.xi),
                      T(m.p0_floor), T(m.p_bond), T(m.kappa_s)],
              outputs=[out[k] for k in names], device=device)
    r = {k: a.numpy() for k, a in out.items()}
    tau = r["tau"].astype(np.float64)
    J = np.linalg.det(r["F"].astype(np.float64))
    r["sigma"] = tau / J[..., None, None]
    p = -np.trace(tau, axis1=-2, axis2=-1) / 3.0
    dev = tau + p[..., None, None] * np.eye(3)
    r["p"] = p
    r["q"] = np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))
    return r


def total_path(gamma, stretch_y=1.0) -> np.ndarray:
    """Total deformation gradients ``[[1, gamma, 0], [0, stretch_y, 0], [0, 0, 1]]`` (simple shear of ``x``
    along the layer normal ``y`` with lateral confinement), shape ``(n, 3, 3)``."""
    g = np.atleast_1d(np.asarray(gamma, dtype=np.float64))
    F = np.repeat(np.eye(3)[None], len(g), axis=0)
    F[:, 0, 1] = g
    F[:, 1, 1] = np.broadcast_to(np.asarray(stretch_y, dtype=np.float64), g.shape)
    return F
