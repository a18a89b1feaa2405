"""Reference loading paths of the bonded weak layer: closed forms and material-point runs.

The weak layer, laterally confined (no strain along the bed, ``x`` and ``z``),
is loaded in the two tests that define its measured properties
(:mod:`mpm_warp.scenes.weak_layer.calibration`):

* **uniaxial strain** (oedometer) ``F = diag(1, lambda, 1)``: the compressive
  strength ``sigma_c`` is the Cauchy normal stress at first yield;
* **simple shear under the slab's normal stress** ``F = [[1, gamma, 0], [0,
  lambda, 0], [0, 0, 1]]`` with the Cauchy ``sigma_yy = -sigma_n`` held
  (``lambda`` free) and ``gamma`` imposed: the shear strength ``tau_p`` is the
  shear stress ``sigma_xy`` at first yield; then the bond softens and, once the
  bond cannot carry ``sigma_n`` any more, the layer collapses.

Elastic states are exact at finite strain (Hencky, docs/model.md §1): uniaxial
strain has ``eps = (0, ln lambda, 0)``; simple shear ``eps = ln(F F^T)/2``,
solved by Newton in ``(ln lambda, gamma)``. The yield test of a state is
:func:`mpm_warp.validation.weak_layer.consolidation_pressure` (the ellipse
through ``(p, q)``). The softening part has no closed form: it is measured on
the material-point driver (:mod:`mpm_warp.material_point`, the engine's update).

Definitions (per unit area of the layer of thickness ``D_wl``; the
material point is the layer, uniform across its thickness):

* plastic slip ``delta_p = D_wl (gamma - gamma_e)``, ``gamma_e = 2 eps_e,xy``
  the elastic shear strain (lab-frame Hencky strain of ``F_E``);
* ``delta_s``: plastic slip from first yield to the loss of the bond (``b = 0``);
* residual ``tau_r``: the lowest shear stress after the peak (reached when the
  bond is gone: right after the collapse, before the collapsed layer
  re-hardens towards its critical state);
* fracture energy ``w_f = integral (tau - tau_r) d delta_p`` from first yield
  to the loss of the bond (J/m^2): the work of the shear stress in excess of
  the residual over the softening (the cohesive-zone fracture energy in the
  slip, e.g. Bazant et al. 2003; the tip of a crack pays it, the slab's weight
  pays for the collapse behind it).
"""

import math

import numpy as np

from ...camclay_forms import consolidation_pressure, oedometric_p0
from ...camclay_forms import oedometric_collapse as confined_collapse
from ...errors import InvalidArgument
from ...material_point import drive_material_points
from ...materials import BondedCamClay
from ...stress import cauchy_stress

__all__ = [
    "compressive_strength", "elastic_shear_state", "shear_strength", "bond_pressure_for_shear_strength",
    "oedometric_collapse", "xi_for_collapse", "loaded_shear_test",
]


def simple_shear_path(gamma, stretch_y=1.0) -> np.ndarray:
    """Total deformation gradients ``[[1, gamma, 0], [0, stretch_y, 0], [0, 0, 1]]`` (simple shear of ``x``
    along the layer normal ``y`` with lateral confinement), shape ``(n, 3, 3)``."""
    g = np.atleast_1d(np.asarray(gamma, dtype=np.float64))
    F = np.repeat(np.eye(3)[None], len(g), axis=0)
    F[:, 0, 1] = g
    F[:, 1, 1] = stretch_y
    return F


def drive_layer(mat: BondedCamClay, F_total, sigma_yy=None, *, kappa0=None, dtype: str = "float64",
                device=None) -> dict:
    """The shared material-point driver (:func:`mpm_warp.material_point.drive_material_points`) on total paths
    ``F_total`` (n, 3, 3), with the bed-normal Cauchy stress ``sigma_yy`` (Pa, tension positive; one per
    increment, NaN: not held) held by solving ``F_yy``: the layer under its slab. ``kappa0``: a debonded start."""
    control = None
    if sigma_yy is not None:
        s = np.asarray(sigma_yy, dtype=np.float64)
        nan = np.full_like(s, np.nan)
        control = {"axes": (False, True, False), "sigma": np.stack([nan, s, nan], axis=-1)}
    return drive_material_points(F_total=F_total, material=mat, kappa0=kappa0, stress_control=control, dtype=dtype,
                                 device=device)


def _hencky_cauchy(mat, lam_y: float, gamma: float) -> np.ndarray:
    """Cauchy stress (Pa, 3x3) of the elastic state ``F = [[1, gamma, 0], [0, lam_y, 0], [0, 0, 1]]``."""
    return cauchy_stress(np.array([[1.0, gamma, 0.0], [0.0, lam_y, 0.0], [0.0, 0.0, 1.0]]), mat.mu, mat.lam)[0]


def _p_q(sigma: np.ndarray, J: float) -> tuple[float, float]:
    tau = J * sigma
    p = -np.trace(tau) / 3.0
    dev = tau + p * np.eye(3)
    return p, math.sqrt(1.5 * np.sum(dev * dev))


