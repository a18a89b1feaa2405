"""Many independent simulations stepped together: one plan of launches, one step size.

Each column (a :class:`~mpm_warp.simulation.Simulation` on one thread) keeps its own grid, particles, walls,
monitors and clock. A step of the batch lets every active column choose its step as it would alone, takes the
least (kernels/shared_dt.py), and runs the rest of every active column's step with it, so all clocks stay
equal. A column taken out (:meth:`SharedStep.retire`) costs no launch from then on. On CUDA a batch of steps
of all active columns is one captured graph, captured again when the active set changes.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from .errors import InvalidArgument, SimulationBlowUp
from .health import MIN_DT_SHARE
from .kernels.shared_dt import least_dt_kernel, offer_dt_kernel, take_dt_kernel
from .step import replay_captured

__all__ = ["SharedStep"]


class SharedStep:
    """The launch plan of ``sims`` stepped together with one step size.

    Parameters
    ----------
    sims : list of Simulation
        On one device, each stepping on one thread (``n_threads=1``), none run yet.

    Attributes
    ----------
    active : list of int
        The columns still stepped (indices into ``sims``).
    """

    def __init__(self, sims: list):
        if not sims:
            raise InvalidArgument("sims", sims, "at least one Simulation")
        dev = sims[0].device
        for k, s in enumerate(sims):
            if s.device != dev:
                raise InvalidArgument(f"sims[{k}].device", s.device, f"{dev}, the device of sims[0]")
            if s.stepper.n_threads != 1:
                raise InvalidArgument(f"sims[{k}].stepper.n_threads", s.stepper.n_threads, "1 (make the Simulation "
                                      "with n_threads=1: a column stepped with others runs on one thread)")
        self.sims, self.device = list(sims), dev
        n = len(sims)
        self.active = list(range(n))
        self.offers = wp.full(n, 1e30, dtype=wp.float64, device=dev)
        self._active_dev = wp.ones(n, dtype=wp.int32, device=dev)
        self.least = wp.zeros(1, dtype=wp.float64, device=dev)
        self._offer = [wp.launch(offer_dt_kernel(), 1, inputs=[s.state.clock, self.offers, k], device=dev,
                                 record_cmd=True) for k, s in enumerate(sims)]
        self._least = wp.launch(least_dt_kernel(), 1, inputs=[self.offers, self._active_dev, self.least],
                                device=dev, record_cmd=True)
        self._take = [wp.launch(take_dt_kernel(s.model.T), 1, inputs=[self.least, s.state.clock, s.stepper.dt],
                                device=dev, record_cmd=True) for s in sims]
        self.use_graph = wp.get_device(dev).is_cuda
        self.graph_batch = min(s.scenario.output.health_every for s in sims)
        self._graph = None
        #: below a column's floor (``MIN_DT_SHARE`` of its elastic step) its state has diverged
        self._floor = np.array([MIN_DT_SHARE * s._first_dt() for s in sims])

    # ------------------------------------------------------------------ plan
    def compile(self) -> None:
        """Load the shared step's kernels (compiling on first use), so that timing starts with them ready."""
        for launch in (self._offer[0], self._least, self._take[0]):
            launch.kernel.module.load(wp.get_device(self.device))

    def retire(self, k: int) -> None:
        """Take column ``k`` out: from the next step on it is not stepped and costs no launch."""
        if k in self.active:
            self.active.remove(k)
            mask = np.zeros(len(self.sims), dtype=np.int32)
            mask[self.active] = 1
            self._active_dev.assign(mask)
            self._graph = None

    def own_steps(self) -> np.ndarray:
        """Each column's step alone at rest, ``cfl dx / c_p`` (s): the batch steps with the least of the active."""
        return np.array([s._first_dt() for s in self.sims])

    def _launch_step(self) -> None:
        act = self.active
        for k in act:                       # each column chooses its step as it would alone
            self.sims[k].stepper.choose_step()
            self._offer[k].launch()
        self._least.launch()                # the batch takes the least
        for k in act:                       # and every column steps with it
            self._take[k].launch()
            self.sims[k].stepper.finish_step()

    def steps(self, n: int) -> None:
        """Launch ``n`` steps of every active column without host synchronisation (on CUDA: a captured graph of
        :attr:`graph_batch` steps replayed, the remainder eagerly)."""
        if n <= 0 or not self.active:
            return
        if self.use_graph:
            n = replay_captured(self, self.device, n)
        with self.sims[self.active[0]].stepper.flushed(0):
            for _ in range(n):
                self._launch_step()

    # ----------------------------------------------------------------- clock
    def step_to(self, t_end: float) -> tuple[int, dict]:
        """Advance every active column to ``t_end`` (s) exactly; return the steps taken and the columns that
        diverged on the way (index -> :class:`~mpm_warp.errors.SimulationBlowUp`), taken out of the batch."""
        blown: dict[int, SimulationBlowUp] = {}
        for k in self.active:
            self.sims[k].stepper.set_frame_end(t_end)
        lead = self.sims[self.active[0]]
        t, dt, steps0 = lead.stepper.clock()
        he = self.graph_batch
        taken = since_health = 0
        while self.active and t < t_end * (1 - 1e-12) - 1e-15:
            if dt <= 0:
                dt = float(min(self.own_steps()[self.active]))
            n = self.graph_batch if self.use_graph else max(1, min(he, int(math.ceil((t_end - t) / dt))))
            self.steps(n)
            t_before = t
            t, dt_new, steps = self.sims[self.active[0]].stepper.clock()
            taken = steps - steps0
            since_health += n
            if since_health >= he:
                self._check_health(blown)
                since_health = 0
            if self.active and t < t_end * (1 - 1e-12) - 1e-15:
                self._find_diverged(blown, t, stuck=t == t_before)
            dt = dt_new if dt_new > 0 else dt
        return taken, blown

    def _check_health(self, blown: dict) -> None:
        for k in list(self.active):
            try:
                self.sims[k].health()
            except SimulationBlowUp as e:
                blown[k] = e
                self.retire(k)

    def _find_diverged(self, blown: dict, t: float, stuck: bool) -> None:
        """The columns whose own step fell below their floor leave the batch, each with its error; when the clock
        is ``stuck`` and none did, every active column leaves."""
        offers = self.offers.numpy()
        bad = [k for k in self.active if not offers[k] >= self._floor[k]]
        if stuck and not bad:
            bad = list(self.active)
        for k in bad:
            steps = int(self.sims[k].state.steps.numpy()[0])
            blown[k] = SimulationBlowUp(steps, -1, "dt", (
                f"the time step fell to {offers[k]:.3g} s at t = {t:.6g} s, below {MIN_DT_SHARE:g} of the elastic "
                f"step ({self._floor[k] / MIN_DT_SHARE:.3g} s): the largest nodal speed is not finite or beyond any "
                "physical one (the state diverged)"))
            self.retire(k)
