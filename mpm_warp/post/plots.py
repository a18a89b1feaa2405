"""Time-series plots of a run file (matplotlib, Agg canvas): PNG figures with their data beside them.

Each figure ``<name>.png`` comes with ``<name>.csv`` (the plotted series, header ``name [unit]``)
and, for fits, ``<name>.json``. Figures are made only for the series a run has:

- ``front``: crack front position against time, with the speed of a straight-line fit on the
  steady part of its travel (``front_position``, x [m], or a PST's ``front``, distance from the
  saw's starting end [m]; the saw's position and the slab-deflection front too when stored);
- ``markers``: slab marker displacements ``marker_<k>_dx|dy`` (or ``marker<k>_ux|uy``) against time;
- ``shear``: shear stress (and Mises stress q) and axial strain against shear strain
  (``shear_strain`` with ``shear_stress``, ``mises_q``, ``axial_strain``);
- ``energy``: every ``*_energy`` series and their sum against time.

Uses :class:`matplotlib.figure.Figure` with an Agg canvas: no pyplot, no display, and the
caller's matplotlib backend is left alone.
"""

from __future__ import annotations

import csv
import os
import re

import numpy as np

from ..finite_json import dump_finite
from ..io import RunData, read_run
from ..scenes.pst import PSTParams
from .fronts import front_name, front_speed, scene_params
from .pst_picture import pst_picture

__all__ = ["plot_run", "plot_front", "plot_markers", "plot_shear", "plot_energy"]

_MARKER = re.compile(r"^marker_?(.+?)_(dx|dy|ux|uy)$")


def _figure(ncols: int = 1):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4 * ncols if ncols > 1 else 7.0, 4.5), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, ncols)
    return fig, np.atleast_1d(axes)


def _title(run: RunData) -> str:
    return str((run.scenario or {}).get("name") or os.path.basename(run.path))


def _unit(run: RunData, name: str) -> str:
    return run.units.get(name, "1")