def compressive_strength(mat: BondedCamClay) -> float:
    """Uniaxial-strain (oedometric) strength of the intact layer: Cauchy ``sigma_v`` (Pa, > 0) at first yield.

    Exact: on ``F = diag(1, lambda, 1)`` the Hencky strain is ``(0, e, 0)``,
    ``e = ln lambda``, so ``p = -K e``, ``q = 2 mu |e|``; the yield function
    ``(1 + 2 beta) 4 mu^2 e^2 + M^2 (-K e + beta p0)(-K e - p0) = 0`` is a
    quadratic in ``e`` (its negative root), and ``sigma_v = -(lam + 2 mu) e / lambda``.
    """
    K, mu, M, beta, p0 = mat.bulk, mat.mu, mat.M, mat.beta, mat.p0_ini
    A = 4.0 * (1.0 + 2.0 * beta) * mu * mu + M * M * K * K
    B = M * M * K * p0 * (1.0 - beta)
    C = -M * M * beta * p0 * p0
    e = (-B - math.sqrt(B * B - 4.0 * A * C)) / (2.0 * A)
    return -(mat.lam + 2.0 * mu) * e / math.exp(e)


def elastic_shear_state(mat, sigma_n: float, tau: float) -> tuple[float, float, float, float]:
    """Elastic simple shear with lateral confinement at Cauchy ``sigma_yy = -sigma_n``, ``sigma_xy = tau``.

    Returns ``(lambda_y, gamma, p, q)``: the stretch across the layer, the
    shear of ``F``, and the Kirchhoff ``p, q`` (Pa). Newton in ``(ln lambda, gamma)``
    with a finite-difference Jacobian, to 1e-13 of the stresses.
    """
    x = np.array([-sigma_n / (mat.lam + 2.0 * mat.mu), tau / mat.mu])
    scale = max(abs(sigma_n), abs(tau), 1e-12 * mat.mu)

    def resid(v):
        s = _hencky_cauchy(mat, math.exp(v[0]), v[1])
        return np.array([s[1, 1] + sigma_n, s[0, 1] - tau]) / scale

    for _ in range(50):
        r = resid(x)
        if np.max(np.abs(r)) < 1e-13:
            break
        h = 1e-7 * max(abs(sigma_n), abs(tau), 1.0) / mat.mu
        Jm = np.column_stack([(resid(x + h * e) - resid(x - h * e)) / (2 * h) for e in np.eye(2)])
        x = x - np.linalg.solve(Jm, r)
    lam_y = math.exp(x[0])
    p, q = _p_q(_hencky_cauchy(mat, lam_y, x[1]), lam_y)
    return lam_y, float(x[1]), p, q


def shear_strength(mat: BondedCamClay, sigma_n: float) -> float:
    """First-yield shear stress ``tau_p`` (Pa) of the intact layer in simple shear under ``sigma_n`` (Pa).

    Bisection on ``tau`` for the elastic state (:func:`elastic_shear_state`) whose
    ellipse ``p0`` (:func:`consolidation_pressure`) equals the layer's ``p0_ini``.
    Raises :class:`InvalidArgument` if the layer yields under ``sigma_n`` alone.
    """
    def p0_of(tau):
        _, _, p, q = elastic_shear_state(mat, sigma_n, tau)
        return float(consolidation_pressure(p, q, mat.M, mat.beta))

    p0 = mat.p0_ini
    if p0_of(0.0) >= p0:
        raise InvalidArgument("sigma_n", sigma_n, f"a normal stress the intact layer carries (its oedometric "
                                                  f"strength is {compressive_strength(mat):.4g} Pa)")
    lo, hi = 0.0, mat.M * p0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if p0_of(mid) < p0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    return 0.5 * (lo + hi)


def bond_pressure_for_shear_strength(tau_p: float, sigma_n: float, E: float, nu: float, M: float, beta: float,
                                     p0_int: float) -> float:
    """``p_bond`` (Pa) whose intact layer first yields at ``tau_p`` under ``sigma_n`` (both Pa).

    ``p0_ini`` is the ellipse through the elastic state (:func:`elastic_shear_state`),
    ``p_bond = p0_ini - p0_int`` with ``p0_int`` the intrinsic part (Pa).
    """
    probe = BondedCamClay(E, nu, 1.0, M=M, beta=beta)
    _, _, p, q = elastic_shear_state(probe, sigma_n, tau_p)
    return float(consolidation_pressure(p, q, M, beta)) - p0_int


def xi_for_collapse(collapse: float, sigma_n: float, M: float, K: float, p0_int_ini: float) -> float:
    """Hardening factor ``xi`` that makes the debonded layer collapse by ``collapse`` under ``sigma_n``.

    ``xi = (asinh(p0_f/K) - asinh(p0_int_ini/K)) / (-ln(1 - collapse))`` with ``p0_f``
    the final oedometric consolidation pressure (:func:`mpm_warp.camclay_forms.oedometric_p0`); Pa for
    stresses, ``collapse`` in (0, 1).
    """
    p0_f = float(oedometric_p0(collapse, sigma_n, M, 0.0, K))
    if p0_f <= p0_int_ini:
        raise InvalidArgument("p0_int_ini", p0_int_ini, f"a number below the final consolidation pressure "
                                                        f"{p0_f:.4g} Pa (else the debonded layer does not collapse)")
    return (math.asinh(p0_f / K) - math.asinh(p0_int_ini / K)) / -math.log1p(-collapse)


