"""Single-material-point driver for the Cam-Clay snow model (no grid).

Drives the elastic deformation gradient ``F_E`` of independent material points
through prescribed incremental deformation gradients, exactly as the MPM
engine does per particle and step: ``F_tr = F_inc F_E``, SVD, Cam-Clay return
mapping (:func:`mpm_warp.kernels.camclay.camclay_return_func`), rebuild of
``F_E``. Used to test the constitutive update (VALIDATION.md, "Cam-Clay single
material point") and to calibrate ``M``, ``beta``, ``xi`` and ``p0``.

Stresses are Kirchhoff, in Pa, compression positive (MODEL.md section 1).
"""

import functools

import numpy as np
import warp as wp

from mpm_warp.errors import InvalidArgument
from mpm_warp.kernels.camclay import (
    SINGULAR_VALUE_FLOOR,
    camclay_p0_func,
    camclay_pq_func,
    camclay_return_func,
    initial_log_jp,
)
from mpm_warp.kernels.elasticity import clamp_singular_func
from mpm_warp.kernels.types import mat33

__all__ = ["drive_material_points", "isotropic_compression", "lame_parameters", "strain_path"]

_DTYPES = {"float32": (wp.float32, np.float32), "float64": (wp.float64, np.float64)}


def lame_parameters(E: float, nu: float) -> tuple[float, float, float]:
    """Return ``(mu, lam, K)`` (Pa) from Young's modulus ``E`` (Pa) and Poisson's ratio ``nu``.

    ``mu = E / (2 (1 + nu))``, ``lam = E nu / ((1 + nu)(1 - 2 nu))``,
    ``K = lam + 2 mu / 3`` (MODEL.md section 1).
    """
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return mu, lam, lam + 2.0 * mu / 3.0


@functools.cache
def _drive_kernel(T):
    """Kernel: one thread per material point, looping over its increments."""
    m33 = mat33(T)
    camclay_return = camclay_return_func(T)
    camclay_pq = camclay_pq_func(T)
    camclay_p0 = camclay_p0_func(T)
    clamp_singular = clamp_singular_func(T)
    s_floor = SINGULAR_VALUE_FLOOR

    @wp.kernel(enable_backward=False)
    def drive(
        F_inc: wp.array2d(dtype=m33),
        log_jp_ini: T,
        mu: T,
        lam: T,
        M: T,
        beta: T,
        xi: T,
        p0_floor: T,
        F_E: wp.array2d(dtype=m33),
        p: wp.array2d(dtype=T),
        q: wp.array2d(dtype=T),
        log_jp: wp.array2d(dtype=T),
        p0: wp.array2d(dtype=T),
        yielded: wp.array2d(dtype=wp.int32),
    ):
        i = wp.tid()
        K = lam + T(2.0) / T(3.0) * mu
        sf = T(s_floor)
        Fe = wp.identity(n=3, dtype=T)
        ljp = log_jp_ini
        F_E[i, 0] = Fe
        log_jp[i, 0] = ljp
        p0[i, 0] = camclay_p0(ljp, K, xi, p0_floor)
        for k in range(F_inc.shape[1]):
            F_tr = F_inc[i, k] * Fe
            U, sig, V = wp.svd3(F_tr)
            sig_new, ljp_new, y = camclay_return(sig, ljp, mu, lam, M, beta, xi, p0_floor)
            ljp = ljp_new
            if y != 0 or sig[2] < sf:
                Fe = U * wp.diag(clamp_singular(sig_new, sf)) * wp.transpose(V)
            else:
                Fe = F_tr
            pk, qk = camclay_pq(sig_new, mu, lam)
            F_E[i, k + 1] = Fe
            p[i, k + 1] = pk
            q[i, k + 1] = qk
            log_jp[i, k + 1] = ljp
            p0[i, k + 1] = camclay_p0(ljp, K, xi, p0_floor)
            yielded[i, k + 1] = y

    return drive


def _check_positive(name, value, allow_zero=False):
    ok = np.isfinite(value) and (value >= 0.0 if allow_zero else value > 0.0)
    if not ok:
        raise InvalidArgument(name, value, "a finite number " + (">= 0" if allow_zero else "> 0"))


