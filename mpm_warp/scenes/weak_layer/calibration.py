"""Weak-layer parameters from what snow scientists measure, converted in one place (docs/model.md §3b).

:func:`weak_layer_material` checks the field quantities (slab load, shear strength or bond pressure,
fracture energy or softening slip, collapse height or xi), turns the strength and the collapse into
``p_bond`` and ``xi`` by closed forms (:mod:`.paths`), fits ``kappa_s`` on the material-point shear test
(:mod:`.fit`) and adds the predictions the scenes compare with (:class:`~.record.CalibratedWeakLayer`).
A scene runs it once when it is built and stores the result with the scenario
(:func:`stored_calibration` reads it back).
"""

from __future__ import annotations

import math

from ...checks import finite_number
from ...errors import InvalidArgument
from ...materials import BondedCamClay
from ..references import critical_cut_length_formula, heierli_speed, heierli_touchdown, weac_collapse_height
from ..snow import slab_normal_stress
from .fit import CALIBRATION_RTOL, fit_kappa_s, shear_range
from .paths import (
    bond_pressure_for_shear_strength,
    compressive_strength,
    elastic_shear_state,
    oedometric_collapse,
    shear_strength,
    xi_for_collapse,
)
from .record import CalibratedWeakLayer

__all__ = ["CalibratedWeakLayer", "stored_calibration", "weak_layer_material", "weac_collapse_height",
           "heierli_anticrack", "shear_range", "CALIBRATION_RTOL", "least_shear_strength", "carries_slab"]


def heierli_anticrack(slab_E: float, slab_thickness: float, slab_density: float, h_c: float) -> tuple[float, float]:
    """Heierli (2005) steady anticrack ``(speed, touchdown)`` (m/s, m) of a slab on a layer collapsing by ``h_c``
    (m): :func:`~mpm_warp.scenes.references.heierli_speed` and :func:`~mpm_warp.scenes.references.heierli_touchdown`.
    Example of docs/model.md §6: 5 MPa, 0.5 m, 200 kg/m^3, 2 mm give 33.6 m/s and 1.58 m."""
    return (heierli_speed(slab_E, slab_thickness, slab_density, h_c),
            heierli_touchdown(slab_E, slab_thickness, slab_density, h_c))


def stored_calibration(scenario) -> CalibratedWeakLayer:
    """The weak layer's calibration a snow scene's builder stored in ``scenario.calibration`` (never rerun)."""
    stored = (scenario.calibration or {}).get("weak_layer")
    if stored is None:
        raise InvalidArgument("scenario.calibration", scenario.calibration,
                              "the weak layer's calibration stored by the scene's builder (build the scenario with "
                              "mpm_warp.scenes.pst.build or the loader)")
    return CalibratedWeakLayer.from_dict(stored)


def _exactly_one(a_name, a, b_name, b):
    if (a is None) == (b is None):
        raise InvalidArgument(f"{a_name}/{b_name}", (a, b), f"exactly one of {a_name} and {b_name}")


def weak_layer_material(*, E: float, nu: float, density: float, D_wl: float, M: float = 1.2, beta: float = 0.3,
                        sigma_n: float | None = None, slab_density: float | None = None,
                        slab_thickness: float | None = None, slope_angle: float = 0.0,
                        tau_p: float | None = None, p_bond: float | None = None,
                        w_f: float | None = None, delta_s: float | None = None,
                        h_c: float | None = None, xi: float | None = None,
                        p0_int_ini: float = 0.0, p0_floor_ratio: float = 1e-5,
                        slab_E: float | None = None, slab_nu: float | None = None) -> CalibratedWeakLayer:
    """Calibrate a bonded Cam-Clay weak layer from field measurements (module docstring).

    Parameters
    ----------
    E, nu, density : float
        Weak-layer elasticity (Pa, -) and density (kg/m^3).
    D_wl : float
        Weak-layer thickness (m), > 0.
    M, beta : float
        Critical-state slope (-) and cohesion ratio (-, in [0, 1]).
    sigma_n : float, optional
        Slab normal stress on the layer (Pa, > 0); or give ``slab_density`` (kg/m^3)
        and ``slab_thickness`` (m), with ``slope_angle`` (deg, in [0, 60]).
    tau_p, p_bond : float
        Exactly one: shear strength under ``sigma_n`` (Pa), or bond pressure (Pa).
    w_f, delta_s : float
        Exactly one: fracture energy (J/m^2), or softening slip (m).
    h_c, xi : float, optional
        At most one: collapse height (m, < D_wl) or hardening factor (-); default
        ``h_c`` = :func:`weac_collapse_height`.
    p0_int_ini : float
        Intrinsic consolidation pressure of the intact layer (Pa, >= 0; 0: loose skeleton).
    p0_floor_ratio : float
        Floor of ``p0_int`` relative to K (-).
    slab_E, slab_nu : float, optional
        Slab elasticity (Pa, -), for the predictions only: the critical cut length
        (needs ``slab_density``) and Heierli's anticrack (needs ``slab_density`` and
        ``slab_thickness``).

    Returns
    -------
    CalibratedWeakLayer

    Raises
    ------
    InvalidArgument
        Naming the field: a value out of range, both or neither of a pair, a
        strength the slab would already break (``tau_p`` below the debonded
        skeleton's, an oedometric strength below ``sigma_n``, or a first yield on
        the compaction side of the critical state: the slab nearly crushes the
        layer), a collapse the intrinsic consolidation forbids, a ``w_f`` or
        ``delta_s`` the shear test cannot reach.
    """
    given, sigma_n, tau_slope = _check(locals())
    mat0, xi, p_bond, tau_first, sigma_c = _closed_forms(given, E=E, nu=nu, density=density, D_wl=D_wl, M=M,
                                                         beta=beta, sigma_n=sigma_n, h_c=h_c, xi=xi, tau_p=tau_p,
                                                         p_bond=p_bond, p0_int_ini=p0_int_ini,
                                                         p0_floor_ratio=p0_floor_ratio)
    key = "w_f" if w_f is not None else "delta_s"
    given[key] = finite_number(key, w_f if w_f is not None else delta_s, lo=0.0, lo_open=True)
    mat, r, info = fit_kappa_s(mat0, sigma_n, D_wl, key, given[key], tau_first)
    h_c_out = oedometric_collapse(mat, sigma_n) * D_wl
    return CalibratedWeakLayer(
        material=mat, D_wl=D_wl, sigma_n=sigma_n, tau_slope=tau_slope, given=given, tau_p=tau_first,
        w_f=r["w_f"], delta_s=r["delta_s"], h_c=h_c_out, p_bond=p_bond, kappa_s=mat.kappa_s, xi=xi,
        tau_peak=r["tau_peak"], tau_residual=r["tau_r"], bond_at_collapse=r["bond_before_loss"],
        compressive_strength=sigma_c, calibration=info,
        **_predictions(tau_first, mat, D_wl, h_c_out, slab_E, slab_nu, slab_density, slab_thickness))


