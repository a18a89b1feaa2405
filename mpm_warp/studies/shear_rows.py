"""Where a shear test's sample carries its load at the peak: per particle row and along the sample.

The structural peak of a shear test is the push force over the sample's area at its maximum. A sample
with free ends carries less than its material's strength there: the ends are traction free, so the shear
stress falls to zero over a few layer thicknesses from each end, and they soften first. This module runs
the shear test and, at every frame, reads the weak layer's Cauchy ``sigma_xy`` per particle: along the
sample (the layer's mean over bins of one layer thickness) and per particle row of the interior (at least
one layer thickness from both ends), keeping the frame of the structural peak. The interior's own peak
over time is the strength the material shows away from the ends.
"""

from __future__ import annotations

import time

import numpy as np

from ..loader import load_scenario
from ..runner import run

__all__ = ["shear_rows", "length_fit"]


def shear_rows(cells: float, sample_length: float | None = None, overrides=(), device: str = "cpu") -> dict:
    """Run the shear test at ``cells`` grid cells across the layer and measure its peak's distribution.

    Parameters
    ----------
    cells : float
        Grid cells across the weak layer (dx = D_wl / cells).
    sample_length : float, optional
        Sample length L_s (m); default the scenario's.
    overrides : sequence of str
        Further ``section.key=value`` overrides of the ready scene ``shear_test``.

    Returns
    -------
    dict
        ``cells``, ``dx`` and ``sample_length`` (m), ``tau_p`` (Pa, the calibrated strength),
        ``peak_over_tau_p`` (the structural peak), ``interior_peak_over_tau_p`` (the interior's mean
        ``sigma_xy`` at its own maximum over time), ``rows`` (per interior particle row at the structural peak,
        bottom to top: ``y0`` height above the layer's base (m), ``tau_over_tau_p``), ``along`` (bins of one
        layer thickness along the sample at the structural peak: ``x`` (m, bin centre from the sample's
        start), ``tau_over_tau_p``), ``steps``, ``wall_s``.
    """
    base = load_scenario("shear_test").scene
    d_wl = base.weak_layer_thickness
    over = [f"scene.dx={d_wl / cells!r}", *overrides]
    if sample_length is not None:
        over.append(f"scene.sample_length={sample_length!r}")
    best = {"push": -np.inf}
    interior_peak = [-np.inf]

    def frame(sim, k):
        mon = sim.monitors["shear_test"]
        if sim.time < mon.params.push_start:
            return None
        g = mon.weak.group
        x0 = g.x0
        _, _, sig = sim.stresses(cauchy=True)
        sxy = sig[g.start:g.end, 0, 1].astype(float)
        lo, hi = x0[:, 0].min(), x0[:, 0].max()
        inner = (x0[:, 0] >= lo + d_wl) & (x0[:, 0] <= hi - d_wl)
        interior_peak[0] = max(interior_peak[0], float(sxy[inner].mean()))
        push = mon.series["shear_stress"][-1]
        if push > best["push"]:
            y0 = np.round(x0[:, 1] - x0[:, 1].min(), 9)
            rows = [(float(y), float(sxy[inner & (y0 == y)].mean())) for y in np.unique(y0)]
            edges = np.arange(lo, hi + d_wl, d_wl)
            b = np.clip(np.digitize(x0[:, 0], edges) - 1, 0, len(edges) - 2)
            along = [(float(0.5 * (edges[i] + edges[i + 1]) - lo), float(sxy[b == i].mean()))
                     for i in range(len(edges) - 1) if np.any(b == i)]
            best.update(push=push, t=sim.time, rows=rows, along=along)
        return None

    t0 = time.perf_counter()
    rr = run("shear_test", device=device, overrides=over, callback=frame)
    wall = time.perf_counter() - t0
    res = rr.scene_result
    tau_p = res["tau_p_calibrated"]
    return {"cells": float(cells), "dx": d_wl / cells, "sample_length": rr.monitor.params.sample_length,
            "overrides": list(overrides), "tau_p": tau_p, "peak_shear_stress": res["peak_shear_stress"],
            "peak_over_tau_p": res["peak_shear_stress"] / tau_p,
            "interior_peak_over_tau_p": interior_peak[0] / tau_p, "peak_time": best.get("t"),
            "rows": [{"y0": y, "tau_over_tau_p": s / tau_p} for y, s in best.get("rows", [])],
            "along": [{"x": x, "tau_over_tau_p": s / tau_p} for x, s in best.get("along", [])],
            "steps": int(rr.steps), "wall_s": wall}


def length_fit(lengths, peaks) -> dict:
    """Least-squares fit ``peak = a - b / L`` of structural peaks (over tau_p) against sample lengths L (m).

    The free ends' deficit is a fixed length of unloaded sample, so it falls as ``1 / L``; ``a`` is the
    peak of an endless sample. Returns ``a``, ``b`` (m) and the largest residual.
    """
    L = np.asarray(lengths, dtype=float)
    y = np.asarray(peaks, dtype=float)
    A = np.stack([np.ones_like(L), -1.0 / L], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, y, rcond=None)
    return {"a": float(a), "b": float(b), "max_residual": float(np.max(np.abs(A @ np.array([a, b]) - y)))}
