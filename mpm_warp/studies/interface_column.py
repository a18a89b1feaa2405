"""The settled column: normal and shear stress per particle row across the weak layer and its two interfaces.

A PST's stack (substratum, weak layer, slab) as a narrow column between two slip walls (plane strain), settled
as the PST settles (gravity ramp and grid damping, ``settle.duration``), no saw. Between slip walls every row is
uniform along the column, so at rest each row's ``sigma_yy`` must equal the overburden at its height: the
weight of the material above it, ``g cos(theta) * integral of rho`` over the initial stack above the row's
initial height (mass above a row is conserved, so this holds at any compaction). Returns each row's
``sigma_yy`` and ``tau`` beside it (docs/model.md §5, the interfaces' stress).
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..loader import load_scenario
from ..scenes.snow import GRAVITY
from ..simulation import Simulation
from ..walls import Wall

__all__ = ["column_scenario", "overburden", "settled_rows", "column_rows", "free_column_rows", "row_ratios",
           "step_cost", "running_rows"]


def column_scenario(cells: float, scenario: str = "pst_demo", width_cells: int = 4, overrides=()):
    """The settled column of ``scenario``'s stack at ``cells`` grid cells across its weak layer.

    Parameters
    ----------
    cells : float
        Grid cells across the weak layer (``dx = D_wl / cells``).
    scenario : str
        A PST scenario (name or file) whose stack and settling the column takes.
    width_cells : int
        Column width in grid cells (its rows are uniform, so a few cells suffice).
    overrides : sequence of str
        Further scenario overrides (e.g. ``"scene.interface_closure=true"``).

    Returns
    -------
    Scenario
        The column between slip walls at ``x = 0`` and ``x = L``, ending when settling ends.
    """
    base = load_scenario(scenario)
    dx = base.scene.weak_layer_thickness / float(cells)
    L = width_cells * dx
    sc = load_scenario(scenario, [f"scene.dx={dx!r}", f"scene.length={L!r}", f"scene.margin={2.0 * dx!r}",
                                  "scene.column_ends=slope_normal", "scene.saw.cut_length=0.0",
                                  *overrides])
    dim = sc.domain.dimension
    z = (0.0,) * (dim - 2)
    ends = (Wall((0.0, 0.0, *z), (1.0, 0.0, *z), kind="slip", name="end_lo"),
            Wall((L, 0.0, *z), (-1.0, 0.0, *z), kind="slip", name="end_hi"))
    t_end = float(sc.scene.settle.duration)
    time_ = dataclasses.replace(sc.time, end=t_end, frame_interval=t_end)
    return dataclasses.replace(sc, walls=tuple(sc.walls) + ends, time=time_)


def _stack(params) -> list[tuple[str, float, float, float]]:
    """``(group, y0, y1, density)`` of the column's layers, bottom to top (as the PST builds them)."""
    from ..scenes.pst.build import layer_names

    out, y = [], 0.0
    sub, slab = params.substratum_stack(), params.slab_stack()
    for g, layer in reversed(list(zip(layer_names("substratum", len(sub)), sub, strict=True))):
        out.append((g, y, y + layer.thickness, layer.density))
        y += layer.thickness
    out.append(("weak_layer", y, y + params.weak_layer_thickness, params.weak_layer.density))
    y += params.weak_layer_thickness
    for g, layer in reversed(list(zip(layer_names("slab", len(slab)), slab, strict=True))):
        out.append((g, y, y + layer.thickness, layer.density))
        y += layer.thickness
    return out


def overburden(params, y0) -> np.ndarray:
    """Bed-normal stress of the material above initial height ``y0`` (Pa, compression positive):
    ``g cos(theta) * integral_{y0}^{top} rho dy`` over the PST's initial stack ``params``."""
    y0 = np.asarray(y0, dtype=float)
    out = np.zeros_like(y0)
    for _, a, b, rho in _stack(params):
        out += rho * np.clip(b - np.maximum(y0, a), 0.0, None)
    return GRAVITY * math.cos(math.radians(params.slope_angle)) * out


def settled_rows(sim: Simulation, columns: tuple[float, float] | None = None) -> list[dict]:
    """Per particle row (bottom to top): group, initial and current height, mean ``sigma_yy`` and ``tau``.

    Rows are the particles of one group at one initial height; ``columns`` (m) keeps only the particles whose
    initial ``x`` lies in ``[lo, hi)`` (None: all). Stresses are Cauchy (Pa, tension positive).
    """
    p = sim.scenario.scene
    _, _, sig = sim.stresses(cauchy=True)
    x = sim.state.x.numpy().astype(float)
    rows = []
    for g in sim.model.groups:
        sl = slice(g.start, g.end)
        x0 = sim.x0[sl]
        keep = np.ones(len(x0), bool) if columns is None else (x0[:, 0] >= columns[0]) & (x0[:, 0] < columns[1])
        y0 = np.round(x0[keep, 1], 9)
        syy, sxy, yc = sig[sl][keep, 1, 1], sig[sl][keep, 0, 1], x[sl][keep, 1]
        for y in np.unique(y0):
            k = y0 == y
            rows.append({"group": g.name, "y0": float(y), "y": float(yc[k].mean()), "n": int(k.sum()),
                         "sigma_yy": float(syy[k].mean()), "tau": float(sxy[k].mean()),
                         "sigma_yy_spread": float(syy[k].max() - syy[k].min())})
    rows.sort(key=lambda r: r["y0"])
    ob = overburden(p, [r["y0"] for r in rows])
    for r, s in zip(rows, ob, strict=True):
        r["overburden"] = float(s)
        r["ratio"] = float(-r["sigma_yy"] / s) if s > 0 else float("nan")
    return rows


