"""Snow scenes on top of the engine: the registry by kind and the scene contract.

A scene kind is one :class:`~mpm_warp.scenes.contract.SceneType` (typed parameters, ``build``,
``attach``; the contract is documented in :mod:`mpm_warp.scenes.contract`):

- ``"pst"``: Propagation Saw Test (:mod:`mpm_warp.scenes.pst`);
- ``"shear_test"``: unconfined shear test of the weak layer (:mod:`mpm_warp.scenes.shear_test`).

Shared pieces: :mod:`.snow` (slab, settling, slab load, plane-strain box), :mod:`.weak_layer` (the
weak layer's parameters, failure rule and device state), :mod:`.fronts` (crack fronts in plain
arrays), :mod:`.series` (a monitor's frame series and checkpoint state). The engine knows none of
this: it runs a :class:`~mpm_warp.Scenario` and calls the monitors it is given.
"""

from __future__ import annotations

from ..errors import ScenarioError
from . import pst, shear_test
from .contract import SceneType

__all__ = ["SCENES", "SceneType", "scene_type", "attach", "pst", "shear_test"]

#: the scene kinds by name
SCENES: dict[str, SceneType] = {s.kind: s for s in (pst.SCENE, shear_test.SCENE)}


def scene_type(kind, source: str = "scene") -> SceneType:
    """The :class:`SceneType` of ``kind``; :class:`ScenarioError` listing the known kinds otherwise."""
    if not isinstance(kind, str) or kind not in SCENES:
        raise ScenarioError(f"{source}: scene.kind = {kind!r} is unknown; known: {', '.join(['blocks', *SCENES])}")
    return SCENES[kind]


def attach(sim):
    """Attach the monitor of ``sim``'s scene (None for a scenario without a scene)."""
    scene = sim.scenario.scene
    return None if scene is None else scene_type(scene.kind).attach(sim)
