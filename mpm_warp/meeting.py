"""Where the CPU step's threads meet between its stages: a barrier that polls briefly before it sleeps.

A stage of a step lasts about a millisecond, so the first thread to finish waits well under that for the
others. ``threading.Barrier`` puts it to sleep at once, and the wake-up (a lock hand-off and the GIL) costs
a measurable part of a two-thread step (docs/architecture.md). :class:`MeetingPoint` polls instead,
yielding the GIL at each poll, for at most ``spin_s``; then it sleeps on a condition like the standard one.
It polls only when every party can have a core of its own, so an oversubscribed machine loses no CPU time.
"""

from __future__ import annotations

import os
import threading
import time

__all__ = ["MeetingPoint"]


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


class MeetingPoint:
    """A reusable barrier for ``parties`` threads, with ``abort`` and ``reset`` as ``threading.Barrier``'s.

    Parameters
    ----------
    parties : int
        Threads that meet.
    spin_s : float
        Longest poll before sleeping (s); 0 when there are more parties than cores.
    """

    def __init__(self, parties: int, spin_s: float = 2e-3):
        self.parties = parties
        self.spin_s = spin_s if parties <= _cores() else 0.0
        self._lock = threading.Lock()
        self._woken = threading.Condition(self._lock)
        self._count = 0
        self._generation = 0
        self._broken = False

    @property
    def broken(self) -> bool:
        """Whether :meth:`abort` was called since the last :meth:`reset`."""
        return self._broken

    def wait(self) -> None:
        """Return once all parties have called ``wait``; raise ``threading.BrokenBarrierError`` if aborted."""
        with self._lock:
            if self._broken:
                raise threading.BrokenBarrierError
            generation = self._generation
            self._count += 1
            if self._count == self.parties:
                self._count = 0
                self._generation += 1
                self._woken.notify_all()
                return
        deadline = time.perf_counter() + self.spin_s
        while self._generation == generation and not self._broken and time.perf_counter() < deadline:
            time.sleep(0)  # yields the GIL to the threads still launching
        with self._lock:
            while self._generation == generation and not self._broken:
                self._woken.wait()
            if self._generation == generation:
                raise threading.BrokenBarrierError

    def abort(self) -> None:
        """Break the barrier: every thread waiting, or coming to wait, raises ``BrokenBarrierError``."""
        with self._lock:
            self._broken = True
            self._woken.notify_all()

    def reset(self) -> None:
        """Mend a broken barrier for the next batch of steps (no thread may be waiting)."""
        with self._lock:
            self._broken = False
            self._count = 0