def drive_material_points(F_path, *, E, nu, M, beta, xi, p0_ini=0.0, p0_floor=None, dtype="float32",
                          device=None) -> dict:
    """Run the Cam-Clay update of independent material points along prescribed paths.

    Each point starts at ``F_E = I``, ``log_Jp = -asinh(p0_ini/K)/xi``
    (MODEL.md section 3); at increment ``k`` the trial ``F_tr = F_inc[k] F_E``
    is returned to the yield surface (MODEL.md section 4, SI Note 1) and
    ``F_E`` rebuilt as ``U diag(sig_new) V^T`` when it yielded or was inverted.
    One kernel launch runs all points and increments.

    Parameters
    ----------
    F_path : array_like, shape (n_points, n_increments, 3, 3) or (n_increments, 3, 3)
        Incremental deformation gradients ``F_inc`` (dimensionless), finite.
    E : float
        Young's modulus (Pa, > 0).
    nu : float
        Poisson's ratio, in [0, 0.5).
    M : float
        Slope of the critical state line (> 0).
    beta : float
        Cohesion ratio (>= 0): tensile strength ``beta p0``.
    xi : float
        Hardening coefficient (> 0).
    p0_ini : float
        Initial consolidation pressure (Pa, >= 0).
    p0_floor : float or None
        Floor on ``p0`` (Pa, > 0). Default ``1e-5 K``: small enough that a fully
        softened point carries no meaningful stress, large enough to keep the
        return well conditioned.
    dtype : {"float32", "float64"}
        Scalar type of the kernel.
    device : str or warp.context.Device or None
        Warp device; None means Warp's default device.

    Returns
    -------
    dict of numpy.ndarray
        Over the path, index 0 the initial state, shape ``(n_points, n_increments + 1)``
        unless stated: ``p``, ``q`` (Pa), ``log_jp`` (ln det F_P), ``p0`` (Pa),
        ``yielded`` (int32, 1 where the increment was plastic), ``F_E``
        (``(n_points, n_increments + 1, 3, 3)``). A single path gives ``n_points = 1``.

    Raises
    ------
    InvalidArgument
        On a non-positive ``E``, ``M`` or ``xi``, ``nu`` outside [0, 0.5),
        ``beta < 0``, ``p0_ini < 0``, ``p0_floor <= 0``, an unknown ``dtype`` or a
        badly shaped or non-finite ``F_path``.
    """
    _check_positive("E", E)
    if not (np.isfinite(nu) and 0.0 <= nu < 0.5):
        raise InvalidArgument("nu", nu, "a number in [0, 0.5)")
    _check_positive("M", M)
    _check_positive("beta", beta, allow_zero=True)
    _check_positive("xi", xi)
    _check_positive("p0_ini", p0_ini, allow_zero=True)
    if dtype not in _DTYPES:
        raise InvalidArgument("dtype", dtype, f"one of {sorted(_DTYPES)}")
    T, np_t = _DTYPES[dtype]
    mu, lam, K = lame_parameters(E, nu)
    if p0_floor is None:
        p0_floor = 1.0e-5 * K
    _check_positive("p0_floor", p0_floor)

    F = np.asarray(F_path, dtype=np.float64)
    if F.ndim == 3:
        F = F[None]
    if F.ndim != 4 or F.shape[2:] != (3, 3) or F.shape[0] < 1 or F.shape[1] < 1:
        raise InvalidArgument("F_path", f"array of shape {np.shape(F_path)}",
                              "shape (n_points, n_increments, 3, 3) or (n_increments, 3, 3), non-empty")
    if not np.all(np.isfinite(F)):
        raise InvalidArgument("F_path", "array with non-finite entries", "finite entries")

    device = wp.get_device(device)
    n_pts, n_inc = F.shape[:2]
    m33 = mat33(T)
    F_inc = wp.array(F.astype(np_t), dtype=m33, device=device)
    shape = (n_pts, n_inc + 1)
    out = {
        "F_E": wp.zeros(shape, dtype=m33, device=device),
        "p": wp.zeros(shape, dtype=T, device=device),
        "q": wp.zeros(shape, dtype=T, device=device),
        "log_jp": wp.zeros(shape, dtype=T, device=device),
        "p0": wp.zeros(shape, dtype=T, device=device),
        "yielded": wp.zeros(shape, dtype=wp.int32, device=device),
    }
    wp.launch(
        _drive_kernel(T),
        dim=n_pts,
        inputs=[F_inc, T(initial_log_jp(p0_ini, K, xi)), T(mu), T(lam), T(M), T(beta), T(xi), T(p0_floor)],
        outputs=[out[k] for k in ("F_E", "p", "q", "log_jp", "p0", "yielded")],
        device=device,
    )
    return {k: a.numpy() for k, a in out.items()}


def strain_path(H, n_increments: int) -> np.ndarray:
    """Increments ``F_inc = I + H / n_increments`` of a constant velocity gradient.

    This is the engine's ``F_tr = (I + dt grad v) F_E`` with ``dt grad v = H / n``.

    Parameters
    ----------
    H : array_like, shape (3, 3) or (n_points, 3, 3)
        Total displacement-gradient-like increment ``grad v * t_total`` (dimensionless).
    n_increments : int
        Number of increments (>= 1).

    Returns
    -------
    numpy.ndarray, shape (n_increments, 3, 3) or (n_points, n_increments, 3, 3)
    """
    if int(n_increments) < 1:
        raise InvalidArgument("n_increments", n_increments, "an integer >= 1")
    H = np.asarray(H, dtype=np.float64)
    if H.shape[-2:] != (3, 3) or H.ndim not in (2, 3):
        raise InvalidArgument("H", f"array of shape {H.shape}", "shape (3, 3) or (n_points, 3, 3)")
    step = np.eye(3) + H / int(n_increments)
    return np.repeat(step[..., None, :, :], int(n_increments), axis=-3)


def isotropic_compression(volumetric_strain: float, n_increments: int, **material) -> dict:
    """Isotropic compression of one point to a total volumetric strain.

    Applies ``n_increments`` equal increments ``F_inc = exp(-volumetric_strain /
    (3 n)) I``, so that ``-ln det F = volumetric_strain`` at the end
    (compression positive). On the cap (``q = 0``) the theory gives
    ``1 - J_P = 1 - exp(-asinh(p/K)/xi)`` (MODEL.md section 6, SI Note 3).

    Parameters
    ----------
    volumetric_strain : float
        Total logarithmic volumetric strain ``-ln J`` (dimensionless, finite).
    n_increments : int
        Number of increments (>= 1).
    **material
        Keyword arguments of :func:`drive_material_points` (``E``, ``nu``, ``M``,
        ``beta``, ``xi``, ``p0_ini``, ``p0_floor``, ``dtype``, ``device``).

    Returns
    -------
    dict
        As :func:`drive_material_points`, with ``n_points = 1``.
    """
    if not np.isfinite(volumetric_strain):
        raise InvalidArgument("volumetric_strain", volumetric_strain, "a finite number")
    if int(n_increments) < 1:
        raise InvalidArgument("n_increments", n_increments, "an integer >= 1")
    n = int(n_increments)
    step = np.exp(-volumetric_strain / (3.0 * n)) * np.eye(3)
    return drive_material_points(np.repeat(step[None], n, axis=0), **material)