def _check(a: dict) -> tuple[dict, float, float]:
    """Check the inputs of :func:`weak_layer_material` (its arguments ``a``); return what was given and the load
    ``(sigma_n, tau_slope)`` (Pa): the slab's normal and bed-parallel stress."""
    f = finite_number
    f("E", a["E"], lo=0.0, lo_open=True)
    f("nu", a["nu"], lo=0.0, hi=0.5, hi_open=True)
    f("density", a["density"], lo=0.0, lo_open=True)
    f("D_wl", a["D_wl"], lo=0.0, lo_open=True)
    f("M", a["M"], lo=0.0, lo_open=True)
    f("beta", a["beta"], lo=0.0, hi=1.0)
    f("p0_int_ini", a["p0_int_ini"], lo=0.0)
    f("p0_floor_ratio", a["p0_floor_ratio"], lo=0.0, hi=1e-2, lo_open=True)
    theta = f("slope_angle", a["slope_angle"], lo=0.0, hi=60.0)
    given = {}
    if a["sigma_n"] is None:
        if a["slab_density"] is None or a["slab_thickness"] is None:
            raise InvalidArgument("sigma_n", None, "a slab normal stress, or slab_density and slab_thickness")
        rho = f("slab_density", a["slab_density"], lo=0.0, lo_open=True)
        h = f("slab_thickness", a["slab_thickness"], lo=0.0, lo_open=True)
        sigma_n = slab_normal_stress(rho, h, theta)
        tau_slope = sigma_n * math.tan(math.radians(theta))
        given.update(slab_density=a["slab_density"], slab_thickness=a["slab_thickness"], slope_angle=a["slope_angle"])
    else:
        sigma_n = f("sigma_n", a["sigma_n"], lo=0.0, lo_open=True)
        tau_slope = 0.0
        given["sigma_n"] = sigma_n
    _exactly_one("tau_p", a["tau_p"], "p_bond", a["p_bond"])
    _exactly_one("w_f", a["w_f"], "delta_s", a["delta_s"])
    if a["h_c"] is not None and a["xi"] is not None:
        raise InvalidArgument("h_c/xi", (a["h_c"], a["xi"]), "at most one of h_c and xi")
    return given, sigma_n, tau_slope


