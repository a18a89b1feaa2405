"""Material-point driver: the engine's constitutive update on independent points (no grid).

Each point carries the engine's particle state (``H = F_E - I``, ``h_zz`` in plane
strain, ``log_Jp``) and goes through prescribed increments of the velocity
gradient ``L = dt grad v`` (equivalently ``F_inc = I + L``): the trial is
``H_tr = H + L + L H`` and the update is
:func:`mpm_warp.kernels.constitutive.constitutive_update_func`, the very
function P2G calls, so a point driven by the ``dt C`` a particle saw follows that
particle bit for bit. Used to test the constitutive update (docs/validation.md,
"Cam-Clay single material point") and to calibrate a material before a big run.

Mixed control: on chosen axes the normal Cauchy stress is prescribed instead of
the strain (oedometer with a constant load, triaxial with a confining stress,
simple shear under a constant normal stress). The diagonal entries of ``L`` on
those axes are then unknowns, solved at every increment by Newton iterations
with the elastic tangent (``d sigma_aa / d L_bb = lam + 2 mu delta_ab``), repeating
the update from the increment's start state.

Stresses: ``p``, ``q`` Kirchhoff, compression positive (docs/model.md §1); ``stress``
Cauchy ``tau / J_E``, tension positive.
"""

import numpy as np
import warp as wp

from .errors import InvalidArgument
from .kernels.camclay import SINGULAR_VALUE_FLOOR
from .kernels.constitutive import material_struct
from .kernels.material_point import drive_kernel
from .kernels.types import mat, vec
from .materials import CamClaySnow, Elastic, lame_parameters
from .particle_groups import material_params

__all__ = ["drive_material_points", "isotropic_compression", "lame_parameters", "strain_path"]

_DTYPES = {"float32": (wp.float32, np.float32), "float64": (wp.float64, np.float64)}


def _materials(material, n_points: int, legacy: dict) -> list[Elastic]:
    """One validated material per point, from ``material`` (one or a list) or the legacy scalar keywords."""
    if material is None:
        missing = [k for k in ("E", "nu", "M", "beta", "xi") if legacy.get(k) is None]
        if missing:
            raise InvalidArgument("material", None, "a material (Elastic, CamClaySnow) or the keywords E, nu, M, "
                                                    f"beta, xi (missing: {', '.join(missing)})")
        E, nu = legacy["E"], legacy["nu"]
        p0_floor = legacy.get("p0_floor")
        if p0_floor is not None:
            K = lame_parameters(E, nu)[2] if np.isfinite(E) and np.isfinite(nu) and nu < 0.5 else 1.0
            floor_ratio = p0_floor / K if np.isfinite(p0_floor) and p0_floor > 0 and K > 0 else p0_floor
        else:
            floor_ratio = 1e-5
        try:
            material = CamClaySnow(E=E, nu=nu, density=1.0, M=legacy["M"], beta=legacy["beta"], xi=legacy["xi"],
                                   p0_ini=legacy.get("p0_ini", 0.0), p0_floor_ratio=floor_ratio)
            material.validate("material")
        except InvalidArgument as e:
            raise InvalidArgument(e.field.split(".")[-1].replace("p0_floor_ratio", "p0_floor"), e.value,
                                  e.allowed) from None
    mats = list(material) if isinstance(material, (list, tuple)) else [material] * n_points
    if len(mats) != n_points:
        raise InvalidArgument("material", f"{len(mats)} materials", f"one material, or one per point ({n_points})")
    out = []
    for k, mt in enumerate(mats):
        if not isinstance(mt, Elastic):
            raise InvalidArgument(f"material[{k}]", mt, "an Elastic or CamClaySnow material")
        out.append(mt.validate(f"material[{k}]"))
    models = {mt.model for mt in out}
    if len(models) > 1:
        raise InvalidArgument("material", sorted(models), "materials of one model in one call")
    return out


def _per_point(name: str, given, default, lo=None) -> np.ndarray:
    """One finite value per point (float64): ``given`` broadcast, or ``default`` when None."""
    n = len(default)
    a = np.asarray(default if given is None else np.broadcast_to(np.asarray(given, dtype=np.float64), (n,)),
                   dtype=np.float64).copy()
    if not np.all(np.isfinite(a)) or (lo is not None and np.any(a < lo)):
        raise InvalidArgument(name, given, "finite values" + (f" >= {lo:g}" if lo is not None else ""))
    return a


