"""Critical cut length of a PST by bisection on the saw's stop position, trial runs forked from one base run.

Two runs that differ only in where the saw stops are the same run until the shorter cut ends (the
blade moves at a fixed speed). So one *base run* with the longest cut is stepped once, with a
snapshot (:func:`mpm_warp.snapshot.take_snapshot`) every ``snapshot_every`` metres of sawing; a
trial cut ``a`` starts from the last snapshot before the blade reached ``a``, in a simulation whose
saw stops at ``a``, and runs until its crack has run ``run_distance`` beyond the cut (it
propagated) or ``free_run`` seconds after the saw stopped (it arrested). Each trial pays for its free
run only, never for the settling. The predicate is monotone in the cut, and
:func:`~mpm_warp.scenes.fronts.bisect_threshold` brackets the critical cut to ``tol``.

With ``workers=2`` the two trials every search needs first, the bracket's bottom ``lo`` and the first
midpoint, run at the same time in two Python threads (a launch releases the GIL, and each trial has its
own simulation and grids), so a search of one bisection step costs the base run and one trial's wall
time on two cores; the trials and the result are those of the serial search.

The result states the bracket, every trial (cut, outcome, how far its damage front got, its
runaway time) and the base run's one-run estimate (``runaway_cut``, see :mod:`.analysis`).
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time as _time
from concurrent.futures import ThreadPoolExecutor

import warp as wp

from ...simulation import Simulation
from ..fronts import bisect_threshold
from .analysis import end_zone
from .monitor import PSTMonitor, attach
from .params import PSTParams
from .saw import blade_time
from .static import weac_answer

__all__ = ["CriticalCut", "critical_cut", "cut_run"]


@dataclasses.dataclass
class CriticalCut:
    """Critical cut of a PST (m) from bisection over forked trial runs.

    Attributes
    ----------
    value : float
        Midpoint of the final bracket (m).
    lo, hi : float
        The longest cut that arrested and the shortest that propagated (m).
    trials : list of dict
        ``cut`` (m), ``propagated``, ``front`` (m: the damage front's reach when the trial ended),
        ``t_start``, ``t_end`` (s: simulated times the trial started from its snapshot and ended; the
        base run starts at 0), ``steps`` (the trial's own), ``wall`` (s); with ``classify``, ``class`` (END, SF,
        ARR: :func:`~.outcome.classify`), ``slab_fracture_at``, ``arrest_at`` (m from the cut end, nan).
    runaway_cut : float
        The base run's one-run estimate (m; nan if its crack never ran away from the saw).
    base : dict
        The base run's :func:`~.analysis.pst_summary` (cut ``hi`` of the first call).
    wall : float
        Wall time of the whole search (s).
    bracketed : bool
        False when a cut of ``lo`` propagated or one of ``hi`` arrested: ``value`` is nan and ``note``
        says which (the trials are kept).
    note : str
    classes : dict
        The field class on each side of the critical cut: ``below`` (the trial of ``lo``: an arrest) and
        ``above`` (the trial of ``hi``: END, or SF when the slab broke first); empty without ``classify``.
    weac : dict
        weac's static answer for the same column (:func:`~.static.weac_answer`: its critical cut, and its
        energy release rate at ``value``), or the one line saying weac is not installed.
    """

    value: float
    lo: float
    hi: float
    trials: list
    runaway_cut: float
    base: dict
    wall: float
    bracketed: bool = True
    note: str = ""
    classes: dict = dataclasses.field(default_factory=dict)
    weac: dict = dataclasses.field(default_factory=dict)

    def to_dict(self) -> dict:
        """Plain dict (JSON)."""
        return dataclasses.asdict(self)


def _with_cut(scenario, cut: float):
    scene = dataclasses.replace(scenario.scene, saw=dataclasses.replace(scenario.scene.saw, cut_length=float(cut)))
    return dataclasses.replace(scenario, scene=scene)


def _simulation(scenario, device, n_threads) -> tuple[Simulation, PSTMonitor]:
    sim = Simulation(scenario, device=device, n_threads=n_threads)
    return sim, attach(sim)


def critical_cut(scenario, lo: float, hi: float, tol: float = 0.02, run_distance: float = 1.0,
                 free_run: float = 0.2, snapshot_every: float | None = None, check_interval: float = 0.01,
                 base_run_distance: float | None = None, base_free_run: float | None = None,
                 device: str | None = None, n_threads: int | None = None, workers: int = 1,
                 log=None, classify: bool = True) -> CriticalCut:
    """Bisect the critical cut of the PST ``scenario`` within ``[lo, hi]`` (m) to ``tol`` (m).

    Parameters
    ----------
    scenario : Scenario
        A PST scenario (``scenario.scene`` a :class:`PSTParams`); its own cut length is ignored.
    lo, hi : float
        Bracket (m): a cut of ``lo`` should arrest and one of ``hi`` propagate (both are run; when
        not, the result is not ``bracketed`` and its ``note`` names the end).
    tol : float
        Bracket width to stop at (m).
    run_distance : float
        A trial propagated once its damage front ran this far beyond its cut (m), or into the end zone
        (within one slab thickness of the far end, as :func:`~.analysis.pst_summary`).
    free_run : float
        A trial arrested if it has not propagated this long after its saw stopped (s).
    snapshot_every : float, optional
        Blade travel between snapshots of the base run (m); default ``tol / 2``.
    base_run_distance : float, optional
        How far beyond ``hi`` the base run's crack must run before it stops (m); default
        ``run_distance``; ``length`` runs it into the end zone, so that its ``base`` summary holds the
        crack's speed over the column.
    base_free_run : float, optional
        The base run's ``free_run`` (s); default ``free_run``.
    check_interval : float
        Simulated time between the trial's front checks (s); each is a frame of the monitor's series, so
        the ``base`` summary has a touchdown and a collapse height.
    device, n_threads
        As :class:`~mpm_warp.Simulation`: ``n_threads`` CPU threads for the base run and each serial trial;
        the two concurrent trials of ``workers=2`` take half as many each (one each when ``n_threads`` is
        None), so that they share the cores the base run used.
    workers : int
        1: one trial after another. 2: on a CPU, the trials of ``lo`` and the first midpoint run
        concurrently (the bisection after them is serial, with the same trials as ``1``); on a GPU, where
        one run fills the device, the trials stay serial.
    log : callable, optional
        ``log(str)`` for a line per trial.
    classify : bool
        A trial that propagated runs on until its field class is known (END, SF or ARR), so that every trial
        and both sides of the bracket have one (about a third more time per propagating trial on the ladder
        PST); False stops it once it propagated.
    """
    p = scenario.scene
    if not isinstance(p, PSTParams):
        raise TypeError("critical_cut needs a PST scenario (scene kind 'pst')")
    if p.saw.stop != "cut_length":
        raise ValueError(f"critical_cut bisects on the cut length: need saw.stop = 'cut_length' (got {p.saw.stop!r}; "
                         "a saw that stops on runaway estimates the critical cut from one run: runaway_cut)")
    if not 0.0 <= lo < hi <= p.length:
        raise ValueError(f"need 0 <= lo < hi <= length (got lo={lo}, hi={hi}, length={p.length})")
    if p.saw.pre_cut > lo:
        raise ValueError(f"saw.pre_cut = {p.saw.pre_cut} m is beyond lo = {lo} m: a trial cannot cut less than the "
                         "pre-cut")
    if workers not in (1, 2):
        raise ValueError(f"workers = {workers}: need 1 (serial trials) or 2 (lo and the first midpoint at once)")
    wall0 = _time.perf_counter()
    step = float(snapshot_every or 0.5 * tol)
    t_saw = p.saw_start
    # ---------------------------------------------------------------- base run: cut hi, snapshots while sawing
    base_sc = _with_cut(scenario, hi)
    sim, mon = _simulation(base_sc, device, n_threads)
    snaps = []                               # (blade position, snapshot), increasing
    sim.step_to(t_saw)
    a = min(lo, hi)                          # no trial starts before lo
    _step_recording(sim, mon, blade_time(p, a), check_interval)
    while True:
        snaps.append((a, sim.snapshot()))
        if a >= hi:
            break
        a = min(a + step, hi)
        _step_recording(sim, mon, blade_time(p, a), check_interval)
    base = _trial(sim, mon, hi, run_distance if base_run_distance is None else base_run_distance,
                  free_run if base_free_run is None else base_free_run, check_interval, classify)
    base_summary = mon.result()
    trials = [{**base, "t_start": 0.0, "steps": sim.stepper.clock()[2], "wall": _time.perf_counter() - wall0}]
    if log:
        log(f"cut {hi:.4g} m (base): propagated={base['propagated']}, front {base['front']:.3f} m, "
            f"class {base.get('class')}")
    cache = {hi: base["propagated"]}
    lock = threading.Lock()

    def propagates(cut: float, threads: int | None = n_threads) -> bool:
        if cut in cache:
            return cache[cut]
        t0 = _time.perf_counter()
        k = max(i for i, (pos, _) in enumerate(snaps) if pos <= cut + 1e-12)
        tsim, tmon = _simulation(_with_cut(scenario, cut), device, threads)
        tsim.load_snapshot(*snaps[k][1])
        steps0, t_start = tsim.stepper.clock()[2], tsim.time
        out = _trial(tsim, tmon, cut, run_distance, free_run, check_interval, classify)
        out.update(t_start=t_start, steps=tsim.stepper.clock()[2] - steps0, wall=_time.perf_counter() - t0)
        with lock:
            trials.append(out)
            cache[cut] = out["propagated"]
            if log:
                log(f"cut {cut:.4g} m: propagated={out['propagated']}, front {out['front']:.3f} m, "
                    f"class {out.get('class')} ({out['wall']:.0f} s)")
        return out["propagated"]

    runaway = float(base_summary.get("runaway_cut", math.nan))
    # on a GPU a run fills the device (and captures CUDA graphs on its stream): trials stay serial there
    concurrent = workers == 2 and not wp.get_device(sim.device).is_cuda
    if concurrent and cache[hi] and hi - lo > tol:   # the first midpoint, with lo: bisect_threshold's first point
        with ThreadPoolExecutor(2) as pool:
            half = max(1, (n_threads or 2) // 2)
            list(pool.map(lambda c: propagates(c, half), (lo, 0.5 * (lo + hi))))
        trials[1:] = sorted(trials[1:], key=lambda t: t["cut"] != lo)   # lo's trial first, as in the serial search
    low = propagates(lo)
    weac = weac_answer(p, mon.calibration)
    if low or not cache[hi]:   # the critical cut is not in the bracket: say which end, keep the trials
        why = f"a cut of {lo:g} m propagated" if low else f"a cut of {hi:g} m arrested"
        return CriticalCut(math.nan, lo, hi, trials, runaway, base_summary, _time.perf_counter() - wall0,
                           bracketed=False, note=why, classes=_sides(trials, lo, hi, classify), weac=weac)
    b = bisect_threshold(propagates, lo, hi, tol, check_ends=False)
    weac = weac_answer(p, mon.calibration, cut=b.value)
    return CriticalCut(b.value, b.lo, b.hi, trials, runaway, base_summary, _time.perf_counter() - wall0,
                       classes=_sides(trials, b.lo, b.hi, classify), weac=weac)


def _sides(trials: list, lo: float, hi: float, classify: bool) -> dict:
    """The field class of the trials at the bracket's two ends."""
    if not classify:
        return {}
    by_cut = {t["cut"]: t.get("class") for t in trials}
    return {"below": by_cut.get(float(lo)), "above": by_cut.get(float(hi))}


