"""Running a scenario: frames, output, health checks, checkpoints and resume.

Data flows one way: scenario -> model/state -> stepper (kernels) -> output.
The host touches the device only between batches of steps (clock and health
flags, a few bytes) and at frames (output fields).
"""

from __future__ import annotations

import logging
import math
import time as _time
from collections.abc import Callable

import numpy as np
import warp as wp

from . import checks, frames, io, snapshot
from .config import Scenario
from .device import resolve_device
from .errors import InvalidArgument, MPMError, SimulationBlowUp
from .health import MAX_CELLS_PER_STEP, MIN_DT_SHARE, check_health  # noqa: F401
from .kernels.diagnostics import INT_MAX, energy_kernel, health_kernel, health_zz_kernel, stress_kernel  # noqa: F401
from .memory import check_memory
from .model import Model, ParticleGroup, State, material_params
from .monitor import GroupState, Monitor
from .result import RunResult
from .step import Stepper
from .time_step import run_times

__all__ = ["Simulation"]
# MAX_CELLS_PER_STEP and the health kernels (the health check is in .health) stay importable from here


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
        self._energy = wp.zeros(2, dtype=wp.float64, device=self.device)
        self._no_log_jp = wp.zeros(0, dtype=self.model.T, device=self.device)  # elastic groups: no plastic volume
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

    def _hzz_of(self, g) -> wp.array:
        """``hzz`` of group ``g``'s particles, or an empty array (elastic or 3D: ``F_E,zz`` not stored)."""
        s = self.state
        if s.hzz is None or g.plastic_start < 0:
            return self._no_log_jp
        return s.hzz[g.plastic_start:g.plastic_start + g.count]

    def _kappa_of_cracking(self, g) -> wp.array:
        """``kappa`` of a cracking group's particles (their softened stress), else an empty array."""
        if g.material.model != "tensile_cracking":
            return self._no_log_jp
        return self.state.kappa[g.kappa_start:g.kappa_start + g.count]

    def energies(self) -> dict[str, float]:
        """Kinetic and elastic energy (J; J/m of depth in 2D) of the current state."""
        self._energy.zero_()
        T = self.model.T
        s = self.state
        for g in self.model.groups:
            sl = slice(g.start, g.end)
            hz = self._hzz_of(g)
            wp.launch(energy_kernel(self.model.dim, T), g.count,
                      inputs=[s.v[sl], s.H[sl], hz, self._kappa_of_cracking(g), T(g.mass), T(g.vol0),
                              material_params(g.material, T), self._energy], device=self.device)
        e = self._energy.numpy()
        return {"kinetic_energy": float(e[0]), "elastic_energy": float(e[1])}

    def stresses(self, cauchy: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Pressure p and Mises stress q (Pa, Kirchhoff, compression positive) of every particle and,
        with ``cauchy``, the Cauchy stress tensor (N, 3, 3) (Pa, tension positive; plane strain: in-plane
        block and ``sigma_zz``)."""
        T = self.model.T
        n = self.model.n_particles
        s = self.state
        p = wp.zeros(n, dtype=T, device=self.device)
        q = wp.zeros(n, dtype=T, device=self.device)
        sig = wp.zeros(n, dtype=wp.types.matrix((3, 3), T), device=self.device) if cauchy else None
        for g in self.model.groups:
            sl = slice(g.start, g.end)
            hz = self._hzz_of(g)
            ljp = s.log_jp[g.plastic_start:g.plastic_start + g.count] if g.plastic_start >= 0 else self._no_log_jp
            wp.launch(stress_kernel(self.model.dim, T), g.count,
                      inputs=[s.H[sl], hz, ljp, self._kappa_of_cracking(g), material_params(g.material, T), int(cauchy),
                              p[sl], q[sl], sig[sl] if cauchy else None],
                      device=self.device)
        return p.numpy(), q.numpy(), sig.numpy() if cauchy else None

    def stress_invariants(self) -> tuple[np.ndarray, np.ndarray]:
        """Pressure p and Mises stress q (Pa, Kirchhoff, compression positive) of every particle."""
        p, q, _ = self.stresses()
        return p, q

    def particle_field(self, name: str) -> np.ndarray:
        """Host copy of one output field for all particles (:func:`mpm_warp.frames.particle_field`)."""
        return frames.particle_field(self, name)

    def _store_outcome(self, writer) -> None:
        """The monitors' ``outcome()`` records into the run file's ``outcome`` attribute (a failure there is logged:
        the frames are safe and the result carries the outcome too)."""
        outcomes = {n: m.outcome() for n, m in self.monitors.items() if callable(getattr(m, "outcome", None))}
        if not outcomes or getattr(writer, "_failed", False):
            return
        try:
            writer.set_outcome(outcomes)
        except (OSError, MPMError) as e:
            logging.getLogger("mpm_warp").warning(f"{writer.path}: the outcome attribute was not stored ({e})")

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
        output = checks.file_path("output", output, none=True)
        end, fi = run_times(self.scenario, end_time, frame_interval)
        callback = checks.optional_callable("callback", callback)
        append, overwrite = checks.flag("append", append), checks.flag("overwrite", overwrite)
        if not append and self.time > 0.0:
            if output is not None:
                raise InvalidArgument("output", output, f"None: this Simulation has run to t = {self.time:.6g} s "
                                      "already, and a run file starts at the initial state (make a new Simulation, "
                                      "or mpm_warp.resume the file it wrote)")
            if end <= self.time * (1 + 1e-12):
                raise InvalidArgument("end_time", end_time, f"a time after t = {self.time:.6g} s, where this "
                                      "Simulation stopped (a second run continues from there)")
        if output is None:
            return self._run(None, end, fi, callback, append)
        output = io.check_output_file(output, overwrite=overwrite, append=append)
        with io.output_lock(output):
            try:
                return self._run(output, end, fi, callback, append)
            except io.OutOfSpace as e:   # the complete frames and the checkpoint say how to go on
                raise frames.out_of_space(e, output) from None

    def _run(self, output, end, fi, callback, append) -> RunResult:
        writer = None
        ckpt = io.checkpoint_path_for(output) if output else None
        n_frames_total = int(math.ceil(end / fi - 1e-9))
        if output:
            if append:
                # every frame is kept (restore() read them all): those after the checkpoint are stepped over
                writer = io.RunWriter.reopen(output, verify=False)
            else:
                self.run_id = frames.new_run_id()
                writer = frames.open_writer(self, output)
        elif not append:
            frames.frame_diagnostics(self)
        if not append:
            self._last_frame_time = self.time
        steps_total = 0
        n_done = 0
        wall = 0.0
        edge0 = self.stepper.edge_count()[0]
        events0 = self.stepper.deformation_events()
        stopped = False
        try:
            if writer is not None and not append:
                frames.write_frame(self, writer)
                self._checkpoint(ckpt)
            self._compile()   # warm up: compile every kernel before timing
            while self.frame_index < n_frames_total:
                t_next = min((self.frame_index + 1) * fi, end)
                t0 = _time.perf_counter()
                steps_total += self.step_to(t_next)
                wp.synchronize_device(self.device)
                wall += _time.perf_counter() - t0
                if self._stop_now and self.time < t_next * (1 - 1e-12) - 1e-15:   # stopped mid-frame
                    self.health()
                    self._checkpoint(ckpt)
                    stopped = True
                    break
                self.frame_index += 1
                n_done += 1
                self.health()  # never write a bad state into a frame or a checkpoint
                self._since_health = 0
                if writer is not None:
                    if self.frame_index < writer.n_frames:   # on file already (after the checkpoint): kept
                        frames.frame_record(self)
                    else:
                        frames.write_frame(self, writer)
                    ce = self.scenario.output.checkpoint_every
                    if ce and self.frame_index % ce == 0:
                        self._checkpoint(ckpt)
                else:
                    frames.frame_diagnostics(self)
                if (callback is not None and callback(self, self.frame_index) is False) or self._stop_now:
                    if writer is not None:
                        self._checkpoint(ckpt)  # a stop on request can be resumed from exactly here
                    stopped = True
                    break
        except SimulationBlowUp as e:
            e.output = output
            e.checkpoint = ckpt if ckpt and io.checkpoint_is_intact(ckpt) else None
            e.args = (str(SimulationBlowUp(e.step, e.particle, e.field, e.cause, e.checkpoint, e.output)),)
            raise
        finally:
            self._stop_now = False
            if writer is not None:
                try:
                    self._store_outcome(writer)
                finally:
                    writer.close()
        n = self.model.n_particles
        result = {}
        for m in self.monitors.values():
            result.update(m.result())
        floors, inversions = (a - b for a, b in zip(self.stepper.deformation_events(), events0, strict=True))
        return RunResult(output, steps_total, n_done, self.time, wall, n * steps_total / wall if wall > 0 else 0.0,
                         n, self.device, self.stepper.edge_count()[0] - edge0, result, dict(self.monitors),
                         floors, inversions, stopped)

    def _compile(self) -> None:
        """Load every kernel of the plan (compiling on first use) without stepping."""
        for m in {k.kernel.module for k in self.stepper.launches}:
            m.load(wp.get_device(self.device))

    # ----------------------------------------------------------------- state
    def snapshot(self) -> tuple[dict[str, np.ndarray], dict]:
        """The whole state of the run in memory (:func:`mpm_warp.snapshot.take_snapshot`): what a checkpoint holds."""
        return snapshot.take_snapshot(self)

    def load_snapshot(self, arrays: dict[str, np.ndarray], meta: dict) -> None:
        """Continue from a :meth:`snapshot` (:func:`mpm_warp.snapshot.load_snapshot`); e.g. a fork."""
        snapshot.load_snapshot(self, arrays, meta)

    def _checkpoint(self, path: str | None) -> None:
        if path is not None:
            io.write_checkpoint(path, *self.snapshot())

    def restore(self, output: str) -> None:
        """Load the last checkpoint of the run file ``output`` (:func:`mpm_warp.snapshot.restore_run`).

        Attach the same monitors first (their state is restored into them); on the CPU the run then
        continues bit for bit as if never stopped.
        """
        snapshot.restore_run(self, output)
