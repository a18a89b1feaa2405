"""A scenario on a device: its model, state and stepper, its monitors, stepping to a time, and its state in and out.

Data flows one way: scenario -> model/state -> stepper (kernels) -> output.
The host touches the device only between batches of steps (clock and health
flags, a few bytes) and at frames (output fields). The frame-by-frame run into a
run file is :mod:`mpm_warp.run_loop`; snapshots and restores are :mod:`mpm_warp.snapshot`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import warp as wp

from . import checks, frames, run_loop, snapshot
from .config import Scenario
from .device import resolve_device
from .errors import InvalidArgument, SimulationBlowUp
from .health import MAX_CELLS_PER_STEP, MIN_DT_SHARE, check_health  # noqa: F401
from .kernels.diagnostics import INT_MAX, energy_kernel, health_kernel, health_zz_kernel, stress_kernel  # noqa: F401
from .measures import ParticleMeasures
from .memory import check_memory
from .model import Model, ParticleGroup, State
from .monitor import GroupState, Monitor
from .result import RunResult
from .step import Stepper

__all__ = ["Simulation"]
# MAX_CELLS_PER_STEP and the diagnostics kernels (the health check is in .health, the energies and stresses in
# .measures) stay importable from here


class Simulation:
    """A scenario instantiated on a device.

    Parameters
    ----------
    scenario : Scenario
        Validated scenario (``Scenario.validate()`` is called again here).
    device : str or None
        ``"cpu"``, ``"cuda"``, ``"cuda:N"`` or None (``MPM_WARP_DEVICE``, then CUDA if present).
    use_graph : bool or None
        CUDA graph capture of step batches (default on CUDA).
    n_threads : int or None
        CPU threads for the step (default: all cores for scenes of 20k particles
        or more; ``MPM_WARP_THREADS`` overrides). Results depend on the thread
        count at round-off level only (the order grid copies are summed in). Ignored on CUDA.
    max_memory : int, str or None
        Refuse a scenario whose memory estimate exceeds this (bytes, or e.g. ``"16G"``); the
        machine's available memory is always a limit (:func:`mpm_warp.memory.check_memory`).

    A snow scene's saw, push and diagnostics are its monitor, attached by :func:`mpm_warp.run`.

    Examples
    --------
    >>> sim = Simulation(load_scenario("elastic_block"))          # doctest: +SKIP
    >>> result = sim.run("out.h5")                                # doctest: +SKIP
    """

    def __init__(self, scenario: Scenario, device: str | None = None, use_graph: bool | None = None,
                 n_threads: int | None = None, max_memory=None):
        if not isinstance(scenario, Scenario):
            raise InvalidArgument("scenario", scenario if isinstance(scenario, str) else type(scenario).__name__,
                                  "a Scenario (mpm_warp.load_scenario(file or scene name); mpm_warp.run takes "
                                  "names and files directly)")
        if use_graph is not None:
            checks.flag("use_graph", use_graph)
        if n_threads is not None:
            checks.positive_int("n_threads", n_threads, lo=1, hi=1024)
        self.scenario = scenario.validate()
        self.device = resolve_device(device)
        #: the memory estimate, checked before anything is allocated
        self.memory = check_memory(self.scenario, self.device, n_threads, max_memory)
        self.model = Model(self.scenario, self.device)
        fields_ = self.scenario.output.fields
        self.state: State = self.model.initial_state(track_yield="yielded" in fields_)
        self.stepper = Stepper(self.model, self.state, use_graph, n_threads)
        self.frame_index = 0
        self.x0 = self.state.x.numpy().astype(np.float64)
        #: monitors by name (:meth:`add_monitor`)
        self.monitors: dict[str, Monitor] = {}
        self._since_health = 0
        self._bad = wp.full(3, INT_MAX, dtype=wp.int32, device=self.device)
        #: energies and stresses of the particles (:mod:`mpm_warp.measures`)
        self._measures = ParticleMeasures(self.model, self.state)
        self._stop_now = False
        #: identity of the run file this simulation writes (:func:`mpm_warp.frames.new_run_id`), in its checkpoints
        self.run_id: str | None = None

    # ----------------------------------------------------------------- public
    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return float(self.state.clock.numpy()[0])

    @property
    def clock(self) -> wp.array:
        """Device clock ``[t, dt, t_end, dt_last]`` (float64, s), read by device actions."""
        return self.state.clock

    def add_monitor(self, monitor: Monitor) -> Monitor:
        """Attach a monitor (:mod:`mpm_warp.monitor`): its actions run every step from the next one on."""
        if not isinstance(monitor, Monitor):
            raise InvalidArgument("monitor", type(monitor).__name__, "an mpm_warp.monitor.Monitor")
        if monitor.name in self.monitors:
            raise InvalidArgument("monitor.name", monitor.name, f"a name not in use (used: {sorted(self.monitors)})")
        self.monitors[monitor.name] = monitor
        self.stepper.actions.extend(monitor.actions())
        return monitor

    def group(self, name: str) -> ParticleGroup:
        """The particle group (range, material, mass) of the block named ``name``."""
        for g in self.model.groups:
            if g.name == name:
                return g
        raise InvalidArgument("group", name, "one of " + ", ".join(repr(g.name) for g in self.model.groups))

    def group_state(self, name: str) -> GroupState:
        """Array views of the state of group ``name`` (:class:`mpm_warp.monitor.GroupState`)."""
        g, s = self.group(name), self.state
        sl = slice(g.start, g.end)
        psl = slice(g.plastic_start, g.plastic_start + g.count)
        plastic = g.plastic_start >= 0
        return GroupState(g.name, g.material, g.start, g.end, g.mass, g.vol0, s.x[sl], s.v[sl], s.C[sl], s.H[sl],
                          s.hzz[psl] if plastic and s.hzz is not None else None, s.log_jp[psl] if plastic else None,
                          self.x0[sl], s.kappa[g.kappa_start:g.kappa_start + g.count] if g.kappa_start >= 0 else None)

    def energies(self) -> dict[str, float]:
        """Kinetic and elastic energy (J; J/m of depth in 2D) of the current state."""
        return self._measures.energies()

    def stresses(self, cauchy: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Pressure p and Mises stress q (Pa, Kirchhoff, compression positive) of every particle and,
        with ``cauchy``, the Cauchy stress tensor (N, 3, 3) (Pa, tension positive; plane strain: in-plane
        block and ``sigma_zz``)."""
        return self._measures.stresses(cauchy)

    def stress_invariants(self) -> tuple[np.ndarray, np.ndarray]:
        """Pressure p and Mises stress q (Pa, Kirchhoff, compression positive) of every particle."""
        p, q, _ = self.stresses()
        return p, q

    def particle_field(self, name: str) -> np.ndarray:
        """Host copy of one output field for all particles (:func:`mpm_warp.frames.particle_field`)."""
        return frames.particle_field(self, name)

    def health(self) -> None:
        """Run the device health check (:func:`mpm_warp.health.check_health`); raise SimulationBlowUp on failure."""
        check_health(self, self._bad)

    def step_to(self, t_end: float, health_every: int | None = None) -> int:
        """Advance to ``t_end`` (s) exactly; return the steps taken.

        Steps run in batches sized from the current step size; between batches
        the host reads the clock and (every ``health_every`` steps) the health flags.
        """
        t_end = checks.finite_number("t_end", t_end, lo=0.0)
        he = health_every or self.scenario.output.health_every
        self.stepper.set_frame_end(t_end)
        t, dt, steps0 = self.stepper.clock()
        taken = 0
        dt_floor = MIN_DT_SHARE * self._first_dt()     # below it the state has diverged (mpm_warp.health)
        while t < t_end * (1 - 1e-12) - 1e-15:
            if dt <= 0:
                dt = self._first_dt()
            n = max(1, min(he, int(math.ceil((t_end - t) / dt))))
            if self.stepper.use_graph:
                n = self.stepper.graph_batch  # one captured graph; the steps past t_end are no-ops (dt = 0)
            self.stepper.steps(n)
            t_before = t
            t, dt_new, steps = self.stepper.clock()
            taken = steps - steps0
            self._since_health += n
            if self._since_health >= he:
                self.health()
                self._since_health = 0
            if t < t_end * (1 - 1e-12) - 1e-15 and (t == t_before or not dt_new >= dt_floor):
                raise SimulationBlowUp(steps, -1, "dt", (
                    f"the time step fell to {dt_new:.3g} s at t = {t:.6g} s, below {MIN_DT_SHARE:g} of the elastic "
                    f"step ({dt_floor / MIN_DT_SHARE:.3g} s): the largest nodal speed is not finite or beyond any "
                    "physical one (the state diverged)"))
            dt = dt_new if dt_new > 0 else dt
            if self._stop_now:
                break
        return taken

    def request_stop(self) -> None:
        """Make a running :meth:`run` stop after its current batch of steps (at most ``output.health_every``),
        mid-frame, with a checkpoint that resumes exactly; safe to call from a signal handler."""
        self._stop_now = True

    def _first_dt(self) -> float:
        tc = self.scenario.time
        if tc.dt > 0:
            return tc.dt
        d = tc.cfl * self.model.dx / self.model.c_p
        return min(d, tc.dt_max) if tc.dt_max > 0 else d

    # -------------------------------------------------------------------- run
    def run(self, output: str | None = None, end_time: float | None = None, frame_interval: float | None = None,
            callback: Callable[[Simulation, int], bool | None] | None = None, append: bool = False,
            overwrite: bool = False) -> RunResult:
        """Run to ``end_time`` writing a frame every ``frame_interval``.

        Parameters
        ----------
        output : str, os.PathLike or None
            HDF5 path; None runs without output. It is checked (:func:`mpm_warp.io.check_output_file`) and
            locked (:func:`mpm_warp.io.output_lock`) before anything else.
        end_time, frame_interval : float or None
            Override the scenario's ``time.end`` / ``time.frame_interval`` (s); checked as they are (finite,
            > 0, at most :data:`~mpm_warp.config.MAX_STEPS` steps; a frame interval at most the end time).
        callback : callable or None
            ``callback(sim, frame)`` after every frame; returning False stops the run.
        append : bool
            Continue an existing output (used by :func:`resume`): its frames are all kept, those after
            the checkpoint are stepped over again without being rewritten.
        overwrite : bool
            Replace an existing ``output`` (a regular file only).

        A second call continues from where the first stopped (``end_time`` beyond it) without output;
        with one it is refused (a run file starts at the initial state; :func:`~mpm_warp.resume` it).
        """
        return run_loop.run_frames(self, output, end_time, frame_interval, callback, append, overwrite)

    # ----------------------------------------------------------------- state
    def snapshot(self) -> tuple[dict[str, np.ndarray], dict]:
        """The whole state of the run in memory (:func:`mpm_warp.snapshot.take_snapshot`): what a checkpoint holds."""
        return snapshot.take_snapshot(self)

    def load_snapshot(self, arrays: dict[str, np.ndarray], meta: dict) -> None:
        """Continue from a :meth:`snapshot` (:func:`mpm_warp.snapshot.load_snapshot`); e.g. a fork."""
        snapshot.load_snapshot(self, arrays, meta)

    def restore(self, output: str) -> None:
        """Load the last checkpoint of the run file ``output`` (:func:`mpm_warp.snapshot.restore_run`).

        Attach the same monitors first (their state is restored into them); on the CPU the run then
        continues bit for bit as if never stopped.
        """
        snapshot.restore_run(self, output)
