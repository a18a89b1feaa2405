"""The phases of an MLS-MPM step as recorded Warp launches, built once per scene.

One function per phase, in the order a step runs them: the step size (:func:`begin_step_launch`),
the walls' position and velocity (:func:`wall_state_launch`), the laminate closure at material
interfaces (:func:`closure_launches`), P2G per particle group (:func:`p2g_launches`), the grid
update by rows of nodes (:func:`grid_update_launches`), G2P (:func:`g2p_launches`), the bonded
layers' column means (:func:`column_mean_launches`) and the clock (:func:`end_step_launch`). The
parallel phases get one launch per thread of the CPU step, each over its own range and grid copy
(:class:`StepGrid`). :class:`~mpm_warp.step.Stepper` allocates what they write and runs them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import warp as wp

from .interfaces import closure_factors
from .kernels.crack_band import column_sums_zero_kernel, kappa_column_mean_kernel, kappa_column_sum_kernel
from .kernels.g2p import g2p_kernel
from .kernels.grid_update import grid_update_kernel, wall_state_kernel
from .kernels.interface_closure import closure_kernel
from .kernels.p2g import p2g_kernel
from .kernels.timestep import begin_step_kernel, end_step_kernel
from .kernels.types import vec
from .particle_groups import material_params

__all__ = ["StepGrid", "step_grid", "begin_step_launch", "p2g_launches", "closure_launches", "wall_state_launch",
           "grid_update_launches", "g2p_launches", "column_mean_launches", "end_step_launch"]


def _chunks(start: int, end: int, n: int) -> list[tuple[int, int]]:
    """Split ``[start, end)`` into ``n`` contiguous near-equal ranges."""
    edges = np.linspace(start, end, n + 1).round().astype(int)
    return [(int(edges[k]), int(edges[k + 1])) for k in range(n)]


@dataclass(frozen=True)
class StepGrid:
    """The background grid as the step's kernels see it.

    The kernels see the grid flat (node (i, j[, k]) at i s_0 + j s_1 [+ k]), copy k at k n_nodes;
    ``m`` and ``p`` are the flat buffers of every copy (nodal masses, kg, and momenta, kg m/s),
    ``copies`` per thread its (mass, momentum) views.
    """

    #: position of node (0, ..., 0) (m), as a Warp vector
    origin: Any
    dx: Any
    inv_dx: Any
    #: nodes per axis and the flat index strides, as Warp int vectors
    shape: Any
    strides: Any
    m: wp.array
    p: wp.array
    copies: list


def step_grid(model, n_copies: int) -> StepGrid:
    """Allocate ``n_copies`` zeroed grid copies of ``model`` (a :class:`~mpm_warp.model.Model`)."""
    T, dev, dim, gs = model.T, model.device, model.dim, model.grid_shape
    V = vec(dim, T)
    Vi = wp.types.vector(dim, wp.int32)
    n_nodes = int(np.prod(gs))
    strides = Vi(*[int(np.prod(gs[a + 1:])) for a in range(dim)])
    m = wp.zeros(n_copies * n_nodes, dtype=T, device=dev)
    p = wp.zeros(n_copies * n_nodes, dtype=V, device=dev)
    copies = [(m[k * n_nodes:(k + 1) * n_nodes], p[k * n_nodes:(k + 1) * n_nodes]) for k in range(n_copies)]
    return StepGrid(V(*model.origin), T(model.dx), T(1.0 / model.dx), Vi(*gs), strides, m, p, copies)


def begin_step_launch(model, state, vmax: wp.array, dt: wp.array, fixed_dt: float):
    """The step size: ``dt = cfl dx / (c_p + |v|max)`` on the device (or ``fixed_dt``), written to ``dt``."""
    tc = model.scenario.time
    dt_max = tc.dt_max if tc.dt_max > 0 else 1e30
    return wp.launch(begin_step_kernel(model.T), 1, inputs=[state.clock, vmax, tc.cfl, model.dx, model.c_p,
                                                            fixed_dt, dt_max, dt],
                     device=model.device, record_cmd=True)


def p2g_launches(model, state, grid: StepGrid, dt: wp.array, counts: wp.array, nt: int) -> list[list]:
    """Per thread k, the P2G launches of its share of every particle group (the Cam-Clay return compiled in
    only for plastic groups), scattering into grid copy k."""
    T, dev, dim, s = model.T, model.device, model.dim, state
    out: list[list] = [[] for _ in range(nt)]
    # fields a group does not have (never read: the kernel is built without them) are passed as one-element
    # arrays, not None: Warp's CPU code takes its contiguous fast path only when every array is contiguous
    unused = {t: wp.zeros(1, dtype=t, device=dev) for t in (T, wp.uint8)}
    for g in model.groups:
        mat = g.material
        plastic = mat.plastic
        k_p2g = p2g_kernel(dim, T, mat.model, plastic and s.yielded is not None)
        m_par = material_params(mat, T)
        for k, (a, b) in enumerate(_chunks(g.start, g.end, nt)):
            if b <= a:
                continue
            sl = slice(a, b)
            ljp, kap, yld, hz = unused[T], unused[T], unused[wp.uint8], unused[T]
            if g.kappa_start >= 0:
                kap = s.kappa[g.kappa_start + a - g.start:g.kappa_start + b - g.start]
            if plastic:
                psl = slice(g.plastic_start + a - g.start, g.plastic_start + b - g.start)
                ljp = s.log_jp[psl]
                yld = s.yielded[psl] if s.yielded is not None else yld
                hz = s.hzz[psl] if s.hzz is not None else hz
            out[k].append(wp.launch(
                k_p2g, b - a,
                inputs=[s.x[sl], s.v[sl], s.C[sl], s.H[sl], hz, ljp, kap, yld, T(g.mass), T(g.vol0), m_par,
                        dt, grid.origin, grid.inv_dx, grid.dx, grid.shape, grid.strides, *grid.copies[k], counts[k]],
                device=dev, record_cmd=True))
    return out


def closure_launches(model, state, dt: wp.array) -> tuple[list, list]:
    """The laminate closure at material interfaces (docs/model.md §5b), before every P2G: only for stacks.

    Returns the launches and the device arrays (particle indices, factors) they read."""
    launches, arrays_all = [], []
    F3 = wp.types.vector(3, model.T)
    dev = model.device
    for axis, idx, fac in closure_factors(model):
        if len(idx) == 0:
            continue
        arrays = (wp.array(idx, dtype=wp.int32, device=dev), wp.array(fac.astype(model.np_dtype), dtype=F3,
                                                                       device=dev))
        arrays_all.append(arrays)
        launches.append(wp.launch(closure_kernel(model.dim, model.T), len(idx), inputs=[*arrays, axis, state.C, dt],
                                  device=dev, record_cmd=True))
    return launches, arrays_all


def wall_state_launch(model, state, dt: wp.array) -> tuple:
    """The walls at the end of the step, evaluated once per step for every node of the grid update.

    Returns ``(launch, wall_point, wall_velocity)``, all None without walls."""
    if not model.walls:
        return None, None, None
    dev, nw = model.device, len(model.walls)
    V = vec(model.dim, model.T)
    wall_point = wp.zeros(nw, dtype=V, device=dev)
    wall_velocity = wp.zeros(nw, dtype=V, device=dev)
    launch = wp.launch(wall_state_kernel(model.T, model.dim), nw,
                       inputs=[model.walls_device, dt, state.clock, wall_point, wall_velocity],
                       device=dev, record_cmd=True)
    return launch, wall_point, wall_velocity


def grid_update_launches(model, state, grid: StepGrid, dt: wp.array, nt: int, seg_len: int, wall_point,
                         wall_velocity, wall_impulses, vmax: wp.array) -> list:
    """Per thread k, the grid update of its slab of node rows along the last axis (summing the copies, then
    gravity, damping and walls), in segments of ``seg_len`` nodes: a whole row on the CPU, a node on CUDA."""
    T, dev, dim, gs = model.T, model.device, model.dim, model.grid_shape
    V = vec(dim, T)
    tc = model.scenario.time
    has_walls = bool(model.walls)
    rows = int(np.prod(gs[:-1]))
    per_row = gs[-1] // seg_len
    out = []
    for k, (a, b) in enumerate(_chunks(0, rows, nt)):
        out.append(wp.launch(
            grid_update_kernel(dim, T, has_walls), (b - a) * per_row,
            inputs=[grid.m, grid.p, nt, a, seg_len, grid.shape, grid.strides, dt, state.clock,
                    V(*model.gravity), T(tc.gravity_ramp), T(tc.damping),
                    T(tc.damping_until if tc.damping > 0 else 0.0), T(model.mass_threshold), grid.origin, grid.dx,
                    model.walls_device, wall_point, wall_velocity,
                    wall_impulses[k] if has_walls else None, vmax[k:k + 1]],
            device=dev, record_cmd=True))
    return out


def g2p_launches(model, state, grid: StepGrid, dt: wp.array, counts: wp.array, nt: int) -> list:
    """Per thread k, G2P of its range of particles from the summed grid (copy 0), clamped to the grid's inside."""
    T, dim, s = model.T, model.dim, state
    V = vec(dim, T)
    out = []
    for k, (a, b) in enumerate(_chunks(0, model.n_particles, nt)):
        sl = slice(a, b)
        out.append(wp.launch(
            g2p_kernel(dim, T), b - a,
            inputs=[s.x[sl], s.v[sl], s.C[sl], grid.copies[0][1], dt, grid.origin, grid.inv_dx, grid.dx, grid.shape,
                    grid.strides, V(*model.x_lo), V(*model.x_hi), counts[k]],
            device=model.device, record_cmd=True))
    return out