def _closed_forms(given: dict, *, E, nu, density, D_wl, M, beta, sigma_n, h_c, xi, tau_p, p_bond, p0_int_ini,
                  p0_floor_ratio):
    """The parameters with a closed form: ``xi`` from the collapse, ``p_bond`` from the strength; then the intact
    layer's checks (it carries the slab, and fails in shear). Returns ``(material without kappa_s, xi, p_bond,
    tau_p, compressive strength)``."""
    f = finite_number
    probe = BondedCamClay(E, nu, density, M=M, beta=beta, p0_int_ini=p0_int_ini, p0_floor_ratio=p0_floor_ratio)
    if xi is None:                           # collapse -> xi
        if h_c is None:
            h_c = weac_collapse_height(D_wl)
        else:
            given["h_c"] = h_c
        f("h_c", h_c, lo=0.0, hi=D_wl, lo_open=True, hi_open=True)
        xi = xi_for_collapse(h_c / D_wl, sigma_n, M, probe.bulk, p0_int_ini)
    else:
        given["xi"] = f("xi", xi, lo=0.0, lo_open=True)
    if p_bond is None:                       # strength -> p_bond
        given["tau_p"] = f("tau_p", tau_p, lo=0.0, lo_open=True)
        p_bond = bond_pressure_for_shear_strength(tau_p, sigma_n, E, nu, M, beta, max(p0_int_ini, probe.p0_floor))
        if p_bond < 0.0:
            raise InvalidArgument("tau_p", tau_p, f"a strength above that of the debonded skeleton under "
                                                  f"sigma_n = {sigma_n:.4g} Pa")
    else:
        given["p_bond"] = f("p_bond", p_bond, lo=0.0)
    mat0 = BondedCamClay(E, nu, density, M=M, beta=beta, xi=xi, p0_int_ini=p0_int_ini, p0_floor_ratio=p0_floor_ratio,
                         p_bond=p_bond, kappa_s=math.inf)
    strength = ("tau_p", tau_p) if "tau_p" in given else ("p_bond", p_bond)
    sigma_c = compressive_strength(mat0)
    if sigma_c <= sigma_n:
        raise InvalidArgument(*strength, f"a strength at which the intact layer carries the slab (its oedometric "
                                         f"strength {sigma_c:.4g} Pa is below sigma_n = {sigma_n:.4g} Pa)")
    tau_first = shear_strength(mat0, sigma_n)
    # a shear failure: the first-yield state on the dilatant side of the apex, so that the bond softens from the
    # peak on; on the compaction side the slab nearly crushes the layer and the shear test hardens first
    if elastic_shear_state(mat0, sigma_n, tau_first)[2] >= 0.5 * mat0.p0_ini * (1.0 - beta):
        raise InvalidArgument(*strength, f"a strength at which the layer fails in shear under sigma_n = "
                                         f"{sigma_n:.4g} Pa (here it yields in compaction: tau_p = {tau_first:.4g} "
                                         f"Pa, oedometric strength {sigma_c:.4g} Pa); raise it")
    return mat0, xi, p_bond, tau_first, sigma_c


def carries_slab(tau_p: float, *, E: float, nu: float, density: float, D_wl: float, M: float, beta: float,
                 sigma_n: float, h_c: float | None = None, p0_int_ini: float = 0.0,
                 p0_floor_ratio: float = 1e-5) -> bool:
    """Whether a layer of shear strength ``tau_p`` (Pa; the other quantities as :func:`weak_layer_material`) carries
    the slab's ``sigma_n`` (Pa) intact and fails in shear: the closed forms alone, no shear-test run."""
    try:
        _closed_forms({}, E=E, nu=nu, density=density, D_wl=D_wl, M=M, beta=beta, sigma_n=sigma_n, h_c=h_c,
                      xi=None, tau_p=tau_p, p_bond=None, p0_int_ini=p0_int_ini, p0_floor_ratio=p0_floor_ratio)
    except InvalidArgument:
        return False
    return True


def least_shear_strength(lo: float = 0.0, tau_max: float = 1.0e5, **layer) -> float | None:
    """The least shear strength (Pa) above ``lo`` at which the layer ``layer`` (the keywords of :func:`carries_slab`)
    carries its slab and fails in shear, to 0.1 %; None when none up to ``tau_max`` does.

    Below it the layer yields in compaction (the slab would crush it), so a layer observed intact under that slab
    is at least this strong. The bracket grows from ``lo`` by doubling, then bisects.
    """
    hi = max(2.0 * lo, 1.0)
    while not carries_slab(hi, **layer):
        lo, hi = hi, 2.0 * hi
        if hi > tau_max:
            return None
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if carries_slab(mid, **layer) else (mid, hi)
    return hi


def _predictions(tau_p, mat, D_wl, h_c, slab_E, slab_nu, slab_density, slab_thickness) -> dict:
    """The closed-form predictions of the scenes: Gaume et al. (2017)'s critical cut and Heierli's anticrack."""
    f = finite_number
    out = {"critical_cut": None, "critical_cut_inputs": {}, "heierli_speed": None, "heierli_touchdown": None}
    if slab_E is None or slab_density is None:
        return out
    f("slab_E", slab_E, lo=0.0, lo_open=True)
    f("slab_density", slab_density, lo=0.0, lo_open=True)
    if slab_nu is not None:
        cut_in = {"tau_p": tau_p, "E": slab_E, "nu": f("slab_nu", slab_nu, lo=0.0, hi=0.5, hi_open=True),
                  "D_wl": D_wl, "G_wl": mat.mu, "rho": slab_density}
        out.update(critical_cut=critical_cut_length_formula(**cut_in), critical_cut_inputs=cut_in)
    if slab_thickness is not None:
        h = f("slab_thickness", slab_thickness, lo=0.0, lo_open=True)
        out["heierli_speed"], out["heierli_touchdown"] = heierli_anticrack(slab_E, h, slab_density, h_c)
    return out