def oedometric_collapse(mat: BondedCamClay, sigma_n: float) -> float:
    """Collapse ``1 - J_P/J_P(0)`` of the debonded layer (cohesion 0) at rest under ``sigma_n`` (Pa), uniaxial
    strain: :func:`mpm_warp.camclay_forms.oedometric_collapse`; the inverse of :func:`xi_for_collapse`."""
    return float(confined_collapse(sigma_n, mat.M, 0.0, mat.bulk, mat.xi, mat.p0_int_ini))


def loaded_shear_test(mat: BondedCamClay, sigma_n: float, D_wl: float, gamma_end: float, n_increments: int,
                      dtype: str = "float64", device=None) -> dict:
    """Simple shear of the layer under the held normal stress ``sigma_n`` (Pa), on the material-point driver.

    The first increment applies ``sigma_n`` at ``gamma = 0``; then ``n_increments``
    equal shear increments to ``gamma_end``. Returns the curve (``gamma``,
    ``tau`` = Cauchy ``sigma_xy`` (Pa), ``slip`` = plastic slip (m), ``bond``,
    ``collapse`` = ``1 - J_P/J_P(0)``, ``log_jp``, ``kappa``, ``lambda_y``, ``p``, ``q``)
    and the measures of the module docstring: ``tau_peak``, ``tau_yield`` (the
    last elastic increment's stress, a lower bound of the first-yield stress),
    ``tau_r``, ``delta_s`` (m), ``w_f`` (J/m^2), ``bond_before_loss`` (the bond of the
    last increment before ``b = 0``: the remaining bond that the collapse
    removed), ``max_bond_drop`` (largest drop of ``b`` in one increment before
    that), ``lost`` (False if the bond survived ``gamma_end``), and the indices
    into the curve of the first plastic increment (``first_yield_index``) and of
    the first without bond (``loss_index``).
    """
    n = int(n_increments)
    if n < 2:
        raise InvalidArgument("n_increments", n_increments, "an integer >= 2")
    gamma = np.concatenate([[0.0], np.linspace(0.0, gamma_end, n + 1)[1:]])
    r = drive_layer(mat, simple_shear_path(gamma), np.full(len(gamma), -float(sigma_n)), dtype=dtype, device=device)
    s = r["stress"][0].astype(np.float64)
    FE = r["F_E"][0].astype(np.float64)
    tau = s[1:, 0, 1]
    gam = gamma
    # elastic shear strain: 2 (ln V_E)_xy, V_E the left stretch of F_E
    w, V = np.linalg.eigh(np.einsum("kij,klj->kil", FE[1:], FE[1:]))
    eps_e = np.einsum("kij,kj,klj->kil", V, 0.5 * np.log(w), V)
    slip = D_wl * (gam - 2.0 * eps_e[:, 0, 1])
    bond = r["bond"][0, 1:].astype(np.float64)
    ljp = r["log_jp"][0, 1:].astype(np.float64)
    yielded = r["yielded"][0, 1:]
    first = int(np.argmax(yielded != 0)) if np.any(yielded != 0) else len(tau)
    gone = np.flatnonzero(bond <= 0.0)
    lost = len(gone) > 0
    end = int(gone[0]) if lost else len(tau) - 1
    ipk = int(np.argmax(tau))
    tau_r = float(np.min(tau[ipk:]))
    seg = slice(max(first - 1, 0), end + 1)
    excess, ds = tau[seg] - tau_r, np.diff(slip[seg])
    w_f = float(np.sum(0.5 * (excess[1:] + excess[:-1]) * ds)) if lost else float("nan")  # trapezoid rule
    drops = -np.diff(bond[: end]) if end > 1 else np.zeros(1)
    return {
        "gamma": gam, "tau": tau, "slip": slip, "bond": bond, "log_jp": ljp, "kappa": r["kappa"][0, 1:],
        "collapse": 1.0 - np.exp(ljp - mat.initial_log_jp), "lambda_y": r["F"][0, 1:, 1, 1], "p": r["p"][0, 1:],
        "q": r["q"][0, 1:], "yielded": yielded,
        "tau_peak": float(tau[ipk]), "tau_yield": float(tau[first - 1]) if first > 0 else float("nan"),
        "tau_r": tau_r, "delta_s": float(slip[end] - slip[max(first - 1, 0)]) if lost else float("nan"),
        "w_f": w_f, "bond_before_loss": float(bond[end - 1]) if lost and end > 0 else float("nan"),
        "max_bond_drop": float(drops.max()) if len(drops) else 0.0, "lost": lost,
        "first_yield_index": first, "loss_index": end,
    }