def column_mean_launches(model, state) -> tuple[list, list]:
    """Bonded weak layers: ``kappa`` replaced by its lattice-column mean after every step
    (kernels/bonded_camclay.py). Returns the launches and, per bonded group, its (column index, sums) arrays."""
    T, dev, s = model.T, model.device, state
    launches, column_sums = [], []
    for g in model.groups:
        if g.columns is None:
            continue
        kap = s.kappa[g.plastic_start:g.plastic_start + g.count]
        col = wp.array(g.columns, dtype=wp.int32, device=dev)
        sums = wp.zeros(g.n_columns, dtype=wp.vec2d, device=dev)
        column_sums.append((col, sums))
        launches += [
            wp.launch(column_sums_zero_kernel(), g.n_columns, inputs=[sums], device=dev, record_cmd=True),
            wp.launch(kappa_column_sum_kernel(T), g.count, inputs=[kap, col, sums], device=dev, record_cmd=True),
            wp.launch(kappa_column_mean_kernel(T), g.count, inputs=[sums, col, kap], device=dev, record_cmd=True)]
    return launches, column_sums


def end_step_launch(model, state):
    """The clock: ``t += dt`` and one more step (a step of ``dt = 0``, past a frame end, is none)."""
    return wp.launch(end_step_kernel(), 1, inputs=[state.clock, state.steps], device=model.device, record_cmd=True)
