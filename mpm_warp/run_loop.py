"""The run loop: a simulation stepped frame by frame into its run file, with checkpoints and stops.

:func:`run_frames` is :meth:`mpm_warp.simulation.Simulation.run`: it checks the times and the output,
locks the file, writes the initial frame and checkpoint, then steps to each frame time
(:meth:`~mpm_warp.simulation.Simulation.step_to`), checks health before every frame it writes,
writes checkpoints at ``output.checkpoint_every`` and on a stop, stores the monitors' outcome and
returns the :class:`~mpm_warp.result.RunResult`. Frames are written by :mod:`mpm_warp.frames`, the
state a checkpoint holds is taken by :mod:`mpm_warp.snapshot`.
"""

from __future__ import annotations

import logging
import math
import time as _time

import warp as wp

from . import checks, frames, io
from .errors import InvalidArgument, MPMError, SimulationBlowUp
from .result import RunResult
from .time_step import run_times

__all__ = ["run_frames", "FrameRun"]


def run_frames(sim, output=None, end_time=None, frame_interval=None, callback=None, append=False,
               overwrite=False) -> RunResult:
    """Run ``sim`` (a :class:`~mpm_warp.simulation.Simulation`) to ``end_time`` writing a frame every
    ``frame_interval`` (:meth:`Simulation.run <mpm_warp.simulation.Simulation.run>` says what each argument is)."""
    output = checks.file_path("output", output, none=True)
    end, fi = run_times(sim.scenario, end_time, frame_interval)
    callback = checks.optional_callable("callback", callback)
    append, overwrite = checks.flag("append", append), checks.flag("overwrite", overwrite)
    if not append and sim.time > 0.0:
        if output is not None:
            raise InvalidArgument("output", output, f"None: this Simulation has run to t = {sim.time:.6g} s "
                                  "already, and a run file starts at the initial state (make a new Simulation, "
                                  "or mpm_warp.resume the file it wrote)")
        if end <= sim.time * (1 + 1e-12):
            raise InvalidArgument("end_time", end_time, f"a time after t = {sim.time:.6g} s, where this "
                                  "Simulation stopped (a second run continues from there)")
    if output is None:
        return _run(sim, None, end, fi, callback, append)
    output = io.check_output_file(output, overwrite=overwrite, append=append)
    with io.output_lock(output):
        try:
            return _run(sim, output, end, fi, callback, append)
        except io.OutOfSpace as e:   # the complete frames and the checkpoint say how to go on
            raise frames.out_of_space(e, output) from None


def _run(sim, output, end, fi, callback, append) -> RunResult:
    frames_ = FrameRun(sim, output, end, fi, callback, append)
    try:
        frames_.open()
        while frames_.running:
            t0 = _time.perf_counter()
            steps = sim.step_to(frames_.next_time)
            wp.synchronize_device(sim.device)
            frames_.reached(steps, _time.perf_counter() - t0)
    except SimulationBlowUp as e:
        frames_.blew_up(e)
        raise
    finally:
        frames_.close()
    return frames_.result()