def drive_material_points(F_path=None, *, L_path=None, F_total=None, material=None, F_E0=None, log_jp0=None,
                          kappa0=None,
                          stress_control=None, stress_tol=None, dtype="float32", device=None,
                          E=None, nu=None, M=None, beta=None, xi=None, p0_ini=0.0, p0_floor=None) -> dict:
    """Run the engine's constitutive update on independent material points along prescribed paths.

    Parameters
    ----------
    F_path : array_like, shape (n_points, n_increments, d, d) or (n_increments, d, d)
        Incremental deformation gradients ``F_inc = I + L`` (-); ``d = 3``, or ``d = 2``
        for plane strain (the total ``F_zz`` stays 1). ``L = F_inc - I`` is formed in
        float64 before rounding.
    L_path : array_like, same shapes
        The increments ``L = dt grad v`` (-) directly, instead of ``F_path``: a particle's
        ``dt C`` gives the engine's update bit for bit.
    F_total : array_like, same shapes
        The total deformation gradients reached after each increment (-), relative to the start,
        instead of increments: ``L = F_k F_{k-1}^-1 - I``, formed in the kernel. Under stress control
        the controlled diagonal entries are solved (their given values are ignored).
    material : Elastic, CamClaySnow, BondedCamClay, or a list of them (one per point, one model)
        The material; or give the Cam-Clay parameters as keywords ``E, nu, M, beta, xi,
        p0_ini, p0_floor`` (Pa, -, -, -, -, Pa, Pa).
    F_E0 : array_like, shape (3, 3) or (n_points, 3, 3), optional
        Initial elastic deformation gradient (-), default ``I``. In plane strain the
        in-plane block and ``F_zz`` are used.
    log_jp0, kappa0 : float or array_like (n_points,), optional
        Initial ``ln det F_P`` (-) and accumulated plastic strain of a bonded weak layer (-);
        default each material's initial state (``p0_ini``; an intact bond).
    stress_control : dict, optional
        ``{"axes": (bool,) * d, "sigma": (float,) * d}`` (one for all points, or arrays of
        shape (n_points, d)): on the axes marked True the normal Cauchy stress (Pa,
        tension positive; ``tau / (J_E J_P)``) is held at ``sigma`` and the matching diagonal
        entries of ``L`` (of ``ln F`` for ``F_total``) are solved for at every increment; see
        :mod:`mpm_warp.kernels.material_point` (one axis: a bracketing search that follows a
        collapse; several: Newton iterations).
    stress_tol : float, optional
        Tolerance on the controlled stresses (Pa); default ``1e-12 (lam + 2 mu)`` in float64,
        ``2.5e-7 (lam + 2 mu)`` in float32 (four rounding units of strain).
    dtype : {"float32", "float64"}
    device : str or None
        Warp device; None means Warp's default device.

    Returns
    -------
    dict of numpy.ndarray, index 0 the initial state, shape ``(n_points, n_increments + 1, ...)``
        ``F_E`` (..., 3, 3); ``H`` (..., d, d) and, in plane strain, ``hzz``: the stored elastic
        state ``F_E - I`` in the driver's precision (the engine's particle state); ``log_jp``
        (and ``kappa`` for the bonded weak layer);
        ``p``, ``q`` (Pa, Kirchhoff, compression positive); ``p0`` (Pa; Cam-Clay); ``stress``
        (..., 3, 3) Cauchy (Pa); ``eps_trial``, ``eps`` (..., 3): principal Hencky strains of the
        trial and of the new state (in-plane first, then zz in 2D); ``yielded`` (int32);
        ``L`` (n_points, n_increments, d, d) the increments used (solved entries included); ``F``
        (..., 3, 3) the total deformation gradient since the start; ``tau`` (..., 3, 3) Kirchhoff (Pa);
        ``bond`` (bonded weak layer: ``max(0, 1 - kappa/kappa_s)``);
        ``control_residual`` (Pa, the largest controlled-stress error left at each increment).

    Raises
    ------
    InvalidArgument
        On bad material parameters, shapes, non-finite paths, an unknown ``dtype``.
    """
    if dtype not in _DTYPES:
        raise InvalidArgument("dtype", dtype, f"one of {sorted(_DTYPES)}")
    T, np_t = _DTYPES[dtype]
    paths = {k: v for k, v in (("F_path", F_path), ("L_path", L_path), ("F_total", F_total)) if v is not None}
    if len(paths) != 1:
        raise InvalidArgument("F_path/L_path/F_total", sorted(paths) or "none", "exactly one of them")
    (name, given), = paths.items()
    A = np.asarray(given, dtype=np.float64)
    if A.ndim == 3:
        A = A[None]
    if A.ndim != 4 or A.shape[2] != A.shape[3] or A.shape[2] not in (2, 3) or A.shape[0] < 1 or A.shape[1] < 1:
        raise InvalidArgument(name, f"array of shape {np.shape(given)}",
                              "shape (n_points, n_increments, d, d) or (n_increments, d, d), d = 2 or 3, non-empty")
    if not np.all(np.isfinite(A)):
        raise InvalidArgument(name, "array with non-finite entries", "finite entries")
    n_pts, n_inc, dim = A.shape[0], A.shape[1], A.shape[2]
    L = A - np.eye(dim) if F_path is not None else A     # F_total: the total gradients, passed as they are
    mats = _materials(material, n_pts, dict(E=E, nu=nu, M=M, beta=beta, xi=xi, p0_ini=p0_ini, p0_floor=p0_floor))
    model = mats[0].model

    F0 = np.eye(3) if F_E0 is None else np.asarray(F_E0, dtype=np.float64)
    F0 = np.broadcast_to(F0, (n_pts, 3, 3)) if F0.shape == (3, 3) else F0
    if F0.shape != (n_pts, 3, 3) or not np.all(np.isfinite(F0)):
        raise InvalidArgument("F_E0", f"array of shape {F0.shape}", f"finite, shape (3, 3) or ({n_pts}, 3, 3)")
    H0 = F0[:, :dim, :dim] - np.eye(dim)
    hzz0 = F0[:, 2, 2] - 1.0 if dim == 2 else np.zeros(n_pts)
    lj0 = _per_point("log_jp0", log_jp0, [getattr(mt, "initial_log_jp", 0.0) for mt in mats])
    kap0 = _per_point("kappa0", kappa0, [getattr(mt, "initial_kappa", 0.0) for mt in mats], lo=0.0)

    axes = np.zeros((n_pts, dim))
    targets = np.full((n_pts, n_inc, dim), np.nan)
    if stress_control is not None:
        try:
            axes[:] = np.broadcast_to(np.asarray(stress_control["axes"], dtype=bool), (n_pts, dim))
            sig = np.asarray(stress_control["sigma"], dtype=np.float64)
            sig = sig[:, None, :] if sig.ndim == 2 and sig.shape != (n_inc, dim) else sig
            targets[:] = np.broadcast_to(sig, (n_pts, n_inc, dim))
        except (KeyError, TypeError, ValueError) as e:
            expected = (f"{{'axes': {dim} booleans, 'sigma': {dim} stresses (Pa), or one row of them per increment "
                        "(NaN: not controlled then)}, per point or shared")
            raise InvalidArgument("stress_control", stress_control, expected) from e
        if np.any(np.isinf(targets)):
            raise InvalidArgument("stress_control.sigma", stress_control["sigma"], "finite stresses (Pa) or NaN")
    stiff = max(mt.lam + 2.0 * mt.mu for mt in mats)
    if stress_tol is None:
        stress_tol = (2.5e-7 if dtype == "float32" else 1e-12) * stiff
    if not (np.isfinite(stress_tol) and stress_tol > 0):
        raise InvalidArgument("stress_tol", stress_tol, "a finite number > 0 (Pa)")

    device = wp.get_device(device)
    Md, M3, V3 = mat(dim, T), mat(3, T), vec(3, T)
    shape = (n_pts, n_inc + 1)
    out = {
        "H": wp.zeros(shape, dtype=Md, device=device), "hzz": wp.zeros(shape, dtype=T, device=device),
        "log_jp": wp.zeros(shape, dtype=T, device=device), "kappa": wp.zeros(shape, dtype=T, device=device),
        "yielded": wp.zeros(shape, dtype=wp.int32, device=device),
        "eps_trial": wp.zeros(shape, dtype=V3, device=device), "eps": wp.zeros(shape, dtype=V3, device=device),
        "stress": wp.zeros(shape, dtype=M3, device=device), "p": wp.zeros(shape, dtype=T, device=device),
        "q": wp.zeros(shape, dtype=T, device=device), "p0": wp.zeros(shape, dtype=T, device=device),
        "L": wp.zeros((n_pts, n_inc), dtype=Md, device=device), "F": wp.zeros(shape, dtype=Md, device=device),
        "control_residual": wp.zeros(shape, dtype=T, device=device),
    }
    params = wp.array([material_params(mt, T) for mt in mats], dtype=material_struct(T), device=device)
    wp.launch(drive_kernel(dim, T, model), dim=n_pts,
              inputs=[wp.array(L.astype(np_t), dtype=Md, device=device), int(name == "F_total"), params,
                      wp.array(H0.astype(np_t), dtype=Md, device=device),
                      wp.array(hzz0.astype(np_t), dtype=T, device=device),
                      wp.array(lj0.astype(np_t), dtype=T, device=device),
                      wp.array(kap0.astype(np_t), dtype=T, device=device),
                      wp.array(axes.astype(np_t), dtype=T, device=device),
                      wp.array(targets.astype(np_t), dtype=T, device=device), T(stress_tol)],
              outputs=[out[k] for k in ("H", "hzz", "log_jp", "kappa", "yielded", "eps_trial", "eps", "stress", "p",
                                        "q", "p0", "L", "F", "control_residual")],
              device=device)
    res = {k: a.numpy() for k, a in out.items()}
    if dim == 3:
        res.pop("hzz")
    H, hzz = res["H"].astype(np.float64), out["hzz"].numpy().astype(np.float64)
    F = np.zeros((n_pts, n_inc + 1, 3, 3))
    F[..., :dim, :dim] = H
    F[..., range(3), range(3)] += 1.0
    if dim == 2:
        F[..., 2, 2] += hzz
    res["F_E"] = F
    Ft = np.zeros((n_pts, n_inc + 1, 3, 3))
    Ft[..., :dim, :dim] = res["F"]
    if dim == 2:
        Ft[..., 2, 2] = 1.0
    res["F"] = Ft
    J = np.exp(res["eps"].astype(np.float64).sum(axis=-1))
    if mats[0].plastic:
        J = J * np.exp(res["log_jp"].astype(np.float64) - np.array([m.initial_log_jp for m in mats])[:, None])
    else:
        res.pop("p0")
    res["tau"] = res["stress"].astype(np.float64) * J[..., None, None]
    if model == "bonded_camclay":
        ks = np.array([m.kappa_s for m in mats])[:, None]
        res["bond"] = np.maximum(0.0, 1.0 - res["kappa"].astype(np.float64) / ks)
    elif model == "tensile_cracking":
        res["damage"] = np.stack([m.damage(res["kappa"][k]) for k, m in enumerate(mats)])
    else:
        res.pop("kappa")
    return res


