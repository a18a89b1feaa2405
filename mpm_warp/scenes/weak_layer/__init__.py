"""The weak layer of the snow scenes: its parameters, its device action and its state during a run.

Everything about the weak layer's scene physics lives here (the engine's Cam-Clay aside):

- :mod:`.params`: :class:`WeakLayer`, the Cam-Clay parameters and the failure rule's settings;
- :mod:`.kernels`: :func:`weak_layer_kernel`, the collapse reference and the brittle rule: from the
  end of settling on, a particle whose stress reaches the yield surface loses its cohesion at once
  (``log_jp -> max(log_jp, failure_log_jp)``) and then compacts under the slab until the hardening
  law carries the load (the anticrack's collapse). Why: the engine's associative return softens only
  through plastic dilation, which the slab's weight stops at the critical state, and compaction on
  the cap only hardens, so without it no crack runs by itself (checked: with ``failure = "none"`` the
  front stops at the saw). Gaume et al. (2018) obtain the softening with a non-associative flow rule;
  this rule is its brittle limit, implemented without touching the engine;
- :mod:`.tracker`: :class:`WeakLayerTracker`, the device arrays (reference, failure flags) of one
  run and their checkpoint state; :class:`ReferenceField`, the ``log_jp_ref`` output field of a
  monitor (the collapse reference of :mod:`mpm_warp.post.fields`).

Replacing the weak layer's physics means replacing these three modules; the PST and shear-test
scenes use them through :class:`WeakLayer` and :class:`WeakLayerTracker` only.
"""

from .kernels import weak_layer_kernel
from .params import FAILURE_RULES, WeakLayer
from .tracker import FAILED, INTACT, SAWN, ReferenceField, WeakLayerTracker

__all__ = ["WeakLayer", "WeakLayerTracker", "ReferenceField", "weak_layer_kernel", "FAILURE_RULES", "INTACT",
           "FAILED", "SAWN"]