class FrameRun:
    """One simulation's frames, checkpoints, stops and result, however it is stepped: by its own
    :meth:`~mpm_warp.simulation.Simulation.step_to` (:func:`run_frames`) or beside other columns
    (:mod:`mpm_warp.column_batch`).

    :meth:`open` writes the initial frame and checkpoint; after each stepping to :attr:`next_time`,
    :meth:`reached` checks health, writes the frame and asks the callback; :meth:`close` stores the
    monitors' outcome and closes the file; :meth:`result` is the run's :class:`~mpm_warp.result.RunResult`.
    """

    def __init__(self, sim, output, end: float, fi: float, callback, append: bool):
        self.sim, self.output, self.end, self.fi, self.callback, self.append = sim, output, end, fi, callback, append
        self.writer = None
        #: series the monitors record that a resumed run file (an older release's) does not hold
        self.left_out: frozenset = frozenset()
        self.ckpt = io.checkpoint_path_for(output) if output else None
        self.n_frames_total = int(math.ceil(end / fi - 1e-9))
        self.steps_total, self.n_done, self.wall, self.stopped = 0, 0, 0.0, False
        self._edge0 = sim.stepper.edge_count()[0]
        self._events0 = sim.stepper.deformation_events()

    @property
    def next_time(self) -> float:
        """The time of the next frame (s)."""
        return min((self.sim.frame_index + 1) * self.fi, self.end)

    @property
    def running(self) -> bool:
        """Whether frames remain and nothing has stopped the run."""
        return not self.stopped and self.sim.frame_index < self.n_frames_total

    def open(self) -> None:
        """The run file (new, or reopened to append), its initial frame and checkpoint; every kernel compiled."""
        sim, output = self.sim, self.output
        if output:
            if self.append:
                # every frame is kept (restore() read them all): those after the checkpoint are stepped over
                self.writer = io.RunWriter.reopen(output, verify=False)
                self.left_out = frozenset(frames.series_units(sim)) - frozenset(self.writer.scalar_series)
                if self.left_out:
                    logging.getLogger("mpm_warp").warning(
                        f"{output}: written by an older release without the series {sorted(self.left_out)}; the "
                        "resumed run records the series the file holds")
            else:
                sim.run_id = frames.new_run_id()
                self.writer = frames.open_writer(sim, output)
        elif not self.append:
            frames.frame_diagnostics(sim)
        if not self.append:
            sim._last_frame_time = sim.time
        if self.writer is not None and not self.append:
            frames.write_frame(sim, self.writer)
            _checkpoint(sim, self.ckpt)
        _compile(sim)   # warm up: compile every kernel before timing

    def reached(self, steps: int, wall: float) -> None:
        """After ``steps`` steps (``wall`` s) towards :attr:`next_time`: the frame (health checked first),
        the checkpoint it is due, and the callback; a stop on request mid-frame checkpoints where it is."""
        sim, writer = self.sim, self.writer
        t_next = self.next_time
        self.steps_total += steps
        self.wall += wall
        if sim._stop_now and sim.time < t_next * (1 - 1e-12) - 1e-15:   # stopped mid-frame
            sim.health()
            _checkpoint(sim, self.ckpt)
            self.stopped = True
            return
        sim.frame_index += 1
        self.n_done += 1
        sim.health()  # never write a bad state into a frame or a checkpoint
        sim._since_health = 0
        if writer is not None:
            if sim.frame_index < writer.n_frames:   # on file already (after the checkpoint): kept
                frames.frame_record(sim)
            else:
                frames.write_frame(sim, writer, self.left_out)
            ce = sim.scenario.output.checkpoint_every
            if ce and sim.frame_index % ce == 0:
                _checkpoint(sim, self.ckpt)
        else:
            frames.frame_diagnostics(sim)
        if (self.callback is not None and self.callback(sim, sim.frame_index) is False) or sim._stop_now:
            if writer is not None:
                _checkpoint(sim, self.ckpt)  # a stop on request can be resumed from exactly here
            self.stopped = True

    def blew_up(self, e: SimulationBlowUp) -> None:
        """Name the run file and its last intact checkpoint in the blow-up ``e``."""
        e.output = self.output
        e.checkpoint = self.ckpt if self.ckpt and io.checkpoint_is_intact(self.ckpt) else None
        e.args = (str(SimulationBlowUp(e.step, e.particle, e.field, e.cause, e.checkpoint, e.output)),)

    def close(self) -> None:
        """The monitors' outcome into the run file, and the file closed (also after an error)."""
        self.sim._stop_now = False
        if self.writer is not None:
            try:
                _store_outcome(self.sim, self.writer)
            finally:
                self.writer.close()
                self.writer = None

    def result(self) -> RunResult:
        """What the run did (:class:`~mpm_warp.result.RunResult`)."""
        sim = self.sim
        n = sim.model.n_particles
        result = {}
        for m in sim.monitors.values():
            result.update(m.result())
        floors, inversions = (a - b for a, b in zip(sim.stepper.deformation_events(), self._events0, strict=True))
        rate = n * self.steps_total / self.wall if self.wall > 0 else 0.0
        return RunResult(self.output, self.steps_total, self.n_done, sim.time, self.wall, rate, n, sim.device,
                         sim.stepper.edge_count()[0] - self._edge0, result, dict(sim.monitors), floors, inversions,
                         self.stopped)


def _checkpoint(sim, path: str | None) -> None:
    """Write the checkpoint of ``sim`` to ``path`` (none for a run without output)."""
    if path is not None:
        io.write_checkpoint(path, *sim.snapshot())


def _compile(sim) -> None:
    """Load every kernel of the plan (compiling on first use) without stepping."""
    for m in {k.kernel.module for k in sim.stepper.launches}:
        m.load(wp.get_device(sim.device))


def _store_outcome(sim, writer) -> None:
    """The monitors' ``outcome()`` records into the run file's ``outcome`` attribute (a failure there is logged:
    the frames are safe and the result carries the outcome too)."""
    outcomes = {n: m.outcome() for n, m in sim.monitors.items() if callable(getattr(m, "outcome", None))}
    if not outcomes or getattr(writer, "_failed", False):
        return
    try:
        writer.set_outcome(outcomes)
    except (OSError, MPMError) as e:
        logging.getLogger("mpm_warp").warning(f"{writer.path}: the outcome attribute was not stored ({e})")
