"""The outcome of a PST as the field writes it: END, SF or ARR (or NP), and the line ``PST 32/100 (END) down 50 cm``.

The field's three classes (e.g. Greene et al., SWAG; Gauthier and Jamieson 2008):

- END: the crack in the weak layer reached the far end of the column;
- SF: the slab fractured through before that;
- ARR: the crack arrested in the weak layer (here also a crack that never ran beyond the saw, with
  ``saw.stop = "cut_length"``).

With the field protocol (``saw.stop = "runaway"``: the saw stops once the crack runs away from it) a fourth:

- NP, no propagation: the blade reached the end it may go to, ``saw.cut_length`` (the column's end for a
  field test), without the crack running away from it, and the front stands still; counted apart from an
  ARR, a crack that ran away and then stopped. A slab that broke only after the blade reached its end is
  noted, not an SF.

A through-crack of the slab (:class:`SlabCrackDetector`): in a window one slab thickness wide along the
column, the fully damaged slab particles (damage >= :data:`THROUGH_DAMAGE`) cover at least
:data:`THROUGH_COVER` of the slab's particle rows, top to bottom; it lies at the median position of those
particles (initial positions) in its best-covered window. The crack reached the far end when the
damage front entered the end zone (one slab thickness from the far end, as the front speeds).
"""

from __future__ import annotations

import math

import numpy as np

from .analysis import crack_ran, end_zone
from .params import PSTParams

__all__ = ["SlabCrackDetector", "carried_over_strength",
           "classify", "field_line", "front_stalled", "FIELD_CLASSES", "CLASSES", "THROUGH_DAMAGE",
           "THROUGH_COVER", "STALL_TIME", "TIE_CELLS"]

#: the field's three classes, in the order of the forecast scores (docs/field.md): the one home of their spelling
FIELD_CLASSES = ("END", "SF", "ARR")
#: the classes of :func:`classify`: the field's three and no propagation (``saw.stop = "runaway"`` only)
CLASSES = (*FIELD_CLASSES, "NP")

#: damage (-) at which a slab particle is cracked through
THROUGH_DAMAGE = 0.95
#: fraction of the slab's particle rows a through-crack covers (-)
THROUGH_COVER = 0.9
#: a front that has not advanced for this long (s) at the end of a run has arrested
STALL_TIME = 0.05
#: grid cells above the weak layer's top particles within which a slab particle's quadratic B-spline stencil
#: (1.5 cells each way) shares a grid node with theirs: the slab's rows the grid ties to the weak layer, outside
#: the slab's body (:meth:`SlabCrackDetector.body_stress_ratio`)
TIE_CELLS = 3.0


def carried_over_strength(H: np.ndarray, kappa: np.ndarray, material) -> np.ndarray:
    """Per particle, the largest tensile stress it carries over its material's tensile strength (-), 1 where its
    ``kappa`` passed the strength (:meth:`SlabCrackDetector.stress_ratio`).

    Parameters
    ----------
    H : ndarray (n, d, d)
        ``F_E - I`` of the particles (-).
    kappa : ndarray (n,)
        Their largest effective tensile stress so far (Pa).
    material : TensileCracking
        Their cracking material (``mu``, ``lam`` in Pa, ``tensile_strength`` in Pa, ``damage(kappa)``).
    """
    H = np.asarray(H, dtype=np.float64)
    F = H + np.eye(H.shape[1])
    b = np.einsum("nij,nkj->nik", F, F)
    eps = 0.5 * np.log(np.clip(np.linalg.eigvalsh(b), 1e-300, None))      # principal Hencky strains
    tau = 2.0 * material.mu * eps + material.lam * eps.sum(axis=1, keepdims=True)
    kappa = np.asarray(kappa, dtype=np.float64)
    d = np.asarray(material.damage(kappa), dtype=np.float64).reshape(-1, 1)
    carried = np.where(tau > 0.0, (1.0 - d) * tau, tau).max(axis=1, initial=-np.inf)
    ratio = np.maximum(carried, 0.0) / material.tensile_strength
    return np.where(kappa > material.tensile_strength, np.maximum(ratio, 1.0), ratio)


