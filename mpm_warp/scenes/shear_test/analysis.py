"""Results of a shear test from its frame series (pure NumPy): peak, residual, softening, collapse (SI Note 2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...materials import hardening_collapse
from .params import ShearTestParams

__all__ = ["ShearSummary", "shear_summary", "shear_curves", "analyze_shear_series"]


def shear_curves(params: ShearTestParams, times, series: dict) -> dict[str, np.ndarray]:
    """Curves of the pushing phase: ``u`` (m, the block's shear displacement), ``slip`` (m, the layer's own),
    ``gamma`` (slip over ``D_wl``), ``tau`` (Pa), ``q`` (Pa), ``axial`` (-), ``bond`` (-), ``bond_interior``
    (-; the whole layer's for a series without it), ``t`` (s).

    Displacements are taken relative to the state when the push starts; ``axial`` is the thickness loss
    over ``D_wl`` (positive = compaction).
    """
    t = np.asarray(times, dtype=float)
    i0 = min(int(np.searchsorted(t, params.push_start - 1e-12)), len(t) - 1)
    d_wl = float(params.weak_layer_thickness)

    def part(name, default=0.0):
        return np.asarray(series.get(name, np.full(len(t), default)), dtype=float)[i0:]

    u, v, slip = part("shear_displacement"), part("normal_displacement"), part("layer_slip")
    u, slip = u - u[0], slip - slip[0]
    bond = part("bond", 1.0)
    return {"t": t[i0:], "u": u, "slip": slip, "gamma": slip / d_wl, "tau": part("shear_stress"),
            "q": part("mises_q"), "axial": -(v - v[0]) / d_wl, "bond": bond,
            "bond_interior": part("bond_interior") if "bond_interior" in series else bond}


def analyze_shear_series(params: ShearTestParams, calibration, times, series: dict) -> dict:
    """Peak and residual strength, softening displacement and collapse of a shear test, with references.

    On the layer's slip (:func:`shear_curves`): the peak and the residual of :func:`shear_summary`
    (``interior_peak_shear_stress``: the largest mean ``sigma_xy`` of the layer's interior, Pa); the
    softening displacement ``delta_s`` is the slip from the peak to the loss of the bond (the mean bond of the
    layer's interior, at least ``D_wl`` from the sample's ends, at zero: the end of the strength drop, before
    the collapse and the frictional residual); the same on the block's displacement (``plate_``) for comparison
    with the loading-plate measurement of a shear test, and ``softening_displacement_whole_layer`` to the whole
    layer's bond at zero, which waits for the traction-free ends: it grows as dx falls (3, 6, 12, 24 cells:
    2.13, 2.17, 2.26, 2.45 mm) because the last column to debond sits ever closer to an end. The collapse is
    given beside two laws: ``collapse_fraction_law`` (oedometric, the debonded layer under the slab at rest) and
    ``collapse_fraction_critical_state`` (the debonded, cohesionless layer at the critical state of its final
    mean Kirchhoff pressure ``p_final``: ``p0 = 2 p``; a sheared layer compacts more, docs/model.md §3b).
    The final pressure does not bound the collapse: once the bond is gone the load falls into the layer, its
    mean pressure overshoots (about 1.7 ``p_final`` on the default scene) while it compacts, then unloads
    elastically, and the compaction stays. So the law is also given at the largest mean pressure of the
    push, ``p_max`` (Pa): ``collapse_fraction_isotropic_at_p_max`` (``p0 = p_max``, the cap's end) and
    ``collapse_fraction_critical_state_at_p_max`` (``p0 = 2 p_max``); the layer's collapse lies between them.
    The calibrated layer's predictions (``calibration``, the scenario's stored
    :class:`~mpm_warp.scenes.weak_layer.CalibratedWeakLayer`; :meth:`ShearTestParams.references`) are copied in.
    """
    c = shear_curves(params, times, series)
    if len(c["u"]) < 3:
        return {}
    sm = shear_summary(c["slip"], c["tau"], c["axial"])
    after_peak = np.arange(len(c["bond"])) > sm.peak_index
    lost_all = np.nonzero(after_peak & (c["bond"] <= 0.0))[0]
    lost = np.nonzero(after_peak & (c["bond_interior"] <= 0.0))[0]
    k = int(lost[0]) if len(lost) else -1
    k_all = int(lost_all[0]) if len(lost_all) else -1
    ip = sm.peak_index
    refs = params.references(calibration)
    mat = calibration.material
    p_end = float(np.asarray(series.get("p_kirchhoff", [math.nan]), dtype=float)[-1])
    # the debonded layer (cohesion beta b = 0) at the critical state: p0 = 2 p, p the Kirchhoff pressure
    cs = hardening_collapse(2.0 * p_end, mat.bulk, mat.xi, mat.p0_int_ini) \
        if np.isfinite(p_end) and p_end > 0 else math.nan
    pushed = np.asarray(times, dtype=float) >= params.push_start - 1e-12
    p_series = np.asarray(series.get("p_kirchhoff", []), dtype=float)
    p_max = float(np.max(p_series[pushed])) if len(p_series) == len(pushed) and pushed.any() else math.nan

    def law(p0):
        return float(hardening_collapse(p0, mat.bulk, mat.xi, mat.p0_int_ini)) \
            if np.isfinite(p0) and p0 > 0 else math.nan
    interior = np.asarray(series.get("interior_shear_stress", []), dtype=float)
    interior = interior[pushed] if len(interior) == len(pushed) else np.array([math.nan])  # absent, or resumed
    return {"peak_shear_stress": sm.peak_stress, "residual_shear_stress": sm.residual_stress,
            "interior_peak_shear_stress": float(np.max(interior)) if np.all(np.isfinite(interior)) else math.nan,
            "peak_slip": float(c["slip"][ip]),
            "softening_displacement": float(c["slip"][k] - c["slip"][ip]) if k >= 0 else math.nan,
            "softening_displacement_whole_layer":
                float(c["slip"][k_all] - c["slip"][ip]) if k_all >= 0 else math.nan,
            "plate_softening_displacement": float(c["u"][k] - c["u"][ip]) if k >= 0 else math.nan,
            "bond_lost": k >= 0, "collapse_fraction": sm.collapse_fraction,
            "collapse_fraction_critical_state": float(cs), "p_final": p_end, "peak_q": float(np.max(c["q"])),
            "p_max": p_max, "collapse_fraction_isotropic_at_p_max": law(p_max),
            "collapse_fraction_critical_state_at_p_max": law(2.0 * p_max),
            **{f"{key}_calibrated" if key in ("delta_s", "w_f", "tau_p", "tau_peak") else key: float(v)
               for key, v in refs.items()}}


@dataclass(frozen=True)
class ShearSummary:
    """Shear test results (SI Note 2).

    Attributes
    ----------
    peak_stress, residual_stress : float
        Peak (intact) and residual shear stress (Pa). The peak is the maximum before the
        stress first falls below half of its running maximum (the failure); the residual
        may exceed it when the collapsed layer hardens.
    peak_displacement : float
        Shear displacement at the peak (m).
    softening_displacement : float
        Critical sliding displacement (m): from the peak to the end of the softening
        zone, the first point where the stress is within ``(1 - drop) max(peak - residual,
        residual - minimum)`` of the residual, searched after the post-peak minimum when
        the stress undershoots the residual (the layer slides at a low stress while it
        collapses, then recovers to the residual friction); nan if never.
    drop_displacement : float
        Displacement (m) from the peak to the first point where the stress has fallen
        by ``drop`` of ``peak - residual`` (how abrupt the loss of strength is); nan if never.
    collapse_fraction : float
        Final weak-layer thickness change over its thickness (-), positive for compaction.
    peak_index, softened_index : int
        Sample indices of the peak and of the end of softening (-1 if none).
    """

    peak_stress: float
    residual_stress: float
    peak_displacement: float
    softening_displacement: float
    drop_displacement: float
    collapse_fraction: float
    peak_index: int
    softened_index: int


def _crossing(u, tau, ip: int, cond) -> tuple[int, float]:
    """First index after ``ip`` where ``cond(tau)`` holds and the displacement from the peak there."""
    idx = np.nonzero((np.arange(len(u)) > ip) & cond(tau))[0]
    if idx.size == 0:
        return -1, math.nan
    j = int(idx[0])
    return j, float(u[j] - u[ip])


def shear_summary(u, tau, axial, residual_window: float = 0.2, drop: float = 0.9) -> ShearSummary:
    """Peak, residual, softening displacement and collapse from shear-test curves.

    Parameters
    ----------
    u : array
        Shear (sliding) displacement of the loaded top relative to the base (m), increasing.
    tau : array
        Shear stress (Pa).
    axial : array
        Weak-layer thickness change over its thickness (-), positive for compaction.
    residual_window : float
        The residual stress is the mean over the last ``residual_window`` of the displacement range.
    drop : float
        Fraction of ``peak - residual`` defining the end of the stress drop and, as its
        complement, the band around the residual that ends the softening zone.
    """
    u = np.asarray(u, dtype=float)
    tau = np.asarray(tau, dtype=float)
    axial = np.asarray(axial, dtype=float)
    # the peak is the intact layer's strength: the maximum before the first failure, i.e. before
    # the stress first falls below half its running maximum (a collapsed layer may later harden
    # to a frictional strength above it); without such a drop, the global maximum
    run_max = np.maximum.accumulate(tau)
    fail = np.nonzero((run_max > 0) & (tau < 0.5 * run_max))[0]
    ip = int(np.argmax(tau[: fail[0]])) if fail.size else int(np.argmax(tau))
    tp = float(tau[ip])
    u_end = float(u[-1])
    tail = u >= u_end - residual_window * (u_end - float(u[0]))
    tail &= np.arange(len(u)) > ip
    tr = float(np.mean(tau[tail])) if tail.any() else float(tau[-1])
    delta = tp - tr
    if ip + 1 < len(tau) and (delta > 0 or float(np.min(tau[ip + 1:])) < 0.5 * tp):
        lowest = min(tr, float(np.min(tau[ip + 1:])))
        _, d_drop = _crossing(u, tau, ip, lambda x: x <= tp - drop * (tp - lowest))
        jmin = ip + 1 + int(np.argmin(tau[ip + 1:]))
        band = (1.0 - drop) * max(delta, tr - float(tau[jmin]))
        start = jmin if tau[jmin] < tr - band else ip
        js, _ = _crossing(u, tau, start, lambda x: np.abs(x - tr) <= band)
        d_soft = float(u[js] - u[ip]) if js >= 0 else math.nan
    else:
        d_drop, js, d_soft = math.nan, -1, math.nan
    return ShearSummary(tp, tr, float(u[ip]), d_soft, d_drop, float(axial[-1]), ip, js)
