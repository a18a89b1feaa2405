"""Registry of scene builders: high-level scene descriptions expanded into blocks.

A scenario file may carry a ``[scene]`` table with a ``kind`` (for example a
Propagation Saw Test). Its builder turns the high-level parameters into
materials, blocks and walls before validation. Files without ``[scene]`` (or
with ``kind = "blocks"``) are used as written.
"""

from __future__ import annotations

from collections.abc import Callable

from .errors import ScenarioError

__all__ = ["register_scene", "register_scene_hooks", "register_scene_monitor", "attach_monitor", "run_scene",
           "expand_scene", "attach_scene", "SCENE_BUILDERS", "SCENE_HOOKS"]

SCENE_BUILDERS: dict[str, Callable[[dict], dict]] = {}
#: scene kind -> ``attach(sim)``: adds the scene's device actions (``sim.stepper.actions``), frame
#: diagnostics (``sim.frame_diagnostics``) and result analyses (``sim.result_hooks``) to a Simulation
SCENE_HOOKS: dict[str, Callable] = {}


def register_scene(kind: str):
    """Decorator registering ``builder(raw_scenario_dict) -> raw_scenario_dict`` for ``scene.kind``."""

    def deco(fn):
        SCENE_BUILDERS[kind] = fn
        return fn

    return deco


def register_scene_hooks(kind: str, attach: Callable) -> None:
    """Register ``attach(sim)`` run by every :class:`~mpm_warp.Simulation` of scene kind ``kind``."""
    SCENE_HOOKS[kind] = attach


def attach_monitor(sim, monitor_cls):
    """Give ``sim`` one scene monitor of ``monitor_cls`` (idempotent) and record its frame series.

    The monitor is built with ``monitor_cls(sim)`` (it adds its device actions),
    kept as ``sim.scene_monitor``, and its ``frame_scalars(sim)`` with ``units()``
    join the simulation's frame diagnostics.
    """
    prev = getattr(sim, "scene_monitor", None)
    if isinstance(prev, monitor_cls):
        return prev
    mon = monitor_cls(sim)
    sim.scene_monitor = mon

    def diagnostics(s):
        return mon.frame_scalars(s)

    diagnostics.units = mon.units()
    sim.frame_diagnostics.append(diagnostics)
    return mon


def register_scene_monitor(kind: str, attach: Callable) -> None:
    """Register ``attach(sim) -> monitor`` for ``kind``; the monitor's ``summary()`` goes into ``RunResult.extra``."""

    def hook(sim):
        mon = attach(sim)
        if not getattr(mon, "_summary_hooked", False):
            sim.result_hooks.append(lambda s: mon.summary())
            mon._summary_hooked = True

    SCENE_HOOKS[kind] = hook


def run_scene(scenario, output=None, device=None, overrides=None, n_threads=None, **run_kwargs):
    """Load (name, path or Scenario) and run a scene; return ``(RunResult, sim.scene_monitor)``.

    The scene's hooks attach its device actions and diagnostics, so this is
    ``mpm_warp.run`` that also hands back the scene's monitor (series, summary).
    """
    from .scenario import Scenario, load_scenario
    from .simulation import Simulation

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(str(scenario), overrides)
    sim = Simulation(scenario, device=device, n_threads=n_threads)
    res = sim.run(output, **run_kwargs)
    return res, getattr(sim, "scene_monitor", None)


def attach_scene(sim) -> None:
    """Run the registered hooks of the simulation's scene kind (no-op for plain block scenes)."""
    kind = (sim.scenario.scene or {}).get("kind", "blocks")
    _load_builtin_scenes()
    hook = SCENE_HOOKS.get(kind)
    if hook is not None:
        hook(sim)


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
    _load_builtin_scenes()
    if kind not in SCENE_BUILDERS:
        known = ", ".join(["blocks", *sorted(SCENE_BUILDERS)])
        raise ScenarioError(f"{source}: scene.kind = {kind!r} is unknown; known: {known}")
    return SCENE_BUILDERS[kind](raw)


def _load_builtin_scenes() -> None:
    """Import the scene modules shipped with the library (they register themselves)."""
    from . import pst, shear_test  # noqa: F401
