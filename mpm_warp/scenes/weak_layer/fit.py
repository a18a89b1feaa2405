"""The one calibrated parameter without a closed form: ``kappa_s``, fitted on the material-point shear test.

The debonding layer dilates, then collapses under ``sigma_n`` once its bond cannot carry it, so the
fracture energy ``w_f`` (or the softening slip ``delta_s``) that a ``kappa_s`` gives is measured on the
loaded shear test (:func:`~.paths.loaded_shear_test`, the engine's update) and ``kappa_s`` found by a
secant iteration in ``ln kappa_s`` (docs/model.md §3b). Start: ``D_wl kappa_s = 1.5 w_f`` (the softening
work plus the residual's share), or ``tau_p delta_s``.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ...errors import InvalidArgument
from .paths import loaded_shear_test

__all__ = ["fit_kappa_s", "shear_range", "CALIBRATION_RTOL"]

CALIBRATION_RTOL = 1e-3
"""Relative tolerance of the ``kappa_s`` calibration on ``w_f`` or ``delta_s``."""
_CALIBRATION_INCREMENTS = 800  # shear increments of a calibration run: w_f within ~1e-3 of the converged value
_MAX_CALIBRATION_RUNS = 12
_CALIBRATION_ACCEPT = 1e-2  # relative error accepted when the secant stalls on the increment's resolution
_MAX_LOG_STEP = math.log(10.0)  # a secant step changes kappa_s by at most 10x: a flat stretch cannot throw it out
_K_SPAN = 1e6  # kappa_s stays within 1e6x of its start either way: beyond, the target is out of the test's reach


def shear_range(mat, sigma_n: float, tau: float) -> float:
    """Shear strain (-) a loaded shear test of ``mat`` under ``sigma_n`` (Pa) needs to break the bond: the elastic
    range plus twice the plastic shear that does the debonding work ``kappa_s`` at the shear stress ``tau`` (Pa)."""
    return 1.5 * (sigma_n + mat.p0_ini) / mat.mu + 2.0 * mat.kappa_s / tau


def _measure(mat, sigma_n, D_wl, n, tau):
    """Shear test run long enough for the bond to go (doubling the shear range)."""
    gamma_end = shear_range(mat, sigma_n, tau)
    for _ in range(8):
        r = loaded_shear_test(mat, sigma_n, D_wl, gamma_end, n, device="cpu")  # deterministic on any machine
        if r["lost"] and r["loss_index"] < 0.9 * n:
            return r
        gamma_end *= 2.0
    raise InvalidArgument("kappa_s", mat.kappa_s, "a bond that breaks in the shear test (it never did)")


def fit_kappa_s(mat0, sigma_n: float, D_wl: float, key: str, target: float, tau_first: float):
    """``kappa_s`` (J/m^3) of the layer ``mat0`` (its other parameters set) whose shear test under ``sigma_n`` (Pa)
    returns ``key`` ("w_f", J/m^2, or "delta_s", m) equal to ``target`` within :data:`CALIBRATION_RTOL`.

    Returns
    -------
    (material, run, info)
        The calibrated :class:`~mpm_warp.materials.BondedCamClay`, the last shear test
        (:func:`~.paths.loaded_shear_test`) and ``{"runs", "n_increments", "relative_error", "target"}``.

    Raises
    ------
    InvalidArgument
        A target the shear test cannot reach (after :data:`_MAX_CALIBRATION_RUNS` runs, not within 1 %).
    """
    k = 1.5 * target / D_wl if key == "w_f" else tau_first * target / D_wl
    n = _CALIBRATION_INCREMENTS
    hist, runs = [], []
    while True:
        mat = replace(mat0, kappa_s=k)
        r = _measure(mat, sigma_n, D_wl, n, tau_first)
        if not r[key] > 0.0:
            raise InvalidArgument(key, target, f"a value the shear test can reach (it gives {r[key]:.4g})")
        err = math.log(r[key] / target)
        hist.append((math.log(k), err))
        runs.append((abs(err), k, r))
        if abs(err) <= CALIBRATION_RTOL:
            break
        if len(hist) == _MAX_CALIBRATION_RUNS:
            # the measured slip is resolved to the shear increment (about 0.4 % at 800 increments), so the secant
            # can stall just above the tolerance: keep the best run when it is within the resolution
            err, k, r = min(runs, key=lambda e: e[0])
            if err > _CALIBRATION_ACCEPT:
                e = InvalidArgument(key, target, f"a value the shear test can reach (after {len(hist)} runs it "
                                                 f"gives {r[key]:.4g})")
                e.reached = r[key]
                raise e
            break
        (x0, e0), (x1, e1) = hist[-2] if len(hist) > 1 else hist[-1], hist[-1]
        step = -e1 * (x1 - x0) / (e1 - e0) if e1 != e0 else -e1
        x = x1 + max(-_MAX_LOG_STEP, min(_MAX_LOG_STEP, step))
        if abs(x - hist[0][0]) > math.log(_K_SPAN):
            e = InvalidArgument(key, target, f"a value the shear test can reach (it gives {r[key]:.4g} at the end "
                                             "of its range)")
            e.reached = r[key]
            raise e
        k = math.exp(x)
    info = {"runs": len(hist), "n_increments": n, "relative_error": math.expm1(abs(err)), "target": key}
    return replace(mat0, kappa_s=k), r, info