def strain_path(H, n_increments: int) -> np.ndarray:
    """Increments ``F_inc = I + H / n_increments`` of a constant velocity gradient.

    This is the engine's ``F_tr = (I + dt grad v) F_E`` with ``dt grad v = H / n``.

    Parameters
    ----------
    H : array_like, shape (d, d) or (n_points, d, d), d = 2 or 3
        Total displacement-gradient-like increment ``grad v * t_total`` (dimensionless).
    n_increments : int
        Number of increments (>= 1).

    Returns
    -------
    numpy.ndarray, shape (n_increments, d, d) or (n_points, n_increments, d, d)
    """
    if int(n_increments) < 1:
        raise InvalidArgument("n_increments", n_increments, "an integer >= 1")
    H = np.asarray(H, dtype=np.float64)
    if H.ndim not in (2, 3) or H.shape[-1] != H.shape[-2] or H.shape[-1] not in (2, 3):
        raise InvalidArgument("H", f"array of shape {H.shape}", "shape (d, d) or (n_points, d, d), d = 2 or 3")
    step = np.eye(H.shape[-1]) + H / int(n_increments)
    return np.repeat(step[..., None, :, :], int(n_increments), axis=-3)


def isotropic_compression(volumetric_strain: float, n_increments: int, **material) -> dict:
    """Isotropic compression of one point to a total volumetric strain.

    Applies ``n_increments`` equal increments ``F_inc = exp(-volumetric_strain /
    (3 n)) I``, so that ``-ln det F = volumetric_strain`` at the end
    (compression positive). On the cap (``q = 0``) the theory gives
    ``1 - J_P = 1 - exp(-asinh(p/K)/xi)`` (docs/model.md §6, SI Note 3).

    Parameters
    ----------
    volumetric_strain : float
        Total logarithmic volumetric strain ``-ln J`` (dimensionless, finite).
    n_increments : int
        Number of increments (>= 1).
    **material
        Keyword arguments of :func:`drive_material_points` (``material`` or ``E``, ``nu``,
        ``M``, ``beta``, ``xi``, ``p0_ini``, ``p0_floor``; ``dtype``, ``device``).

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


#: floor on singular values used by the update (re-exported for calibration scripts)
SINGULAR_VALUE_FLOOR = SINGULAR_VALUE_FLOOR
