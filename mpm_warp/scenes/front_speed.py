"""Front speeds that cannot outrun sound (pure NumPy): damage ahead of the front, and local speeds only where the
front advanced contiguously.

A crack front in a weak layer moves at most at the P-wave speed ``c_p`` of the slab over it (no signal in the
system is faster). A front that seems faster did not travel: the layer ahead of it failed by itself (damage
nucleating at the far end's free edge, or a stretch of the layer failing at once), and the contiguous front
merely connected to it. Dividing the distance by the small time it took gives 10^2-10^15 m/s, which is not a
speed. Here:

- :func:`damage_ahead` finds, from the bins' own arrival times, the blocks damaged while not connected to the
  contiguous front (position, time, extent, how far the front was);
- :func:`path_jumps` finds, from the front's path alone (as a results file stores it), the stretches the front
  crossed faster than ``c_max``: damage that was there before the front;
- :func:`window_speeds` fits the local speed over sliding windows and reports a speed only where the front
  advanced contiguously; a window faster than ``c_max`` or holding a block of damage ahead is marked
  :data:`NUCLEATION` and carries no speed.

Conventions as in :mod:`mpm_warp.scenes.fronts`: ``s`` in m from the cut end, times in s, speeds in m/s.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .fronts import front_trajectory, line_fit

__all__ = ["NUCLEATION", "CONTIGUOUS", "NOT_CROSSED", "JUMP_FRACTION", "AheadDamage", "damage_ahead",
           "path_jumps", "WindowSpeeds", "window_speeds", "bounded_mean_speed"]

#: status of a window (or a mean) whose apparent speed exceeds c_p, or that holds damage ahead of the front
NUCLEATION = "nucleation ahead of the front"
#: status of a window the front crossed contiguously (its speed is reported)
CONTIGUOUS = "contiguous"
#: status of a window the front did not cross (no speed: the crack did not run there)
NOT_CROSSED = "the front did not cross the window"
#: a jump of the path counts when it is at least this fraction of the speed window long: shorter ones change a
#: window's fitted speed by less than this fraction (single bins crossed fast are the noise of the bins'
#: median arrival times, e.g. pst_slope at 4.0 m, where the windows give 66-76 m/s)
JUMP_FRACTION = 0.1


@dataclass(frozen=True)
class AheadDamage:
    """A block of the layer damaged before the contiguous front reached it.

    Attributes
    ----------
    start, end : float
        Its extent along the column (m from the cut end, bin edges).
    time : float
        When it was there (s): its first bin's damage time (from arrival times), or the time the front
        reached its start (from a path: the block was damaged by then, perhaps earlier).
    front : float
        The contiguous front at ``time`` (m).
    crossed_in : float
        Time the contiguous front took to cross the block (s).
    source : str
        ``"arrival times"`` or ``"front path"``.
    """

    start: float
    end: float
    time: float
    front: float
    crossed_in: float
    source: str

    @property
    def extent(self) -> float:
        """Length of the block (m)."""
        return self.end - self.start

    @property
    def lead(self) -> float:
        """Distance from the contiguous front to the block's start at :attr:`time` (m)."""
        return self.start - self.front

    def to_dict(self) -> dict:
        """Plain dict with ``extent`` and ``lead`` (m) and the note :data:`NUCLEATION`."""
        return {**asdict(self), "extent": self.extent, "lead": self.lead, "note": NUCLEATION}


