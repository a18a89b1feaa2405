"""Registry of scene builders: high-level scene descriptions expanded into blocks.

A scenario file may carry a ``[scene]`` table with a ``kind`` (for example a
Propagation Saw Test). Its builder turns the high-level parameters into
materials, blocks and walls before validation. Files without ``[scene]`` (or
with ``kind = "blocks"``) are used as written.
"""

from __future__ import annotations

from collections.abc import Callable

from .errors import ScenarioError

__all__ = ["register_scene", "expand_scene", "SCENE_BUILDERS"]

SCENE_BUILDERS: dict[str, Callable[[dict], dict]] = {}


def register_scene(kind: str):
    """Decorator registering ``builder(raw_scenario_dict) -> raw_scenario_dict`` for ``scene.kind``."""

    def deco(fn):
        SCENE_BUILDERS[kind] = fn
        return fn

    return deco


def expand_scene(raw: dict, source: str = "scenario") -> dict:
    """Expand ``raw["scene"]`` with its registered builder (no-op for plain block scenes)."""
    scene = raw.get("scene")
    if not scene:
        return raw
    if not isinstance(scene, dict):
        raise ScenarioError(f"{source}: [scene] must be a table")
    kind = scene.get("kind", "blocks")
    if kind == "blocks":
        return raw
    if kind not in SCENE_BUILDERS:
        known = ", ".join(["blocks", *sorted(SCENE_BUILDERS)])
        raise ScenarioError(f"{source}: scene.kind = {kind!r} is unknown; known: {known}")
    return SCENE_BUILDERS[kind](raw)
