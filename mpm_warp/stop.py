"""Stopping a command-line run on SIGINT/SIGTERM: with a checkpoint once it steps, at once before it does."""

from __future__ import annotations

import math
import signal
import sys
import time

__all__ = ["StopRequest", "Interrupted"]


class Interrupted(KeyboardInterrupt):
    """A signal that ends the command at once; ``signum`` (the exit status is 128 + signum)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


class StopRequest:
    """SIGINT/SIGTERM handler: stop the run with a checkpoint, never an unbounded wait.

    Python may swallow a KeyboardInterrupt raised inside a callback, so the CLI catches the
    signals itself. Before the simulation exists (reading the scenario, building the scene) a
    signal ends the command at once (:class:`Interrupted`: nothing to checkpoint yet). Once it
    runs, a first signal lets the current frame finish when it is due within :attr:`far_s`
    seconds of wall time (judged from the last frame's duration); otherwise, and on a second
    signal, the simulation stops after its current batch of steps
    (:meth:`mpm_warp.Simulation.request_stop`) with a checkpoint that resumes exactly. A third
    signal aborts at once (complete frames are kept).
    """

    def __init__(self, far_s: float = 2.0):
        self.far_s = far_s
        self.requested = False
        self.signals = 0
        self.sim = None
        self._now = False
        self._frame_start = time.perf_counter()
        self._frame_wall = None
        self._old = {}

    def __enter__(self):
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)

    def attach(self, sim) -> None:
        """The simulation to stop (a stop asked for before it existed applies now)."""
        self.sim = sim
        self._frame_start = time.perf_counter()
        if self._now:
            sim.request_stop()

    def frame_done(self) -> None:
        now = time.perf_counter()
        self._frame_wall, self._frame_start = now - self._frame_start, now

    def frame_due_in(self) -> float:
        """Wall seconds until the current frame is expected to end (inf before a first frame)."""
        if self._frame_wall is None:
            return math.inf
        return max(0.0, self._frame_wall - (time.perf_counter() - self._frame_start))

    def _handle(self, signum, frame):
        self.signals += 1
        if self.sim is None:                   # not stepping yet: nothing to finish or checkpoint
            raise Interrupted(signum)
        if self.signals >= 3:
            raise Interrupted(signum)
        self.requested = True
        if self.signals == 1 and self.frame_due_in() <= self.far_s:
            sys.stderr.write("\nmpm-warp: stop requested; finishing the current frame (signal again to stop "
                             "sooner)\n")
            return
        self._now = True
        if self.sim is not None:
            self.sim.request_stop()
        sys.stderr.write("\nmpm-warp: stop requested; stopping after the current batch of steps with a checkpoint "
                         "(signal again to abort at once)\n")
