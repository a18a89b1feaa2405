"""Propagation Saw Test (PST): parameters, builder, saw, crack-front tracking (MODEL.md 6).

A column of length ``L`` on a stiff substratum: a thin Cam-Clay weak layer (thickness ``D_wl``)
bonded to the substratum (a wall at ``y = 0``) under an elastic slab (thickness ``D``). ``x`` runs
along the column, ``y`` is normal to the bed, ``z`` across; a slope of angle ``theta`` is a rotated
gravity ``g (sin theta, -cos theta, 0)`` (downslope is ``+x``). By default the column is one cell
thin in ``z`` between slip walls (plane strain); ``width > 0`` gives a full 3D column with free sides.

Run sequence (all on the device, no host loop):

1. settling: gravity ramps up over ``settle.gravity_ramp`` while the grid is damped until
   ``settle.duration``; the hardening state of the weak layer at the end of settling is the
   collapse reference;
2. the saw: from ``settle.duration`` on, a blade advances at ``saw.speed`` from one end of the column
   through the weak layer up to ``saw.cut_length``; weak-layer particles behind the blade get
   ``log_jp = saw.log_jp`` (a large positive value: ``p0`` sits at its floor and compaction cannot
   re-harden them within any reachable strain), re-applied every step while behind it;
3. free run: the crack runs by itself or arrests. The weak layer's failure rule (the brittle
   first-yield rule by default) is in :mod:`mpm_warp.scenes.weak_layer`.

Crack front (documented criterion): a weak-layer particle has *collapsed* once its plastic volume
has shrunk by more than ``front.threshold`` relative to the reference state (the settled layer, or
the state at failure), ``1 - exp(log_jp - log_jp_ref) >= threshold``, or once it has been sawn. The
column is split into bins of ``front.bin`` along the cut direction; a bin's arrival time is the first
time any of its particles collapsed (``atomic_min`` on the device, every step). The front at time
``t`` is the far edge of the contiguous run of bins, from the saw's end, whose arrival time is
``<= t`` (distance from the saw's starting end, m). The failure front (failed or sawn particles) is
tracked the same way.

Resolution: the weak layer must span at least two grid cells
(:data:`~mpm_warp.scenes.snow.MIN_WEAK_LAYER_CELLS`); with one, the slab's B-spline stencil reaches
the substratum's wall nodes and the slab rests partly on the wall.

Modules: :mod:`.params` (:class:`PSTParams` and its derived values), :mod:`.build`,
:mod:`.kernels` (saw and front tracker), :mod:`.monitor` (:class:`PSTMonitor`), :mod:`.analysis`
(:func:`pst_summary`), :mod:`.references` (Heierli, Gaume et al. 2017).
"""

from ..contract import SceneType
from ..snow import SETTLE_TIME_KEYS
from .analysis import pst_summary
from .build import build
from .monitor import PSTMonitor, attach
from .params import Front, PSTParams, Saw
from .references import critical_cut_length_formula, heierli_speed, heierli_touchdown

__all__ = ["SCENE", "PSTParams", "Saw", "Front", "build", "attach", "PSTMonitor", "pst_summary", "heierli_speed",
           "heierli_touchdown", "critical_cut_length_formula"]

SCENE = SceneType(
    kind="pst", params=PSTParams, build=build, attach=attach, time_keys=SETTLE_TIME_KEYS,
    description="Propagation Saw Test: a slab on a weak layer, sawn from one end after settling; crack front, "
                "speed, touchdown and collapse")
