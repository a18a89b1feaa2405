"""The MLS-MPM step: a plan of kernel launches built once per scene.

``Stepper.step()`` launches, in physical order: time-step choice, grid clear,
P2G (one launch per particle group, with the Cam-Clay return compiled in only
for plastic groups), grid update (wall code only when walls exist), G2P and
the clock update. No host read-back happens inside a step; on CUDA a batch of
steps is captured once as a graph and replayed.

The launches of each phase are recorded by :mod:`mpm_warp.step_phases`; this module
sizes the plan (threads and grid copies), runs it (on the CPU over threads that meet
between stages, on CUDA as graphs) and reads the clock and counters between batches.
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import warp as wp

from . import step_phases as phases
from .errors import InvalidArgument
from .kernels.fpmode import flush_kernels
from .kernels.types import vec
from .meeting import MeetingPoint
from .model import Model, State
from .step_profile import refuse_no_ops, stage_walls, timed

__all__ = ["Stepper", "default_threads", "grid_copies", "replay_captured"]


def default_threads(device: str, n_particles: int) -> int:
    """CPU threads for the step: all cores for large scenes, 1 on CUDA or below 20k particles."""
    if wp.get_device(device).is_cuda or n_particles < 20000:
        return 1
    env = os.environ.get("MPM_WARP_THREADS")
    if env:
        return max(1, int(env))
    return max(1, min(os.cpu_count() or 1, 64))


def grid_copies(device: str, n_particles: int, grid_shape, n_threads: int | None = None) -> int:
    """Threads of the CPU step, one grid copy each: :func:`default_threads` (or ``n_threads``), at most one per
    3 grid slabs along x and per 1000 particles; 1 on CUDA, whatever ``n_threads`` says."""
    if wp.get_device(device).is_cuda:
        return 1
    nt = n_threads or default_threads(device, n_particles)
    return max(1, min(nt, grid_shape[0] // 3, max(1, n_particles // 1000)))


def _no_wait() -> None:  # the meeting of a one-thread step: nothing to wait for
    pass


def replay_captured(owner, device, n: int) -> int:
    """Replay ``owner``'s captured CUDA graph of ``owner.graph_batch`` steps ``n // graph_batch`` times, capturing
    ``owner._launch_step`` that many times into ``owner._graph`` first when there is none; return the steps left
    to run eagerly (``n % graph_batch``)."""
    if owner._graph is None:
        with wp.ScopedCapture(device=device) as cap:
            for _ in range(owner.graph_batch):
                owner._launch_step()
        owner._graph = cap.graph
    for _ in range(n // owner.graph_batch):
        wp.capture_launch(owner._graph)
    return n % owner.graph_batch


class Stepper:
    """Launch plan for one model and state.

    On the CPU the step is split over ``n_threads`` Python threads, each with its own grid copy
    (docs/architecture.md, "The CPU step on several threads"). On CUDA there is one grid copy and
    one launch per stage.

    Parameters
    ----------
    model : Model
    state : State
    use_graph : bool or None
        Capture a batch of steps as a CUDA graph (default: on CUDA only).
    n_threads : int or None
        CPU threads (default :func:`default_threads`; ``MPM_WARP_THREADS`` overrides); ignored on CUDA.
    """

    def __init__(self, model: Model, state: State, use_graph: bool | None = None, n_threads: int | None = None):
        self.model = model
        self.state = state
        T = model.T
        dev = model.device
        dim = model.dim
        nt = self.n_threads = grid_copies(dev, model.n_particles, model.grid_shape, n_threads)
        gs = model.grid_shape
        # (flat buffers held by the recorded launches and the views below only, so the stepper's own arrays
        # count the grid once)
        grid = phases.step_grid(model, nt)
        #: per-thread grid copies (views of the flat buffers): nodal masses (kg) and momenta (kg m/s)
        self.grid_m_all = grid.m.reshape((nt, *gs))
        self.grid_p_all = grid.p.reshape((nt, *gs))
        #: summed nodal mass (kg) and, after the grid update, nodal velocity (m/s)
        self.grid_m = self.grid_m_all[0]
        self.grid_p = self.grid_p_all[0]
        self._grid_copies = grid.copies
        self.dt = wp.zeros(1, dtype=T, device=dev)
        self.vmax = wp.zeros(nt, dtype=T, device=dev)
        self.seed_vmax()
        # per thread: [particles clamped at the grid edge, particles skipped with a stencil outside the grid,
        #              singular-value floor events, inversions det F_tr <= 0]
        self.counts = wp.zeros((nt, 4), dtype=wp.int32, device=dev)
        # CPU: each thread steps with subnormal numbers flushed to zero, its own mode kept and put back after
        # (kernels/fpmode.py: round-off-sized strains otherwise cost the elastic P2G microcode assists)
        self._fp = []
        if not wp.get_device(dev).is_cuda:
            saved = wp.zeros(nt, dtype=wp.int32, device=dev)
            self._fp = [tuple(wp.launch(kern, 1, inputs=[saved, k], device=dev, record_cmd=True)
                              for kern in flush_kernels()) for k in range(nt)]
        nw = max(len(model.walls), 1)
        self.wall_impulses = wp.zeros((nt, nw), dtype=vec(dim, wp.float64), device=dev) if model.walls else None
        self.fixed_dt = model.scenario.time.dt
        s = state

        # the phases of the step, recorded in the order they run (mpm_warp.step_phases)
        self._begin = phases.begin_step_launch(model, s, self.vmax, self.dt, self.fixed_dt)
        # per thread k (one on CUDA): its P2G launches, grid-update slab and G2P range
        self._p2g = phases.p2g_launches(model, s, grid, self.dt, self.counts, nt)
        self._closure, self._closure_arrays = phases.closure_launches(model, s, self.dt)
        self._wall_state, wall_point, wall_velocity = phases.wall_state_launch(model, s, self.dt)
        # grid update by rows of nodes along the last axis: a whole row per thread on the CPU, a node on CUDA
        seg_len = 1 if wp.get_device(dev).is_cuda else gs[-1]
        self._grid = phases.grid_update_launches(model, s, grid, self.dt, nt, seg_len, wall_point, wall_velocity,
                                                 self.wall_impulses, self.vmax)
        self._g2p = phases.g2p_launches(model, s, grid, self.dt, self.counts, nt)
        self._columns, self.column_sums = phases.column_mean_launches(model, s)
        self._end = phases.end_step_launch(model, s)
        self.use_graph = wp.get_device(dev).is_cuda if use_graph is None else use_graph
        self._graph = None
        #: steps per captured CUDA graph (the driver asks for whole batches; steps past a frame end are no-ops)
        self.graph_batch = max(1, model.scenario.output.health_every)
        self._pool = ThreadPoolExecutor(nt - 1, thread_name_prefix="mpm_warp") if nt > 1 else None
        self._barrier = MeetingPoint(nt) if nt > 1 else None
        #: recorded launches (``.launch()``) run at the start of every step, after the step size is set
        #: (e.g. a saw advancing through a weak layer); add them before the first call of :meth:`steps`.
        self.actions: list = []

    @property
    def launches(self) -> list:
        """Every recorded launch of the plan (for compiling ahead of timing)."""
        walls = [self._wall_state] if self._wall_state is not None else []
        return [self._begin, *walls, *[k for ks in self._p2g for k in ks], *self._grid, *self._g2p,
                *self._columns, self._end, *[f for fs in self._fp for f in fs], *self.actions, *self._closure]

    @contextlib.contextmanager
    def flushed(self, k: int = 0):
        """Run the body with the calling thread (thread ``k`` of the step) flushing subnormals to zero, as the
        step's own threads do (kernels/fpmode.py; nothing on CUDA). For timing stages one by one."""
        if self._fp:
            self._fp[k][0].launch()
        try:
            yield
        finally:
            if self._fp:
                self._fp[k][1].launch()

    # ------------------------------------------------------------------ steps
    def _scatter(self, k: int) -> None:
        gm, gp = self._grid_copies[k]
        gm.zero_()
        gp.zero_()
        for launch in self._p2g[k]:
            launch.launch()

    def _before_scatter(self) -> None:
        """The serial launches before P2G: step size, then :meth:`_serial_before`."""
        self._begin.launch()
        self._serial_before()

    def _serial_before(self) -> None:
        """The serial launches between the step size and P2G: walls, actions (saw, monitors), interface closure."""
        if self._wall_state is not None:
            self._wall_state.launch()
        for a in self.actions:
            a.launch()
        for launch in self._closure:
            launch.launch()

    def _after_gather(self) -> None:
        """The serial launches after G2P: the bonded layers' column means and the clock."""
        for launch in self._columns:
            launch.launch()
        self._end.launch()

    def _thread_steps(self, k: int, n: int, record: list | None = None) -> None:
        """Thread ``k``'s part of ``n`` steps: the parallel stages, with thread 0 also running the serial ones.

        The threads meet (:class:`~mpm_warp.meeting.MeetingPoint`) after the serial launches, P2G, the grid
        update and G2P. With ``record`` each thread appends ``(k, stage, start, end)`` times (:meth:`profile`).
        """
        stages = (("p2g", lambda: self._scatter(k)), ("grid", self._grid[k].launch), ("g2p", self._g2p[k].launch))
        wait = self._barrier.wait if self._barrier is not None else _no_wait
        with self.flushed(k):
            for _ in range(n):
                if k == 0:
                    timed(record, k, "serial", self._before_scatter)
                wait()
                for name, run in stages:
                    timed(record, k, name, run)
                    wait()
                if k == 0:
                    timed(record, k, "serial", self._after_gather)

    def _team_steps(self, n: int, record: list | None = None) -> None:
        """``n`` steps on all threads: 1..n_threads-1 from the pool, thread 0 the caller (no hang on an error)."""
        if self._pool is None:
            self._thread_steps(0, n, record)
            return
        barrier = self._barrier
        barrier.reset()

        def guarded(k):
            try:
                self._thread_steps(k, n, record)
            except threading.BrokenBarrierError:
                pass  # another thread failed: its error is the one raised
            except BaseException:
                barrier.abort()
                raise

        futures = [self._pool.submit(guarded, k) for k in range(1, self.n_threads)]
        try:
            guarded(0)
        finally:
            for f in futures:
                f.result()
        if barrier.broken:
            raise RuntimeError("the CPU step's threads stopped at a broken barrier")

    def _launch_step(self) -> None:
        self._team_steps(1)

    # ------------------------------------------------- a step in two parts, for columns stepped together
    def choose_step(self) -> None:
        """The first part of a one-thread step: the step size, chosen as by :meth:`steps` (into the clock)."""
        self._begin.launch()

    def finish_step(self) -> None:
        """The rest of a one-thread step with the step size now in the clock (:mod:`mpm_warp.column_batch` sets
        one for many columns between the two parts): walls, actions, closure, P2G, grid, G2P, clock."""
        if self.n_threads != 1:
            raise InvalidArgument("n_threads", self.n_threads, "1 for a column stepped with others")
        self._serial_before()
        self._scatter(0)
        self._grid[0].launch()
        self._g2p[0].launch()
        self._after_gather()

    def profile(self, n: int) -> dict:
        """Wall seconds per step of each stage over ``n`` steps, on every thread (the CPU step's cost breakdown).

        Returns ``serial`` (thread 0's launches outside the parallel stages, per step), and for ``p2g``,
        ``grid`` and ``g2p``: ``wall`` (meeting to meeting on thread 0, synchronisation included) and
        ``busy`` (each thread's own launches): ``wall - max(busy)`` is the cost of the meeting and of the
        imbalance. The clock is advanced as by :meth:`steps`; one that meets the frame end raises (no-op steps).
        """
        refuse_no_ops(self.state.clock, "before")
        record: list = []
        t0 = time.perf_counter()
        self._team_steps(n, record)
        wall = time.perf_counter() - t0
        refuse_no_ops(self.state.clock, "during")
        return stage_walls(record, n, self.n_threads, wall)

    def steps(self, n: int) -> None:
        """Launch ``n`` steps without any host synchronisation.

        On CUDA with ``use_graph`` one graph of :attr:`graph_batch` steps is
        captured once and replayed ``n // graph_batch`` times; the remainder runs
        eagerly. Both give the same answer.
        """
        if n <= 0:
            return
        if self.use_graph:
            n = replay_captured(self, self.model.device, n)
        if n > 0:
            self._team_steps(n)

    def seed_vmax(self) -> None:
        """Set the speed bound of the next step from the particles' current speeds.

        The step size uses the largest nodal speed of the previous step; before
        the first step (or after loading a state) there is none, so the particle
        speeds stand in for it and a fast initial state gets a small first step.
        """
        v = self.state.v.numpy()
        vm = float(np.sqrt((v.astype(np.float64) ** 2).sum(axis=1)).max(initial=0.0))
        self.vmax.fill_(vm)

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
        """Impulse the material gave each wall since the last call (N s; N s/m in 2D), then reset.

        Divided by the elapsed time it is the mean force on the wall (N; N/m in 2D).
        """
        if self.wall_impulses is None:
            return np.zeros((0, self.model.dim))
        imp = self.wall_impulses.numpy().sum(axis=0)
        self.wall_impulses.zero_()
        return imp

    def edge_count(self) -> tuple[int, int]:
        """(particles clamped at the grid edge, particles skipped outside the grid) so far."""
        e = self.counts.numpy().sum(axis=0)
        return int(e[0]), int(e[1])

    def deformation_events(self) -> tuple[int, int]:
        """(singular-value floor events, inversions ``det F_tr <= 0``) counted by P2G so far."""
        e = self.counts.numpy().sum(axis=0)
        return int(e[2]), int(e[3])
