"""The MLS-MPM step: a plan of kernel launches built once per scene.

``Stepper.step()`` launches, in physical order: time-step choice, grid clear,
P2G (one launch per particle group, with the Cam-Clay return compiled in only
for plastic groups), grid update (wall code only when walls exist), G2P and
the clock update. No host read-back happens inside a step; on CUDA a batch of
steps is captured once as a graph and replayed.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .kernels.g2p import g2p_kernel
from .kernels.grid_update import grid_update_kernel
from .kernels.p2g import p2g_kernel
from .kernels.timestep import begin_step_kernel, end_step_kernel
from .kernels.types import vec3
from .model import SINGULAR_VALUE_FLOOR, Model, State

__all__ = ["Stepper"]


class Stepper:
    """Launch plan for one model and state.

    Parameters
    ----------
    model : Model
    state : State
    use_graph : bool or None
        Capture a batch of steps as a CUDA graph (default: on CUDA only).
    """

    def __init__(self, model: Model, state: State, use_graph: bool | None = None):
        self.model = model
        self.state = state
        T = model.T
        dev = model.device
        V = vec3(T)
        self.grid_m = wp.zeros(model.grid_shape, dtype=T, device=dev)
        self.grid_p = wp.zeros(model.grid_shape, dtype=V, device=dev)
        self.dt = wp.zeros(1, dtype=T, device=dev)
        self.vmax = wp.zeros(1, dtype=T, device=dev)
        # [particles clamped at the grid edge, particles skipped with a stencil outside the grid]
        self.edge_count = wp.zeros(2, dtype=wp.int32, device=dev)
        has_walls = bool(model.walls)
        self.wall_impulse = wp.zeros(len(model.walls), dtype=V, device=dev) if has_walls else None
        self.fixed_dt = model.scenario.time.dt
        tc = model.scenario.time
        dt_max = tc.dt_max if tc.dt_max > 0 else 1e30
        origin = V(*model.origin)
        inv_dx = T(1.0 / model.dx)
        dx = T(model.dx)
        s = state

        self._begin = wp.launch(begin_step_kernel(T), 1, inputs=[s.clock, self.vmax, tc.cfl, model.dx, model.c_p,
                                                                 self.fixed_dt, dt_max, self.dt],
                                device=dev, record_cmd=True)
        self._p2g = []
        for g in model.groups:
            mat = g.material
            plastic = mat.plastic
            sl = slice(g.start, g.end)
            if plastic:
                psl = slice(g.plastic_start, g.plastic_start + g.count)
                ljp = s.log_jp[psl]
                yld = s.yielded[psl] if s.yielded is not None else None
                cc = (T(mat.M), T(mat.beta), T(mat.xi), T(mat.p0_floor))
            else:
                ljp, yld = None, None
                cc = (T(0.0), T(0.0), T(0.0), T(0.0))
            k = p2g_kernel(T, plastic, plastic and yld is not None)
            self._p2g.append(wp.launch(
                k, g.count,
                inputs=[s.x[sl], s.v[sl], s.C[sl], s.F[sl], ljp, yld, T(g.mass), T(g.vol0), T(mat.mu), T(mat.lam),
                        *cc, T(SINGULAR_VALUE_FLOOR), self.dt, origin, inv_dx, dx, self.grid_m, self.grid_p,
                        self.edge_count[1:]],
                device=dev, record_cmd=True))
        self._grid = wp.launch(
            grid_update_kernel(T, has_walls), model.grid_shape,
            inputs=[self.grid_m, self.grid_p, self.dt, s.clock, V(*model.gravity), T(tc.gravity_ramp),
                    T(tc.damping), T(tc.damping_until if tc.damping > 0 else 0.0), T(model.mass_threshold),
                    origin, dx, model.walls_device, self.wall_impulse, self.vmax],
            device=dev, record_cmd=True)
        self._g2p = wp.launch(
            g2p_kernel(T), model.n_particles,
            inputs=[s.x, s.v, s.C, self.grid_p, self.dt, origin, inv_dx, dx, V(*model.x_lo), V(*model.x_hi),
                    self.edge_count],
            device=dev, record_cmd=True)
        self._end = wp.launch(end_step_kernel(), 1, inputs=[s.clock, s.steps], device=dev, record_cmd=True)
        self.use_graph = wp.get_device(dev).is_cuda if use_graph is None else use_graph
        self._graphs: dict[int, object] = {}
        #: recorded launches (``.launch()``) run at the start of every step, after the step size is set
        #: (e.g. a saw advancing through a weak layer); add them before the first call of :meth:`steps`.
        self.actions: list = []

    # ------------------------------------------------------------------ steps
    def _launch_step(self) -> None:
        self._begin.launch()
        for a in self.actions:
            a.launch()
        self.grid_m.zero_()
        self.grid_p.zero_()
        for k in self._p2g:
            k.launch()
        self._grid.launch()
        self._g2p.launch()
        self._end.launch()

    def steps(self, n: int) -> None:
        """Launch ``n`` steps without any host synchronisation.

        On CUDA with ``use_graph`` the batch is captured once per batch size and
        replayed; otherwise launches are eager. Both give the same answer.
        """
        if n <= 0:
            return
        if self.use_graph:
            graph = self._graphs.get(n)
            if graph is None:
                with wp.ScopedCapture(device=self.model.device) as cap:
                    for _ in range(n):
                        self._launch_step()
                graph = self._graphs[n] = cap.graph
            wp.capture_launch(graph)
        else:
            for _ in range(n):
                self._launch_step()

    def set_frame_end(self, t_end: float) -> None:
        """Set the time the coming steps must land on (s)."""
        c = self.state.clock.numpy()
        c[2] = t_end
        self.state.clock.assign(c)

    def clock(self) -> tuple[float, float, int]:
        """Host read of (t, last dt, steps) — a synchronisation point."""
        c = self.state.clock.numpy()
        return float(c[0]), float(c[1]), int(self.state.steps.numpy()[0])

    def take_wall_impulse(self) -> np.ndarray:
        """Impulse the material gave each wall since the last call (N s), then reset.

        Divided by the elapsed time it is the mean force on the wall (N).
        """
        if self.wall_impulse is None:
            return np.zeros((0, 3))
        imp = self.wall_impulse.numpy().astype(np.float64)
        self.wall_impulse.zero_()
        return imp
