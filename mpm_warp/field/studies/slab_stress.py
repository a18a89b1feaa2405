"""A field run's slab stress over strength frame by frame, its crack's onset, and weac's at the same cuts.

:func:`run_series` runs a scenario with the particles' stress stored at every frame and reads each slab layer's
largest in-plane principal stress over its tensile strength; :func:`onset_cut` is the blade's position when the
damage front first leads it by :data:`ONSET_CELLS` cells; :func:`stress_row` is one finished field case run
again that way (its checkpoint's scenario, the laminate closure switched if asked), beside weac's beam.
:func:`control_params` is the homogeneous control column both slab studies solve.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time

import numpy as np

from .slab_fe import weac_ratios

__all__ = ["ONSET_CELLS", "control_params", "principal_2d", "run_series", "onset_cut", "mpm_ratio_to",
           "weac_at", "stress_row"]

#: the crack has started once the damage front leads the blade by this many grid cells
ONSET_CELLS = 2.0


def control_params():
    """The control: a homogeneous soft slab (20 cm of 120 kg/m^3, E and strength from density) on flat ground, a
    2 m column sawn at 1 m/s from the upslope end to 0.36 m (weac's critical cut 0.40 m)."""
    from ...scenes.pst import PSTParams
    from ...scenes.pst.saw import Saw
    from ...scenes.snowpack import SnowLayer

    p = PSTParams(length=2.0, slab_layers=(SnowLayer(0.2, 120.0),), slab_fracture=True,
                  saw=Saw(cut_length=0.36, speed=1.0))
    return dataclasses.replace(p, weak_layer=dataclasses.replace(p.weak_layer, tau_p=700.0, h_c=0.006))


def principal_2d(stress: np.ndarray) -> np.ndarray:
    """Largest in-plane principal stress (Pa) of Cauchy stresses ``(n, 3, 3)`` (plane strain: the in-plane block)."""
    a, b, c = stress[:, 0, 0], stress[:, 1, 1], stress[:, 0, 1]
    return 0.5 * (a + b) + np.sqrt(0.25 * (a - b) ** 2 + c * c)


def run_series(scenario, path: str, threads: int) -> dict:
    """Run ``scenario`` with stress frames into ``path``; per frame the blade, the front, each slab layer's peak
    ratio (top to bottom) and where the slab's largest ratio sits: ``peak_at`` = [x0 (m along the column, at
    the start), depth below the slab's surface (m, at the start), sigma_xx (along the bed), sigma_yy (normal to
    it), sigma_xy (Pa)]."""
    import h5py

    from ...runner import run
    from ..protocol import decided

    sc = dataclasses.replace(scenario, output=dataclasses.replace(scenario.output, fields=("x", "stress")))
    t0 = time.perf_counter()
    res = run(sc, path, device="cpu", overwrite=True, n_threads=threads, callback=lambda sim, frame: not decided(sim))
    wall = time.perf_counter() - t0
    slabs = sorted((n for n in sc.materials if n.startswith("slab")),     # "slab", or "slab_1" (top) to "slab_N"
                   key=lambda n: int(n.rsplit("_", 1)[-1]) if "_" in n else 0)
    with h5py.File(path, "r") as f:
        groups = [g["name"] if isinstance(g, dict) else g for g in json.loads(f.attrs["groups"])]
        member, x0 = f["static/group"][:], f["static/x0"][:]
        slab = np.isin(member, [groups.index(n) for n in slabs])
        strength = np.zeros(member.size)
        for name in slabs:
            strength[member == groups.index(name)] = sc.materials[name].tensile_strength
        top = x0[slab, 1].max()
        ratio = np.empty((f["time"].shape[0], len(slabs)))
        peak_at = []
        for k in range(ratio.shape[0]):
            stress = f["particles/stress"][k]
            s1 = principal_2d(stress)
            for j, name in enumerate(slabs):
                ratio[k, j] = s1[member == groups.index(name)].max() / sc.materials[name].tensile_strength
            i = np.flatnonzero(slab)[np.argmax(s1[slab] / strength[slab])]
            sig = stress[i]
            peak_at.append([float(x0[i, 0]), float(top - x0[i, 1]), float(sig[0, 0]), float(sig[1, 1]),
                            float(sig[0, 1])])
        series = {"t": f["time"][:].tolist(), "saw": f["scalars/saw"][:].tolist(),
                  "front": f["scalars/front"][:].tolist(), "ratio": ratio.tolist(), "peak_at": peak_at}
    o = res.scene_result.get("outcome", {})
    return {"series": series, "layers": slabs, "predicted": o.get("class"), "wall_s": wall}


def onset_cut(series: dict, dx: float) -> float | None:
    """The blade's position (m) at the first frame the damage front leads it by :data:`ONSET_CELLS` cells."""
    for saw, front in zip(series["saw"], series["front"], strict=True):
        if front - saw >= ONSET_CELLS * dx:
            return float(saw)
    return None


def mpm_ratio_to(series: dict, cut: float) -> float | None:
    """The run's largest slab stress over strength (any layer) while the blade had cut at most ``cut`` (m)."""
    r = [max(row) for saw, row in zip(series["saw"], series["ratio"], strict=True) if saw <= cut + 1e-9]
    return max(r) if r else None


def weac_at(params, cut: float) -> dict:
    """weac's static slab stress over strength of the column ``params`` at ``cut`` (m): :func:`.slab_fe.weac_ratios`."""
    from ...scenes.pst.static import static_column

    return weac_ratios(static_column(params), [ly.strength for ly in params.slab_stack()], cut)


def stress_row(rec: dict, run_dir: str, tmp: str, threads: int, closure: bool | None = None) -> dict:
    """The finished case ``rec`` of ``run_dir`` run again from its checkpoint's scenario into ``tmp`` with stress
    frames (``closure``: the laminate closure on or off, None as it ran): its slab's stress over strength per
    layer and frame (``series``), its onset, and weac's at the recorded cut and at the onset."""
    from ...config import TimeControl
    from ...scenes.pst import build
    from ..run_on import scenario_of

    sc = scenario_of(run_dir, rec["id"])
    if closure is not None and closure != sc.scene.interface_closure:      # the same column, the closure switched
        sc = build(dataclasses.replace(sc.scene, interface_closure=closure),
                   TimeControl(end=sc.time.end, frame_interval=sc.time.frame_interval), name="field")
    p = sc.scene
    out = run_series(sc, os.path.join(tmp, rec["id"] + ".h5"), threads)
    s, onset = out["series"], onset_cut(out["series"], p.dx)
    layers = [{"thickness_m": ly.thickness, "density": ly.density, "cells": ly.thickness / p.dx,
               "tensile_strength": ly.strength, "peak_ratio": max(row[j] for row in s["ratio"])}
              for j, ly in enumerate(p.slab_stack())]
    peak_frame = int(np.argmax([max(row) for row in s["ratio"]]))
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "predicted_batch": rec["predicted"],
            "peak_at": s["peak_at"][peak_frame],
            "predicted": out["predicted"], "interface_closure": p.interface_closure,
            "slope_deg": p.slope_angle, "dx": p.dx, "slab_depth_m": p.slab_depth,
            "recorded_cut": rec["recorded_cut"],
            "onset_cut": onset, "runaway_cut": rec.get("runaway_cut"), "layers": layers,
            "mpm_peak_ratio": max(max(row) for row in s["ratio"]),
            "mpm_ratio_to_recorded_cut": mpm_ratio_to(s, rec["recorded_cut"]),
            "mpm_ratio_to_onset": mpm_ratio_to(s, onset) if onset is not None else None,
            "weac_at_recorded_cut": weac_at(p, rec["recorded_cut"]),
            "weac_at_onset": weac_at(p, onset) if onset else None,
            "wall_s": out["wall_s"], "series": s}
