"""A PST run at one moment, drawn for a snow scientist: collapse of the weak layer, the slab coming down.

Two panels of one frame (matplotlib, no display needed):

- the whole column, side view: particles at their positions with the displacement since the end of
  settling exaggerated by a stated factor (the slab's deflection is millimetres on a metres-long
  column); the weak layer coloured by its collapse ``1 - J_P/J_P,ref`` since settling
  (:mod:`mpm_warp.post.fields`: the intact, settled layer is 0), the slab and the old snow grey; the
  saw cut, the damage front and the slab-deflection front marked;
- a zoom on the weak layer around the damage front at true displacements, its vertical axis
  stretched (stated): the layer compacting behind the front and the slab base following it.

The frame defaults to the moment the crack runs: the damage front halfway between the cut and the
far end zone (or the last frame when it never got there).
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import InvalidArgument
from ..io import RunData, read_run
from ..scenes.pst import PSTParams
from ..scenes.pst.analysis import end_zone
from .fronts import sawn_params, scene_calibration

__all__ = ["pst_picture", "running_frame"]

#: colormap of the collapse (0 = settled, intact)
CMAP = "viridis"


def running_frame(run: RunData, params: PSTParams) -> int:
    """The frame where the damage front is halfway from the cut to the far end zone (the last frame if never)."""
    front = np.asarray(run.scalars["front"], dtype=float)
    cut = float(params.saw.cut_length)
    goal = cut + 0.5 * (float(params.length) - end_zone(params) - cut)
    k = np.nonzero(front >= goal)[0]
    return int(k[0]) if len(k) else run.n_frames - 1


def _slab_layers(ax, params: PSTParams, groups: list, gid, shown, L: float) -> None:
    """A layered slab: its layers in alternating greys, each labelled with its density and E at the right end."""
    stack = params.slab_stack()
    if len(stack) < 2:
        return
    for k, layer in enumerate(stack):
        sel = gid == groups.index(f"slab_{k + 1}")
        ax.scatter(shown[sel, 0], shown[sel, 1], s=0.3, c="0.62" if k % 2 else "0.8", lw=0, rasterized=True)
        y = float(np.median(shown[sel, 1]))
        ax.text(L + 0.06, y, f"{layer.density:.0f} kg/m3, E {layer.modulus / 1e6:.2g} MPa", fontsize=6, va="center")


def _settled_frame(run: RunData, params: PSTParams) -> int:
    return min(int(np.searchsorted(run.times, params.saw_start - 1e-12)), run.n_frames - 1)


def pst_picture(path, out_png: str, frame: int | None = None, exaggeration: float | None = None) -> str:
    """Draw a PST frame (module docstring) into ``out_png``; return its path.

    Parameters
    ----------
    path : str, os.PathLike or RunData
        A PST run file with the output fields ``x`` and ``log_jp`` (and the monitor's ``log_jp_ref``).
    out_png : str
        Image file to write.
    frame : int, optional
        Frame index (default :func:`running_frame`).
    exaggeration : float, optional
        Factor on the displacements since settling in the column panel (default: the calibrated
        collapse height drawn as a quarter of the slab thickness).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    run = path if isinstance(path, RunData) else read_run(path)
    params = sawn_params(run)               # a saw stopped on runaway: the cut it made
    if not isinstance(params, PSTParams):
        raise InvalidArgument("path", run.path, "a PST run file (scene kind 'pst')")
    missing = [f for f in ("x", "log_jp", "log_jp_ref") if f not in run.particle_fields]
    if missing:
        raise InvalidArgument("path", run.path, f"a PST run with the particle fields {missing} in its output")
    k = running_frame(run, params) if frame is None else int(frame) % run.n_frames
    groups = [g["name"] for g in run.attrs["groups"]]
    gid = run.static["group"]
    wl = gid == groups.index("weak_layer")
    ref = run.frame(_settled_frame(run, params))["x"].astype(float)
    fr = run.frame(k)
    x = fr["x"].astype(float)
    collapse = 1.0 - np.exp(fr["log_jp"][wl].astype(float) - fr["log_jp_ref"][wl].astype(float))
    h_c = scene_calibration(run, params).h_c
    c_max = 1.25 * h_c / params.weak_layer_thickness
    D, L, cut = float(params.slab_depth), float(params.length), float(params.saw.cut_length)
    f = exaggeration if exaggeration is not None else 0.25 * D / h_c
    shown = ref + f * (x - ref)
    t = float(run.times[k])
    front = float(run.scalars["front"][k])
    dfront = float(run.scalars["deflection_front"][k]) if "deflection_front" in run.scalars else None
    dfront = dfront if dfront else None          # 0: no slab-deflection front yet (drawn at the cut end otherwise)
    saw = float(run.scalars["saw"][k]) if "saw" in run.scalars else 0.0
    to_x = params.distance_from_cut_end          # distances from the cut end <-> x (its own inverse)

    fig = Figure(figsize=(12, 6.4), dpi=130, layout="constrained")
    FigureCanvasAgg(fig)
    ax, az = fig.subplots(2, 1, height_ratios=[1.15, 1])
    # ---------------------------------------------------------------- the column, displacements exaggerated
    grey = ~wl
    ax.scatter(shown[grey, 0], shown[grey, 1], s=0.3, c="0.75", lw=0, rasterized=True)
    _slab_layers(ax, params, groups, gid, shown, L)
    cracked = None
    if "damage" in fr:                                   # a slab that can break: its cracked particles
        cracked = grey & (fr["damage"].astype(float) >= 0.95)
        if cracked.any():
            ax.scatter(shown[cracked, 0], shown[cracked, 1], s=3.0, c="crimson", lw=0, rasterized=True,
                       label="slab cracked through (damage >= 0.95)")
    sc = ax.scatter(shown[wl, 0], shown[wl, 1], s=2.5, c=collapse, cmap=CMAP, vmin=0.0, vmax=c_max, lw=0,
                    rasterized=True)
    y_top = params.base_y + D
    for s, style, label in ((front if front > 0 else None, "-", f"damage front {front:.2f} m"),
                            (dfront, "--", f"slab-deflection front {dfront:.2f} m" if dfront is not None else ""),
                            (saw, ":", f"saw blade {saw:.2f} m (cut {cut:.2f} m)")):
        if s is None:
            continue
        xs = float(to_x(s))
        ax.plot([xs, xs], [-0.02, y_top + 0.05], style, color="magenta" if style == "-" else "k", lw=1.3,
                label=label)
    ax.set(xlim=(-0.05, L + 0.05), ylim=(-0.03, y_top + 0.08), xlabel="x along the column [m]", ylabel="y [m]")
    ax.set_aspect(max(1.0, 0.3 * (L + 0.1) / (y_top + 0.11)), adjustable="box")   # a column ~0.3 as high as long
    ax.legend(loc="lower right", fontsize=7, ncols=2, framealpha=0.9)
    cb = fig.colorbar(sc, ax=[ax, az], shrink=0.8, pad=0.01, panchor=False)   # a short column stays centred
    cb.set_label("weak-layer collapse since settling, 1 - J_P/J_P,ref [-]\n(white: the law under the slab at rest)")
    cb.ax.axhline(h_c / params.weak_layer_thickness, color="w", lw=2)
    # ---------------------------------------------------------------- zoom on the layer at the front
    xf = float(to_x(front))
    lo, hi = sorted((float(to_x(max(front - 0.8, 0.0))), float(to_x(min(front + 0.3, L)))))
    y0, y1 = params.substratum_depth - 0.01, params.base_y + 0.03
    box = (x[:, 0] >= lo) & (x[:, 0] <= hi) & (x[:, 1] >= y0) & (x[:, 1] <= y1)
    az.scatter(x[box & grey, 0], x[box & grey, 1], s=2.0, c="0.72", lw=0, rasterized=True)
    zw = box[wl]
    az.scatter(x[wl][zw, 0], x[wl][zw, 1], s=5.0, c=collapse[zw], cmap=CMAP, vmin=0.0, vmax=c_max, lw=0,
               rasterized=True)
    if front > 0:
        az.axvline(xf, color="magenta", lw=1.3)
    if dfront is not None:
        az.axvline(float(to_x(dfront)), color="k", ls="--", lw=1.0)
    az.axhline(params.base_y, color="0.3", lw=0.6, ls=":")
    az.axhline(params.base_y - h_c, color="0.3", lw=0.6, ls="-.")
    az.text(lo, params.base_y, " settled slab base", va="bottom", fontsize=7)
    az.text(lo, params.base_y - h_c, " minus the calibrated collapse height", va="top", fontsize=7)
    az.set(xlim=(lo, hi), ylim=(y0, y1), xlabel="x [m]", ylabel="y [m]")
    fig.canvas.draw()                             # the laid-out axes: pixels per metre on each axis

    def stretch(a, x0, x1, y0, y1):
        bb = a.get_window_extent()
        return (bb.height / (y1 - y0)) / (bb.width / (x1 - x0))

    outcome = (run.attrs.get("outcome") or {}).get("pst") or {}
    line = f"{outcome['field_line']}: " if outcome.get("field_line") else ""
    if outcome.get("class") == "SF" and np.isfinite(outcome.get("slab_fracture_at", np.nan)):
        xs = float(to_x(outcome["slab_fracture_at"]))
        ax.annotate(f"slab fracture {outcome['slab_fracture_at']:.2f} m", (xs, y_top), (xs, y_top + 0.045),
                    color="crimson", fontsize=8, ha="center", arrowprops=dict(arrowstyle="->", color="crimson"))
    k = stretch(ax, -0.05, L + 0.05, -0.03, y_top + 0.08)
    ax.set_title(f"{line}{run.scenario.get('name', 'PST')} at t = {t:.3f} s\ndisplacements since settling "
                 f"exaggerated x{f:.0f}, vertical axis stretched x{k:.1f}")
    az.set_title(f"zoom on the weak layer at the damage front: true displacements, vertical axis stretched "
                 f"x{stretch(az, lo, hi, y0, y1):.0f}")
    os.makedirs(os.path.dirname(os.path.abspath(out_png)), exist_ok=True)
    fig.savefig(out_png)
    return out_png