def _blocks(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``[i, j)`` of the runs of True in ``mask``."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.nonzero(d == 1)[0].tolist(), np.nonzero(d == -1)[0].tolist(), strict=True))


def damage_ahead(s, t_arrival, bin_width: float, min_extent: float = 0.0) -> list[AheadDamage]:
    """Blocks of bins damaged while at least one intact bin lay between them and the contiguous front.

    Parameters
    ----------
    s : array (n,)
        Bin centres (m from the cut end), ``bin_width`` apart from ``bin_width / 2``.
    t_arrival : array (n,)
        Damage time of every bin (s; inf: never).
    bin_width : float
        Bin width (m).
    min_extent : float
        Shortest block reported (m): a bin damaged a moment before its neighbour is the noise of the bins'
        median damage times, not a crack of its own.

    Returns
    -------
    list of AheadDamage
        In order along the column; empty for a front that ran bin after bin.
    """
    s, t = np.asarray(s, dtype=float), np.asarray(t_arrival, dtype=float)
    sp, T = front_trajectory(s, t)
    half = 0.5 * bin_width
    passed = np.searchsorted(T, t, side="right")        # bins the contiguous front had passed when each arrived
    ahead = np.isfinite(t) & (np.arange(len(s)) > passed)  # an intact bin (index ``passed``) lies between
    out = []
    for i, j in _blocks(ahead):
        if (j - i) * bin_width < min_extent - 1e-12:
            continue
        k = i + int(np.argmin(t[i:j]))
        n = int(passed[k])
        reached = [T[m] for m in (i, j - 1) if m < len(T)]
        out.append(AheadDamage(float(s[i] - half), float(s[j - 1] + half), float(t[k]), n * bin_width,
                               float(reached[-1] - reached[0]) if len(reached) == 2 else math.nan,
                               "arrival times"))
    return out


def path_jumps(s, T, c_max: float, min_extent: float) -> list[AheadDamage]:
    """Stretches of a front's path crossed faster than ``c_max`` (m/s), at least ``min_extent`` (m) long.

    ``(s, T)`` is the contiguous front's path (:func:`~mpm_warp.scenes.fronts.front_trajectory`: bin centres
    and the times the front passed them). A step between neighbouring bins faster than ``c_max`` means the
    bin was damaged before the front got there; runs of such steps are the blocks of damage ahead. Each block
    starts at the last bin reached at a physical speed (its ``time`` and ``front``) and ends at the last
    bin of the run.
    """
    s, T = np.asarray(s, dtype=float), np.asarray(T, dtype=float)
    if len(s) < 2:
        return []
    fast = np.diff(T) * c_max < np.diff(s)
    out = []
    for i, j in _blocks(fast):                         # steps i..j-1: bins i+1..j reached too fast
        if s[j] - s[i] >= min_extent - 1e-12:
            out.append(AheadDamage(float(s[i]), float(s[j]), float(T[i]), float(s[i]), float(T[j] - T[i]),
                                   "front path"))
    return out


@dataclass(frozen=True)
class WindowSpeeds:
    """Local front speeds over sliding windows (:func:`window_speeds`).

    Attributes
    ----------
    s : ndarray
        Window centres (m).
    speed : ndarray
        Speed (m/s) where the front crossed the window contiguously at most at ``c_max``; nan elsewhere.
    status : list of str
        :data:`CONTIGUOUS`, :data:`NUCLEATION` or :data:`NOT_CROSSED` per window.
    apparent : ndarray
        The fitted ``1 / slope`` of every window (m/s; nan where undefined): for a :data:`NUCLEATION` window
        it is not a speed, it says how fast the front connected to the damage ahead.
    c_max : float
        The bound (m/s), the slab's P-wave speed.
    """

    s: np.ndarray
    speed: np.ndarray
    status: list
    apparent: np.ndarray
    c_max: float

    def largest(self, s_max: float = math.inf) -> float:
        """The largest reported speed (m/s) of the windows centred at most ``s_max`` (m); nan if none."""
        v = self.speed[(self.s <= s_max) & np.isfinite(self.speed)]
        return float(v.max()) if len(v) else math.nan

    def to_dict(self) -> dict:
        """``s``, ``speed`` (None where no speed), ``status``, ``c_max``; the apparent speeds of the
        :data:`NUCLEATION` windows under ``nucleation_apparent_speed`` (m/s, not a speed)."""
        nuc = [k for k, st in enumerate(self.status) if st == NUCLEATION]
        return {"s": self.s.tolist(), "speed": [float(v) if math.isfinite(v) else None for v in self.speed],
                "status": list(self.status), "c_max": self.c_max,
                "nucleation_apparent_speed": {"note": NUCLEATION + ": the path's line fit, not a speed",
                                              "s": [float(self.s[k]) for k in nuc],
                                              "value": [float(self.apparent[k]) if math.isfinite(self.apparent[k])
                                                        else None for k in nuc]}}


def window_speeds(s, T, window: float, start: float, c_max: float, ahead=()) -> WindowSpeeds:
    """Local front speed (m/s) over windows of ``window`` (m) sliding by half a window from ``start`` (m).

    A line ``T(s)`` is fitted over each window of the path ``(s, T)``; its ``1 / slope`` is the window's
    speed when the front crossed the window contiguously: at most ``c_max`` (m/s) and with no block of
    ``ahead`` (:class:`AheadDamage`, from :func:`damage_ahead` or :func:`path_jumps`) inside it. Otherwise the
    window is :data:`NUCLEATION` (no speed); a window with fewer than 3 points or no advance is
    :data:`NOT_CROSSED`.
    """
    s, T = np.asarray(s, dtype=float), np.asarray(T, dtype=float)
    mids, speed, apparent, status = [], [], [], []
    a = float(start)
    while len(s) and a + window <= s[-1] + 1e-12:
        m = (s >= a) & (s <= a + window)
        slope, _, _, n = line_fit(s[m], T[m])
        v = 1.0 / slope if n >= 3 and np.isfinite(slope) and slope > 0 else math.nan
        hit = any(b.start < a + window and b.end > a for b in ahead)
        if hit or (n >= 3 and not slope > 1.0 / c_max):   # a slope of 0 (or below 1/c_max): faster than c_max
            st = NUCLEATION
        else:
            st = CONTIGUOUS if math.isfinite(v) else NOT_CROSSED
        mids.append(a + 0.5 * window)
        apparent.append(v)
        speed.append(v if st == CONTIGUOUS else math.nan)
        status.append(st)
        a += 0.5 * window
    return WindowSpeeds(np.asarray(mids), np.asarray(speed), status, np.asarray(apparent), float(c_max))


def bounded_mean_speed(s, T, s0: float, s1: float, c_max: float, ahead=()) -> tuple[float, str | None]:
    """Mean front speed (m/s) from ``s0`` to ``s1`` (m) and why there is none (``(nan, reason)``).

    As :func:`~mpm_warp.scenes.fronts.mean_speed`, but never above ``c_max`` or across damage ahead of the
    front (:data:`NUCLEATION`), never infinite, and with the reason when there is no value: the front did not
    reach ``s1`` (a crack that did not run has no speed).
    """
    s, T = np.asarray(s, dtype=float), np.asarray(T, dtype=float)
    if not len(s) or s[-1] < s1:
        reach = float(s[-1]) if len(s) else 0.0
        return math.nan, f"the front did not reach {s1:.3g} m (its path ends at {reach:.3g} m): no speed"
    if s[0] > s0 or s1 <= s0:
        return math.nan, f"no path from {s0:.3g} m to {s1:.3g} m"
    a = int(np.searchsorted(s, s0 - 1e-12))
    if a >= len(s) or s[a] >= s1:
        return math.nan, f"no bin between {s0:.3g} m and {s1:.3g} m"
    dt = float(np.interp(s1, s[a:], T[a:]) - T[a])
    d = s1 - float(s[a])
    if any(b.start < s1 and b.end > s[a] for b in ahead) or not dt * c_max > d:
        return math.nan, NUCLEATION + f" between {s0:.3g} m and {s1:.3g} m: not a speed"
    return d / dt, None
