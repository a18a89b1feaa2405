"""Propagation Saw Test (PST): parameters, builder, saw, crack-front tracking (docs/model.md §6).

A column of length ``L``: elastic old snow (the substratum, ``D_sub``) bonded to the bed (a wall at
``y = 0``), the weak layer (``D_wl``, the bonded Cam-Clay of :mod:`mpm_warp.scenes.weak_layer`,
calibrated from its field quantities under this slab) and the elastic slab (``D``). ``x`` runs along
the column, ``y`` is normal to the bed; a slope of angle ``theta`` is a rotated gravity
``g (sin theta, -cos theta)`` (downslope is ``+x``). Plane strain in true 2D by default (``width =
0``, quantities per metre of depth); ``width > 0`` gives a free 3D column.

Run sequence (all on the device, no host loop):

1. settling: gravity ramps up over ``settle.gravity_ramp`` while the grid is damped until
   ``settle.duration``; the weak layer's hardening state and the slab base's position then are the
   references of the collapse and of the deflection;
2. the saw: from ``settle.duration`` on, a blade advances at ``saw.speed`` (at most 1 m/s) from one
   end of the column through the weak layer up to ``saw.cut_length``; behind it the layer loses its
   bond (a kerf), is cohesionless and collapses under the slab;
3. free run: the crack runs by itself or arrests.

With ``saw.stop = "runaway"`` (the field protocol, :mod:`.saw`) the blade stops where it is at the first frame
the crack has run away from it, so that what follows is the crack's own; a crack that never runs away before
the blade reaches ``saw.cut_length`` is "no propagation" (NP, :mod:`.outcome`).

Fronts (documented criteria, distances from the saw's end of the column, m; bins of ``front.bin``):

- damage front: a weak-layer particle is damaged once its bond ``1 - kappa/kappa_s`` has fallen to
  one half; a bin once the median of its particles' damage times has passed; the front is the far
  edge of the contiguous run of damaged bins from the cut end;
- slab-deflection front: the same with the slab base's particles, damaged once the base has come
  down by ``front.deflection`` (0.1) times the calibrated collapse height.

Speeds are profiles along the fronts' paths, the touchdown distance is measured behind the
deflection front, and the critical cut length comes from bisection on the saw's stop position
(:func:`critical_cut`, trial runs forked from one base run) or, from one run, the saw position when the
crack ran away from the blade (``runaway_cut``); :mod:`.analysis`.

Resolution: the weak layer must span at least three grid cells
(:data:`~mpm_warp.scenes.snow.MIN_WEAK_LAYER_CELLS`: the stencils of the slab and the substratum must not
share a grid node); four resolve it (the ready scenes).

Modules: :mod:`.params` (:class:`PSTParams` and its derived values), :mod:`.saw` (the saw, the front
criteria and the cut made by a saw that stopped on runaway), :mod:`.build`,
:mod:`.kernels` (the deflection tracker; the saw is the weak layer's), :mod:`.monitor`
(:class:`PSTMonitor`), :mod:`.analysis` (:func:`pst_summary`), :mod:`.critical` (:func:`critical_cut`:
bisection over trial runs forked from one base run); the closed forms in
:mod:`mpm_warp.scenes.references`.
"""

from ..contract import SceneType
from ..references import critical_cut_length_formula, heierli_speed, heierli_touchdown
from ..snow import SETTLE_TIME_KEYS
from .analysis import pst_summary
from .build import build
from .critical import CriticalCut, critical_cut, cut_run
from .from_profile import ProfileSource, expand_profile
from .monitor import PSTMonitor, attach
from .params import ColumnEnds, CutFrom, Front, PSTParams, Saw, SawStop, upgrade_table
from .saw import sawn

__all__ = ["SCENE", "PSTParams", "Saw", "SawStop", "sawn", "Front", "CutFrom", "ColumnEnds", "ProfileSource",
           "expand_profile",           "build", "attach", "PSTMonitor",
           "pst_summary", "critical_cut", "cut_run", "CriticalCut", "heierli_speed", "heierli_touchdown",
           "critical_cut_length_formula"]

SCENE = SceneType(
    kind="pst", params=PSTParams, build=build, attach=attach, time_keys=SETTLE_TIME_KEYS, upgrade=upgrade_table,
    expand=expand_profile,
    description="Propagation Saw Test: a slab on a weak layer, sawn from one end after settling; crack front, "
                "speed, touchdown and collapse")
