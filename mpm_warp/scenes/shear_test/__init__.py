"""Unconfined shear test of the weak layer under the slab's normal load (SI Note 2).

A weak-layer sample (length ``L_s``, thickness ``D_wl``) bonded to a sticky substratum at ``y = 0``
carries a loading block that applies the slab's bed-normal stress ``sigma_n = rho_slab g D
cos(theta)``: a thin elastic block of thickness ``t`` and density ``sigma_n / (g t)`` (the same load as
the full slab, with a shorter time step and far fewer particles than a 0.5 m slab). The block is the
test's moving top: a device action (:func:`~.kernels.push_kernel`) holds its particles' ``x``
velocity at 0 while settling and at ``wall_speed`` (0.01 m/s in SI Note 2) from the end of settling
on (displacement control, as the SI's wall pushing the slab); its vertical motion is free, so the
layer can collapse. The impulse the action gives is summed: the push force. (An engine wall pushing
the block's face would act on the grid nodes behind its plane only, so its grip would jump from node
to node as it travels.) The weak layer's failure rule is in :mod:`mpm_warp.scenes.weak_layer`.

Modules: :mod:`.params` (:class:`ShearTestParams`), :mod:`.build`, :mod:`.kernels` (the push),
:mod:`.monitor` (:class:`ShearMonitor`, its frame scalars), :mod:`.analysis` (:func:`shear_curves`
takes displacements from the start of the push; :func:`shear_summary`: peak, residual, softening).
"""

from ..contract import SceneType
from ..snow import SETTLE_TIME_KEYS
from .analysis import ShearSummary, analyze_shear_series, shear_curves, shear_summary
from .build import build
from .monitor import ShearMonitor, attach
from .params import ShearTestParams, SlabLoad

__all__ = ["SCENE", "ShearTestParams", "SlabLoad", "build", "attach", "ShearMonitor", "shear_curves",
           "shear_summary", "ShearSummary", "analyze_shear_series"]

SCENE = SceneType(
    kind="shear_test", params=ShearTestParams, build=build, attach=attach, time_keys=SETTLE_TIME_KEYS,
    description="Unconfined shear test of the weak layer under the slab's load, pushed at a constant speed after "
                "settling; peak and residual strength, softening, collapse")