def cut_run(scenario, cut: float, run_distance: float, free_run: float, check_interval: float = 0.01,
            device: str | None = None, n_threads: int | None = None) -> dict:
    """One PST run with its saw stopped at ``cut`` (m): the base run of :func:`critical_cut` without its snapshots.

    Settles, saws to ``cut`` with a frame of the monitor's series every ``check_interval`` (s), then
    runs until the damage front is ``run_distance`` (m) beyond the cut (or in the end zone) or
    ``free_run`` (s) has passed since the saw stopped. Returns the trial record (``cut``, ``propagated``,
    ``front``, ``t_end``, ``steps``) with the run's :func:`~.analysis.pst_summary` under ``"summary"`` (front speed,
    touchdown, collapse height) and its frame series under ``"series"`` (``time`` in s, then the monitor's
    scalars, e.g. ``front`` and ``collapse_height`` in m; lists, one entry a frame).
    """
    p = scenario.scene
    if not isinstance(p, PSTParams):
        raise TypeError("cut_run needs a PST scenario (scene kind 'pst')")
    if not 0.0 < cut <= p.length:
        raise ValueError(f"cut = {cut} m: need 0 < cut <= length = {p.length} m")
    sim, mon = _simulation(_with_cut(scenario, cut), device, n_threads)
    sim.step_to(p.saw_start)
    _step_recording(sim, mon, blade_time(p, cut), check_interval)
    out = _trial(sim, mon, cut, run_distance, free_run, check_interval)
    times, series = mon.series_arrays()
    return {**out, "steps": sim.stepper.clock()[2], "summary": mon.result(),
            "series": {"time": times.tolist(), **{k: v.tolist() for k, v in series.items()}}}