def row_ratios(rows: list[dict], params, reach: float = 3.0) -> list[dict]:
    """The rows within ``reach`` grid cells of the weak layer (its own rows and its neighbours'), bottom to top."""
    lo = params.substratum_depth - reach * params.dx
    hi = params.base_y + reach * params.dx
    return [r for r in rows if lo <= r["y0"] <= hi]


def column_rows(cells: float, scenario: str = "pst_demo", width_cells: int = 4, overrides=(),
                device: str = "cpu") -> dict:
    """Settle the column (:func:`column_scenario`) and return its rows (:func:`settled_rows`) with run facts.

    Returns
    -------
    dict
        ``cells``, ``dx`` (m), ``rows`` (all), ``near`` (within 3 cells of the layer), ``worst`` (the largest
        ``|sigma_yy / overburden - 1|`` over ``near``), ``wall_s``, ``steps``, ``particles``.
    """
    sc = column_scenario(cells, scenario, width_cells, overrides)
    sim = Simulation(sc, device=device)
    t0 = time.perf_counter()
    steps = sim.step_to(sc.time.end)
    wall = time.perf_counter() - t0
    rows = settled_rows(sim)
    near = row_ratios(rows, sc.scene)
    return {"cells": float(cells), "dx": sc.scene.dx, "overrides": list(overrides), "rows": rows, "near": near,
            "worst": max(abs(r["ratio"] - 1.0) for r in near), "wall_s": wall, "steps": int(steps),
            "particles": int(sim.model.n_particles),
            "s_per_particle_step": wall / max(1, steps * sim.model.n_particles)}


def free_column_rows(scenario: str = "pst_demo", x: float = 2.1, overrides=(), device: str = "cpu") -> dict:
    """The scenario itself (free column ends, no saw) settled, and the rows of the particle column nearest ``x`` (m)."""
    sc = load_scenario(scenario, list(overrides))
    t_end = float(sc.scene.settle.duration)
    sc = dataclasses.replace(sc, time=dataclasses.replace(sc.time, end=t_end, frame_interval=t_end))
    sim = Simulation(sc, device=device)
    t0 = time.perf_counter()
    steps = sim.step_to(t_end)
    wall = time.perf_counter() - t0
    h = sc.scene.dx / sc.scene.particles_per_cell
    x0 = sim.x0[:, 0]
    xc = x0[np.argmin(np.abs(x0 - x))]
    rows = settled_rows(sim, (xc - 0.5 * h, xc + 0.5 * h))
    return {"x": float(xc), "rows": rows, "near": row_ratios(rows, sc.scene), "wall_s": wall, "steps": int(steps),
            "particles": int(sim.model.n_particles)}


def step_cost(scenario: str = "pst_demo", overrides=(), steps: int = 200, repeats: int = 3,
              device: str = "cpu") -> dict:
    """CPU seconds per particle-step of ``scenario`` while settling, the best of ``repeats`` batches of ``steps``.

    The simulation is built and compiled (one warm-up batch) before timing; the process's CPU time is the
    clock (the shared machine's other work does not count, as in :mod:`.timing`).
    """
    sc = load_scenario(scenario, list(overrides))
    sim = Simulation(sc, device=device, n_threads=1)
    sim.stepper.set_frame_end(float(sc.scene.settle.duration))
    sim.stepper.steps(steps)
    sim.stepper.clock()
    best = float("inf")
    for _ in range(repeats):
        t0 = time.process_time()
        sim.stepper.steps(steps)
        sim.stepper.clock()
        best = min(best, time.process_time() - t0)
    n = sim.model.n_particles
    return {"scenario": scenario, "overrides": list(overrides), "particles": int(n), "steps": steps,
            "repeats": repeats, "closure_particles": int(sum(len(a[0]) for a in sim.stepper._closure_arrays)),
            "s_per_particle_step": best / (steps * n)}


def running_rows(scenario: str = "pst_demo", overrides=(), ahead: float = 0.1, min_front: float = 0.3,
                 device: str = "cpu") -> dict:
    """A running PST's rows just ahead of its damage front: ``sigma_yy`` and ``tau`` per row of the particle
    column ``ahead`` (m) beyond the front, at the first frame the front has passed ``min_front`` (m) from the
    cut end (the run stops there). Heights are initial; the overburden is the settled column's."""
    from ..runner import run

    state = {}

    def frame(sim, k):
        mon = sim.monitors["pst"]
        front = mon.damage_front(sim.time)
        if front >= min_front:
            state.update(sim=sim, front=front, t=sim.time)
            return False
        return True

    t0 = time.perf_counter()
    rr = run(scenario, device=device, overrides=list(overrides), callback=frame)
    wall = time.perf_counter() - t0
    if "sim" not in state:
        return {"front": float("nan"), "rows": [], "near": [], "wall_s": wall, "note": "the front did not pass "
                f"{min_front} m"}
    sim = state["sim"]
    p = sim.scenario.scene
    x_front = state["front"] if p.saw.cut_from == "upslope" else p.length - state["front"]
    x = x_front + (ahead if p.saw.cut_from == "upslope" else -ahead)
    h = p.dx / p.particles_per_cell
    x0 = sim.x0[:, 0]
    xc = x0[np.argmin(np.abs(x0 - x))]
    rows = settled_rows(sim, (xc - 0.5 * h, xc + 0.5 * h))
    return {"front": float(state["front"]), "t": float(state["t"]), "x": float(xc), "rows": rows,
            "near": row_ratios(rows, p), "wall_s": wall, "steps": int(rr.steps)}