def _write_csv(path: str, columns: dict[str, np.ndarray]) -> str:
    """Columns of equal length under the header ``name [unit]``, full float precision."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(list(columns))
        for row in zip(*columns.values(), strict=True):
            w.writerow([repr(float(v)) for v in row])
    return path


def _save(fig, out_dir: str, name: str, columns: dict, fit: dict | None = None) -> list[str]:
    png = os.path.join(out_dir, name + ".png")
    fig.savefig(png)
    files = [png, _write_csv(os.path.join(out_dir, name + ".csv"), columns)]
    if fit is not None:
        with open(os.path.join(out_dir, name + ".json"), "w") as f:
            dump_finite(fit, f, indent=1)
        files.append(os.path.join(out_dir, name + ".json"))
    return files


def plot_front(run: RunData, out_dir: str) -> list[str]:
    """Front position against time with the fitted speed: ``front.png``, ``.csv``, ``.json``.

    The front is ``front_position`` (x [m]) or a PST's ``front`` (distance from the saw's end
    [m], the damage front; with ``deflection_front`` and ``saw`` beside it). The fit is
    :func:`mpm_warp.post.fronts.front_speed` (for a PST over the positions of the PST's own mean speed).
    """
    name = front_name(run)
    t, xf = run.times, run.scalars[name]
    fit = front_speed(run)
    fig, (ax,) = _figure()
    ax.plot(t, xf, "o-", ms=3, lw=1, color="C0", label="crack front" if name == "front_position" else "damage front")
    columns = {"time [s]": t, f"{name} [{_unit(run, name)}]": xf}
    for other, style, label in (("deflection_front", ":", "slab-deflection front"), ("saw_position", "--", "saw"),
                                ("saw", "--", "saw")):
        if other in run.scalars:
            ax.plot(t, run.scalars[other], style, color="0.4", label=label)
            columns[f"{other} [{_unit(run, other)}]"] = run.scalars[other]
    if np.isfinite(fit["speed"]):
        tt = np.array([fit["t_start"], fit["t_end"]])
        ax.axvspan(*tt, color="C1", alpha=0.12, lw=0)
        ax.plot(tt, fit["intercept"] + fit["speed"] * tt, "-", color="C1", lw=2.5,
                label=f"fit: c = {fit['speed']:.3g} m/s")
        columns["front_fit [m]"] = fit["intercept"] + fit["speed"] * t
    ylabel = "front position x [m]" if name == "front_position" else "front: distance from the saw's end [m]"
    ax.set(xlabel="time t [s]", ylabel=ylabel, title=f"{_title(run)}: crack front")
    ax.grid(alpha=0.3)
    ax.legend(loc="best")
    return _save(fig, out_dir, "front", columns, {**fit, "series": name, "unit_speed": "m/s", "unit_intercept": "m"})


def _marker_key(name: str):
    k, comp = _MARKER.match(name).groups()
    return (int(k) if k.isdigit() else 0, k, comp)


def plot_markers(run: RunData, out_dir: str) -> list[str]:
    """Slab marker displacements [mm] against time: ``markers.png`` and ``.csv`` (in metres).

    Series ``marker_<k>_dx|dy`` or a PST's ``marker<k>_ux|uy``.
    """
    names = sorted((n for n in run.scalars if _MARKER.match(n)), key=_marker_key)
    fig, axes = _figure(2)
    columns = {"time [s]": run.times}
    for n in names:
        k, comp = _MARKER.match(n).groups()
        ax = axes[0 if comp in ("dx", "ux") else 1]
        ax.plot(run.times, 1e3 * run.scalars[n], "-", label=f"marker {k}")
        columns[f"{n} [{_unit(run, n)}]"] = run.scalars[n]
    for ax, comp in zip(axes, ("x", "y"), strict=True):
        ax.set(xlabel="time t [s]", ylabel=f"displacement u{comp} [mm]", title=f"{_title(run)}: markers, u{comp}")
        ax.grid(alpha=0.3)
        if 0 < len(ax.lines) <= 12:
            ax.legend(loc="best", fontsize=8, ncols=2 if len(ax.lines) > 6 else 1)
    return _save(fig, out_dir, "markers", columns)


def plot_shear(run: RunData, out_dir: str) -> list[str]:
    """Shear test: stresses [kPa] and axial strain against shear strain: ``shear.png``, ``.csv``."""
    s = run.scalars
    gamma = s["shear_strain"]
    fig, axes = _figure(2)
    columns = {f"shear_strain [{_unit(run, 'shear_strain')}]": gamma}
    for name, label in (("shear_stress", "shear stress tau"), ("mises_q", "Mises stress q")):
        if name in s:
            axes[0].plot(gamma, 1e-3 * s[name], "-", label=label)
            columns[f"{name} [{_unit(run, name)}]"] = s[name]
    if "axial_strain" in s:
        axes[1].plot(gamma, s["axial_strain"], "-", color="C2")
        columns[f"axial_strain [{_unit(run, 'axial_strain')}]"] = s["axial_strain"]
    columns["time [s]"] = run.times
    axes[0].set(xlabel="shear strain [-]", ylabel="stress [kPa]", title=f"{_title(run)}: shear stress")
    axes[1].set(xlabel="shear strain [-]", ylabel="axial strain [-]", title=f"{_title(run)}: axial strain")
    for ax in axes:
        ax.grid(alpha=0.3)
    if axes[0].lines:
        axes[0].legend(loc="best")
    return _save(fig, out_dir, "shear", columns)


def plot_energy(run: RunData, out_dir: str) -> list[str]:
    """Every ``*_energy`` series and their sum [J] against time: ``energy.png`` and ``.csv``."""
    names = [n for n in run.scalars if n.endswith("_energy")]
    parts = [n for n in names if n != "total_energy"]     # a stored total is plotted, not summed
    fig, (ax,) = _figure()
    columns = {"time [s]": run.times}
    for n in names:
        ax.plot(run.times, run.scalars[n], "-", label=n.replace("_", " "))
        columns[f"{n} [{_unit(run, n)}]"] = run.scalars[n]
    if len(parts) > 1 and "total_energy" not in names:
        total = np.sum([run.scalars[n] for n in parts], axis=0)
        ax.plot(run.times, total, "k--", label="sum")
        columns["total_energy [J]"] = total
    ax.set(xlabel="time t [s]", ylabel="energy [J]", title=f"{_title(run)}: energy")
    ax.grid(alpha=0.3)
    ax.legend(loc="best")
    return _save(fig, out_dir, "energy", columns)


def plot_run(path, out_dir=None) -> list[str]:
    """Make every plot a run supports; return the files written (PNG, CSV, JSON).

    Parameters
    ----------
    path : str, os.PathLike or RunData
        Run file (or one already read).
    out_dir : str, optional
        Folder of the figures (created); default ``<run>_plots`` beside the run file.

    Returns
    -------
    list of str
        ``front.*`` (with ``front_position`` or ``front``), ``markers.*`` (with ``marker_<k>_dx|dy`` or
        ``marker<k>_ux|uy``),
        ``shear.*`` (with ``shear_strain``), ``energy.*`` (with ``*_energy`` series), ``pst.png`` (a PST run
        with ``x``, ``log_jp`` and ``log_jp_ref``: :func:`mpm_warp.post.pst_picture.pst_picture` at the moment
        the crack runs), in that order.
    """
    run = path if isinstance(path, RunData) else read_run(path)
    out_dir = os.fspath(out_dir) if out_dir is not None else os.path.splitext(run.path)[0] + "_plots"
    os.makedirs(out_dir, exist_ok=True)
    s, files = run.scalars, []
    if front_name(run):
        files += plot_front(run, out_dir)
    if any(_MARKER.match(n) for n in s):
        files += plot_markers(run, out_dir)
    if "shear_strain" in s and {"shear_stress", "mises_q", "axial_strain"} & s.keys():
        files += plot_shear(run, out_dir)
    if any(n.endswith("_energy") for n in s):
        files += plot_energy(run, out_dir)
    if isinstance(scene_params(run), PSTParams) and {"x", "log_jp", "log_jp_ref"} <= set(run.particle_fields):
        files.append(pst_picture(run, os.path.join(out_dir, "pst.png")))
    return files