def _step_recording(sim: Simulation, mon: PSTMonitor, t_end: float, check_interval: float) -> None:
    """Step ``sim`` to ``t_end`` (s) with a frame of the monitor's series every ``check_interval`` (s) on the way.

    A crack may run away while the saw is still cutting towards the base run's ``hi``: without these
    frames the base summary would have no frame of its run (no touchdown, no collapse history).
    """
    t = sim.time
    while t < t_end - 1e-12:
        t = min(t + check_interval, t_end)
        sim.step_to(t)
        mon.frame_scalars(sim)


def _trial(sim: Simulation, mon: PSTMonitor, cut: float, run_distance: float, free_run: float,
           check_interval: float, classify: bool = False) -> dict:
    """Run a trial from where ``sim`` is until its crack propagated or arrested; with ``classify``, a crack that
    propagated runs on until its field class is known (END, SF or ARR: :func:`~.outcome.classify`), for at most
    the time a crack at 5 m/s needs to cross the column."""
    p = mon.params
    goal = min(cut + run_distance, p.length - end_zone(p))
    t_stop = blade_time(p, cut) + free_run
    t_cap = t_stop + p.length / 5.0
    t = sim.time
    front, propagated = 0.0, False
    while t < (t_cap if propagated and classify else t_stop) - 1e-12:
        t = min(t + check_interval, t_cap if propagated and classify else t_stop)
        sim.step_to(t)
        mon.frame_scalars(sim)          # a frame of the monitor's series (touchdown, collapse height)
        front = mon.damage_front(t)
        propagated = propagated or front >= goal
        if propagated and not classify:
            break
        if propagated and mon.outcome()["class"] is not None:
            break
    out = {"cut": float(cut), "propagated": bool(propagated), "front": float(front), "t_end": float(sim.time)}
    if classify:
        oc = mon.outcome()
        out.update({"class": oc["class"], "slab_fracture_at": oc["slab_fracture_at"], "arrest_at": oc["arrest_at"]})
    return out
