"""The weak layer of the snow scenes: parameters in field quantities, their calibration, the run's bookkeeping.

The layer is the engine's bonded Cam-Clay (:class:`~mpm_warp.materials.BondedCamClay`,
``kernels/bonded_camclay.py``): strong while its bonds hold, softening over a plastic slip that
costs a fracture energy, then collapsing under the slab (the anticrack). Modules:

- :mod:`.params`: :class:`WeakLayer`, the field quantities (shear strength, fracture energy or
  softening slip, collapse height) a scene takes;
- :mod:`.calibration`: :func:`weak_layer_material`, the one place they become model parameters
  (``p_bond``, ``kappa_s``, ``xi``), with the predictions the scenes compare with
  (:class:`CalibratedWeakLayer`); :mod:`.paths`: the material-point reference paths it uses;
- :mod:`.kernels` and :mod:`.tracker`: the saw's kerf, the collapse reference and the damage
  arrival times of one run (:class:`WeakLayerTracker`), and the ``log_jp_ref`` output field.
"""

from .calibration import CalibratedWeakLayer, stored_calibration, weac_collapse_height, weak_layer_material
from .kernels import weak_layer_kernel
from .params import WeakLayer
from .tracker import DAMAGE_BOND, ReferenceField, WeakLayerTracker, bin_median

__all__ = ["WeakLayer", "CalibratedWeakLayer", "stored_calibration", "weak_layer_material", "weac_collapse_height",
           "WeakLayerTracker", "ReferenceField", "weak_layer_kernel", "DAMAGE_BOND", "bin_median"]