class SlabCrackDetector:
    """Finds a crack through the slab from its particles' damage (host side, once per frame).

    Parameters
    ----------
    params : PSTParams
    groups : list of GroupState
        The slab layers' particle groups (cracking materials).
    body_above : float, optional
        Height (m, initial positions) above which a slab particle belongs to the slab's body
        (:meth:`body_stress_ratio`); default: all of the slab.
    """

    def __init__(self, params: PSTParams, groups, body_above: float = -math.inf):
        self.params = params
        self.groups = groups
        #: per group, its particles in the slab's body
        self.body = [np.asarray(g.x0[:, 1]) > body_above for g in groups]
        x0 = np.concatenate([g.x0 for g in groups])
        s = self.s = params.distance_from_cut_end(x0[:, 0])
        w = params.bin_width
        self.bins = np.clip((s / w).astype(int), 0, params.n_bins - 1)
        rows = np.unique(np.round(x0[:, 1], 9))
        self.rows = np.searchsorted(rows, np.round(x0[:, 1], 9))
        self.n_rows = len(rows)
        #: window of bins a through-crack may lean over (one slab thickness)
        self.window = max(1, int(round(params.slab_depth / w)))

    def damage(self) -> np.ndarray:
        """Damage (-) of the slab's particles, in the order of :attr:`groups`."""
        return np.concatenate([g.material.damage(g.kappa.numpy()) for g in self.groups])

    def stress_ratio(self) -> float:
        """The largest tensile stress the slab carries now over its layer's strength (-), 1 once a particle cracked.

        The stress is the kernel's (``kernels/cracking.py``): the principal Kirchhoff stresses of the Hencky strain
        of ``F_E`` (the in-plane ones in 2D, where ``F_E,zz = 1``), the tensile ones softened by ``1 - d(kappa)``.
        A cracking material carries at most its strength, so the ratio is at most 1 (to the step's round-off); a
        slab with a particle whose ``kappa`` passed the strength counts 1, its stress having reached the strength.
        ``F_E`` holds a crack's opening too (there is no separate crack strain), so its unsoftened stress, and
        ``kappa``, grow without bound as a crack opens: they say how far a crack opened, not what the slab carries
        (docs/field.md, "Why the slab's stress read 20-124 times its strength"); :meth:`crack_cover` says how far
        a crack went through the slab."""
        return self.stress_ratios()[0]

    def body_stress_ratio(self) -> float:
        """:meth:`stress_ratio` over the slab's body alone (the particles above ``body_above``), nan without one.

        The slab's rows whose grid stencils share nodes with the weak layer's are pulled by the collapsing layer
        and crack along the bed, a crack that cannot go through the slab (docs/field.md, "Why the slab's stress
        read 20-124 times its strength"); the body's stress is the one a crack through the slab starts from."""
        return self.stress_ratios()[1]

    def stress_ratios(self) -> tuple[float, float]:
        """``(whole, body)``: :meth:`stress_ratio` and :meth:`body_stress_ratio` from one read of the particles."""
        whole, body = 0.0, math.nan
        for g, in_body in zip(self.groups, self.body, strict=True):
            r = carried_over_strength(g.H.numpy(), g.kappa.numpy(), g.material)
            whole = max(whole, float(np.max(r, initial=0.0)))
            if in_body.any():
                body = max(0.0 if body != body else body, float(r[in_body].max()))
        return whole, body

    def crack_cover(self) -> float:
        """The largest share of the slab's particle rows (-) that fully damaged particles (damage >=
        :data:`THROUGH_DAMAGE`) cover within one window one slab thickness wide: 0 uncracked, at least
        :data:`THROUGH_COVER` for a crack through the slab (:meth:`through_crack`)."""
        cover = self._cover(self.damage() >= THROUGH_DAMAGE)
        return float(cover.max(initial=0.0))

    def _cover(self, cracked: np.ndarray) -> np.ndarray:
        """Per front bin: the share of the slab's rows with a ``cracked`` particle within the window around it."""
        nb = self.params.n_bins
        hit = np.zeros((nb + 1, self.n_rows), dtype=np.int32)
        hit[self.bins[cracked] + 1, self.rows[cracked]] = 1
        c = np.cumsum(hit, axis=0)                         # rows cracked in bins [0, b)
        k = self.window
        lo = np.clip(np.arange(nb) - k // 2, 0, nb)
        hi = np.clip(np.arange(nb) + (k - k // 2), 0, nb)
        return ((c[hi] - c[lo]) > 0).mean(axis=1)          # rows cracked within the window around each bin

    def through_crack(self) -> float:
        """Position (m from the cut end) of the first crack through the slab, nan if there is none."""
        cracked = self.damage() >= THROUGH_DAMAGE
        if not cracked.any():
            return math.nan
        nb, k = self.params.n_bins, self.window
        cover = self._cover(cracked)
        through = np.nonzero(cover >= THROUGH_COVER)[0]
        if not len(through):
            return math.nan
        # the first through-crack: its best-covered window, and the median position of its cracked particles
        run = through[: int(np.argmax(np.diff(np.append(through, nb + 2)) > 1)) + 1]
        b = int(run[np.argmax(cover[run])])
        near = cracked & (np.abs(self.bins - b) <= k // 2)
        return float(np.median(self.s[near]))


def field_line(cls: str | None, cut: float, length: float, depth: float) -> str:
    """The observer's line, e.g. ``PST 32/100 (END) down 50 cm``: cut and column length and the weak layer's depth
    below the surface (measured vertically, as a profile records it) in whole centimetres."""
    c = cls if cls is not None else "running"
    return f"PST {round(100 * cut):d}/{round(100 * length):d} ({c}) down {round(100 * depth):d} cm"


def classify(params: PSTParams, times, front, slab_crack=None, saw_cut: float | None = None) -> dict:
    """The field class of a PST run from its frame series (``times`` s; ``front``, ``slab_crack`` m from the cut end).

    Parameters
    ----------
    params : PSTParams
        The parameters of the cut made (:func:`~.saw.sawn`: ``saw.cut_length`` where the blade stopped when it
        stopped on runaway).
    times, front : array (n,)
        Frame times (s) and the damage front (m from the cut end).
    slab_crack : array (n,), optional
        Position of a through-crack of the slab per frame (m, nan: none); None for a slab that cannot break.
    saw_cut : float, optional
        The cut the field line quotes (m): the saw's position when the crack ran away from it (the run's
        ``runaway_cut``) or, when it never did, the cut made (``saw.cut_length``). With ``saw.stop = "runaway"``
        a nan or None is no runaway: NP once the blade reached its end and the front stands still.

    Returns
    -------
    dict
        ``class`` ("END", "SF", "ARR", "NP" (``saw.stop = "runaway"``, no runaway before the blade's end), or
        None while the crack still runs when the series ends),
        ``field_line`` (:func:`field_line`), ``cut``, ``column_length``, ``depth`` (m, vertical: the slab's
        bed-normal thickness over the cosine of the slope), ``end_time``,
        ``slab_fracture_time`` (s, nan: never), ``slab_fracture_at`` (m from the cut end, nan), ``arrest_at``
        (m from the cut end for ARR, nan otherwise), ``note``; a nan value has its reason under ``<key>_null``.
    """
    t = np.asarray(times, dtype=float)
    fr = np.asarray(front, dtype=float)
    L, D = float(params.length), float(params.slab_depth) / math.cos(math.radians(params.slope_angle))
    cut = float(params.saw.cut_length) if saw_cut is None or not math.isfinite(saw_cut) else float(saw_cut)
    reach_end = np.nonzero((fr >= L - end_zone(params)) & crack_ran(params, fr))[0]
    t_end = float(t[reach_end[0]]) if len(reach_end) else math.nan
    sc = np.full(len(t), np.nan) if slab_crack is None else np.asarray(slab_crack, dtype=float)
    broke = np.nonzero(np.isfinite(sc))[0]
    t_sf = float(t[broke[0]]) if len(broke) else math.nan
    at_sf = float(sc[broke[0]]) if len(broke) else math.nan
    out = {"cut": cut, "column_length": L, "depth": D, "end_time": t_end, "slab_fracture_time": t_sf,
           "slab_fracture_at": math.nan, "arrest_at": math.nan, "note": ""}
    no_runaway = params.saw.stop == "runaway" and (saw_cut is None or not math.isfinite(saw_cut))
    if math.isfinite(t_sf) and not t_end <= t_sf and not (no_runaway and t_sf > params.saw_end):
        cls = "SF"
        out["slab_fracture_at"] = at_sf
    elif math.isfinite(t_end):
        cls = "END"
    elif no_runaway and len(t) and front_stalled(t, fr, params):
        cls = "NP"
        out["note"] = (f"the saw reached its end, {float(params.saw.cut_length):.2f} m, without the crack running "
                       f"away from it by {params.front.runaway_lead:g} m")
        if math.isfinite(t_sf):
            out["note"] += f"; the slab then broke {at_sf:.2f} m from the cut end"
    elif len(t) and front_stalled(t, fr, params):
        cls = "ARR"
        out["arrest_at"] = float(fr[-1])
        if fr[-1] <= float(params.saw.cut_length) + 2.0 * params.bin_width:
            out["note"] = "the crack did not run beyond the saw"
        else:
            out["note"] = f"the crack ran {fr[-1] - float(params.saw.cut_length):.2f} m beyond the saw and stopped"
    else:
        cls = None
        out["note"] = ("the saw had not started when the run ended" if not len(t) or t[-1] < params.saw_start else
                       "the crack was still running when the run ended") + " (lengthen time.end to classify it)"
    out["class"] = cls
    out["field_line"] = field_line(cls, cut, L, D)
    for key, why in _NAN_REASONS.items():
        if not math.isfinite(out[key]):
            out[f"{key}_null"] = why
    return out


#: why a value of :func:`classify` is nan (null in a results file)
_NAN_REASONS = {"end_time": "the crack did not reach the far end zone, having run beyond the cut",
                "slab_fracture_time": "the slab did not crack through", "slab_fracture_at": "not an SF outcome",
                "arrest_at": "not an ARR outcome"}


def front_stalled(t, front, params: PSTParams) -> bool:
    """Whether the front has stood still for :data:`STALL_TIME` at the end of the series, after the saw stopped."""
    if t[-1] < params.saw_end + STALL_TIME:
        return False
    recent = t >= t[-1] - STALL_TIME
    return bool(front[recent].max() - front[recent].min() < params.bin_width)
