"""The PST monitor: the saw, the damage and slab-deflection fronts, touchdown, and the frame series."""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..fronts import front_from_arrival, touchdown_distance
from ..series import SeriesMonitor, entries_below
from ..weak_layer import ReferenceField, WeakLayerTracker, bin_median, stored_calibration
from .analysis import end_zone, pst_summary, runaway_cut
from .build import layer_names
from .kernels import deflection_kernel
from .outcome import TIE_CELLS, SlabCrackDetector, classify
from .params import PSTParams
from .saw import blade_position, sawn, stop_record
from .static import weac_answer

__all__ = ["PSTMonitor", "attach"]


class PSTMonitor(ReferenceField, SeriesMonitor):
    """The saw, the front trackers and the frame diagnostics of one PST simulation.

    Fronts (distances from the cut end, m; see :mod:`mpm_warp.scenes.pst`): ``front`` (damage: bins
    whose particles' median bond fell to one half), ``deflection_front`` (bins whose slab base came
    down by ``front.deflection`` times the collapse height). Frame scalars (stored in the run file):
    both fronts, ``saw`` (m), ``collapse_height`` (m: mean collapse of the debonded, unsawn layer outside
    the far end zone, times ``D_wl``; in the end zone the slab's free end lifts and the layer dilates, by
    as much as the collapse elsewhere on the ladder PST at 24 cells), ``touchdown`` (m behind the
    deflection front where the slab base reaches 95 % of its collapsed deflection; nan before the crack
    runs), ``marker{k}_ux``/``marker{k}_uy`` (m, displacement since t = 0 of the slab-base particle
    nearest to ``params.markers()[k]``).
    With ``saw.stop = "runaway"`` the monitor stops the blade where it is at the first frame the crack has run
    away from it (:func:`~.analysis.runaway_cut` of the arrival times so far is finite) by writing its position
    into the saw kernel's blade end (:attr:`stopped_at`, m from the cut end); the blade overshoots the runaway
    by at most one frame interval times the saw speed.
    Per-frame particle field (with ``log_jp`` in the output): ``log_jp_ref``, the collapse reference.

    Parameters
    ----------
    sim : Simulation
        Built from a PST scenario (``sim.scenario.scene`` a :class:`PSTParams`).

    Attributes
    ----------
    stopped_at : float
        Where the blade stopped on the crack's runaway (m from the cut end), nan while it has not (and always
        with ``saw.stop = "cut_length"``).
    """

    name = "pst"

    def __init__(self, sim):
        super().__init__()
        self.params = p = self.scene_params(sim, PSTParams)
        self.sim = sim
        T = sim.model.T
        left = p.cut_at_origin
        saw = (p.saw_start, p.saw.speed, p.saw.cut_length, 0.0 if left else float(p.length), 1.0 if left else -1.0,
               p.saw.pre_cut)
        self.weak = WeakLayerTracker(sim, "weak_layer", p.saw_start, saw)
        self.stopped_at = math.nan
        self.calibration = stored_calibration(sim.scenario)
        self.h_c = self.calibration.h_c
        self.s_weak = p.distance_from_cut_end(self.weak.group.x0[:, 0])
        self.interior = self.s_weak < p.length - end_zone(p)   # the collapse height's particles: not the far end
        # the slab base: the lowest lattice row of the slab's bottom layer (all of it in z for the fronts)
        self.slab = sim.group_state(layer_names("slab", len(p.slab_stack()))[-1])
        x0 = self.slab.x0
        base = np.nonzero(x0[:, 1] <= x0[:, 1].min() + 1e-6)[0]
        self.base_index = base
        self.s_base = p.distance_from_cut_end(x0[base, 0])
        dev = sim.device
        self.base_y_ref = wp.array(x0[base, 1].astype(np.float64), dtype=wp.float64, device=dev)
        # over a pre-cut the slab base is behind the front from the start, as over a kerf the saw made
        self.base_arrival = wp.array(np.where(self.s_base <= p.saw.pre_cut, 0.0, np.inf) if p.saw.pre_cut > 0.0
                                     else np.full(len(base), np.inf), dtype=wp.float64, device=dev)
        self.deflection_action = wp.launch(
            deflection_kernel(sim.model.dim, T), len(base),
            inputs=[self.slab.x, wp.array(base.astype(np.int32), dtype=wp.int32, device=dev), self.base_y_ref,
                    self.base_arrival, sim.clock, float(p.saw_start), float(p.front.deflection * self.h_c)],
            device=dev, record_cmd=True)
        self.markers = p.markers()
        #: index of each marker's particle within the slab group (the base row, nearest to the middle in z)
        zsel = base
        if x0.shape[1] == 3:
            zmid = 0.5 * float(p.width)  # the quasi-2D slab (width 0): its first layer, nearest z = 0
            dz = np.abs(x0[base, 2] - zmid)
            zsel = base[dz <= dz.min() + 1e-6]
        self.marker_index = zsel[np.argmin(np.abs(x0[zsel, 0][None, :] - self.markers[:, None]), axis=1)]
        #: the slab's through-crack finder (a slab that can break only)
        slab_groups = [sim.group_state(n) for n in layer_names("slab", len(p.slab_stack()))]
        top = float(self.weak.group.x0[:, 1].max())          # the weak layer's top particles: the grid's tie above
        self.slab_crack = (SlabCrackDetector(p, slab_groups, body_above=top + TIE_CELLS * sim.model.dx)
                           if p.slab_fracture else None)

    # ----------------------------------------------------------------- contract
    def actions(self) -> list:
        """The saw and the weak layer's bookkeeping, then the deflection tracker, every step."""
        return [self.weak.launch, self.deflection_action]

    def units(self) -> dict[str, str]:
        """Units of the frame scalars."""
        u = {"front": "m", "deflection_front": "m", "saw": "m", "collapse_height": "m", "touchdown": "m"}
        if self.slab_crack is not None:
            u["slab_crack"] = "m"
            u["slab_stress_ratio"] = "-"
            u["slab_body_stress_ratio"] = "-"
            u["slab_crack_cover"] = "-"
        for k in range(len(self.markers)):
            u[f"marker{k}_ux"] = "m"
            u[f"marker{k}_uy"] = "m"
        return u

    def measure(self, sim) -> dict[str, float]:
        """Frame scalars (see the class docstring)."""
        t = sim.time
        p = self.params
        bin_w = p.bin_width
        arrival = self.damage_arrival()
        self._stop_on_runaway(t, arrival)
        cut = self.sawn().saw.cut_length
        deflection = self.deflection_front(t)
        out = {"front": min(front_from_arrival(arrival, t, bin_w), float(p.length)),
               "deflection_front": deflection, "saw": self.saw_position(t)}
        if self.slab_crack is not None:
            out["slab_crack"] = self.slab_crack.through_crack()
            out["slab_stress_ratio"], out["slab_body_stress_ratio"] = self.slab_crack.stress_ratios()
            out["slab_crack_cover"] = self.slab_crack.crack_cover()
        c, sawn = self.weak.collapse()
        gone = (self.weak.bond() <= 0.0) & (sawn == 0) & self.interior
        out["collapse_height"] = float(np.mean(c[gone]) * p.weak_layer_thickness) if gone.any() else 0.0
        y = self.slab.x.numpy()[self.base_index, 1].astype(np.float64)
        w = self.base_y_ref.numpy() - y
        out["touchdown"] = touchdown_distance(self.s_base, w, deflection, s_min=cut) \
            if deflection > cut + 4.0 * bin_w else float("nan")
        u = self.slab.x.numpy()[self.marker_index].astype(np.float64) - self.slab.x0[self.marker_index]
        for k in range(len(self.markers)):
            out[f"marker{k}_ux"] = float(u[k, 0])
            out[f"marker{k}_uy"] = float(u[k, 1])
        return out

    def device_state(self) -> dict[str, np.ndarray]:
        """Weak-layer reference, saw flags and damage times; slab-base reference and deflection times; where the
        blade stopped on runaway (``saw_stopped_at``, m, nan: it did not)."""
        return {**{f"weak_layer/{k}": v for k, v in self.weak.state().items()},
                "base_y_ref": self.base_y_ref.numpy(), "base_arrival": self.base_arrival.numpy(),
                "saw_stopped_at": np.array([self.stopped_at], dtype=np.float64)}

    def load_device_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`device_state`; the blade's end is this scene's cut unless the state's blade had stopped
        (a checkpoint of an older release has no stop: the blade goes on to the cut)."""
        self.weak.load_state(entries_below(state, "weak_layer/"))
        self.base_y_ref.assign(state["base_y_ref"])
        self.base_arrival.assign(state["base_arrival"])
        stop = float(np.asarray(state.get("saw_stopped_at", [math.nan]), dtype=np.float64)[0])
        self.stopped_at = stop if math.isfinite(stop) else math.nan
        self.weak.stop_blade(stop if math.isfinite(stop) else self.params.saw.cut_length)

    def sawn(self) -> PSTParams:
        """The parameters of the cut made so far (:func:`.saw.sawn`): the scene's, with ``saw.cut_length`` where
        the blade stopped once it stopped on runaway."""
        return sawn(self.params, self.stopped_at)

    def _stop_on_runaway(self, t: float, arrival: np.ndarray) -> None:
        """With ``saw.stop = "runaway"``: stop the blade where it is at ``t`` (s) once the damage front (bin
        arrival times ``arrival``, s) has led it by ``front.runaway_lead`` (:func:`~.analysis.runaway_cut`)."""
        p = self.params
        if p.saw.stop != "runaway" or math.isfinite(self.stopped_at):
            return
        blade = float(blade_position(p, t))
        if blade >= p.saw.cut_length or not math.isfinite(runaway_cut(p, self.bin_centres(), arrival)):
            return                      # at its end already (it stays there), or no runaway yet
        self.weak.stop_blade(blade)
        self.stopped_at = blade

    def result(self) -> dict:
        """Scene results from the series and arrival times so far (:func:`.analysis.pst_summary` of the cut made,
        :meth:`sawn`), with ``saw_stopped_at`` (m, :func:`.saw.stop_record`), the ``outcome`` and ``weac``."""
        times, series = self.series_arrays()
        made = self.sawn()
        out = pst_summary(made, self.calibration, times, series, self.bin_centres(), self.damage_arrival(),
                          self.deflection_arrival())
        out.update(stop_record(self.params, self.stopped_at, out["runaway_cut"]))
        out["outcome"] = self._classify(times, series, out["runaway_cut"])
        out["weac"] = weac_answer(made, self.calibration)       # weac's answer at the cut made
        return out

    def outcome(self) -> dict:
        """How the run ended, as the field writes it (:func:`~.outcome.classify` of the cut made), with
        ``saw_stopped_at`` (m; null with its reason when the blade did not stop on runaway): in the run file."""
        times, series = self.series_arrays()
        return self._classify(times, series, runaway_cut(self.sawn(), self.bin_centres(), self.damage_arrival()))

    def _classify(self, times, series: dict, runaway: float) -> dict:
        out = classify(self.sawn(), times, series.get("front", []), series.get("slab_crack"), runaway)
        ratio = np.asarray(series.get("slab_stress_ratio", []), dtype=float)
        if ratio.size and np.isfinite(ratio).any():     # the slab's peak over its strength at the frames so far
            out["slab_peak_stress_ratio"] = float(np.nanmax(ratio))
        body = np.asarray(series.get("slab_body_stress_ratio", []), dtype=float)
        if body.size and np.isfinite(body).any():       # the same over the slab's body (what the probability reads)
            out["slab_peak_body_stress_ratio"] = float(np.nanmax(body))
        cover = np.asarray(series.get("slab_crack_cover", []), dtype=float)
        if cover.size and np.isfinite(cover).any():     # how far a crack went through the slab, at most
            out["slab_peak_crack_cover"] = float(np.nanmax(cover))
        out.update(stop_record(self.params, self.stopped_at, runaway))
        return out

    # ------------------------------------------------------------------ queries
    def bin_centres(self) -> np.ndarray:
        """Centres of the front bins (m from the cut end)."""
        p = self.params
        return np.minimum((np.arange(p.n_bins) + 0.5) * p.bin_width, float(p.length))

    def damage_arrival(self) -> np.ndarray:
        """Damage time of every bin (s; inf: not yet): the median of its weak-layer particles' times."""
        p = self.params
        return self.weak.damage_arrival(self.s_weak, p.bin_width, p.n_bins)

    def deflection_arrival(self) -> np.ndarray:
        """Deflection time of every bin (s; inf: not yet): the median of its slab-base particles' times."""
        p = self.params
        return bin_median(self.s_base, self.base_arrival.numpy(), p.bin_width, p.n_bins)

    def damage_front(self, t: float) -> float:
        """The damage front at time ``t`` (m from the cut end)."""
        p = self.params
        return min(front_from_arrival(self.damage_arrival(), t, p.bin_width), float(p.length))

    def deflection_front(self, t: float) -> float:
        """The slab-deflection front at time ``t`` (m from the cut end)."""
        p = self.params
        return min(front_from_arrival(self.deflection_arrival(), t, p.bin_width), float(p.length))

    def saw_position(self, t: float) -> float:
        """Blade distance from the cut end (m) at time ``t`` (s), stopped where it stopped on runaway."""
        return float(blade_position(self.sawn(), t))


def attach(sim) -> PSTMonitor:
    """Add the PST's monitor (saw, weak-layer bookkeeping, front trackers, frame series) to ``sim``; return it."""
    return sim.add_monitor(PSTMonitor(sim))
