"""mpm_warp: Material Point Method in NVIDIA Warp for dynamic anticrack propagation in snow.

After Gaume, Gast, Teran, van Herwijnen and Jiang (2018), "Dynamic anticrack
propagation in snow", Nature Communications 9:3047. MLS-MPM with quadratic
B-splines, Hencky St Venant-Kirchhoff elasticity and cohesive Cam-Clay
plasticity; runs on CUDA when present and on the CPU otherwise.
"""

from __future__ import annotations

import os

import warp as _wp

__version__ = "0.1.0"

# Kernel compilation and cache messages are noise for users; MPM_WARP_VERBOSE=1 shows them.
if not os.environ.get("MPM_WARP_VERBOSE"):
    _wp.config.quiet = True
    if hasattr(_wp, "LOG_WARNING"):
        _wp.config.log_level = _wp.LOG_WARNING


def scenarios_dir() -> str:
    """Folder of the ready scenes (TOML files)."""
    from importlib.resources import files

    return str(files("mpm_warp.scenarios"))


from .errors import InvalidArgument, MPMError, OutputError, ScenarioError, SimulationBlowUp  # noqa: E402
from .io import RunData, read_run  # noqa: E402
from .materials import BondedCamClay, CamClaySnow, Elastic  # noqa: E402
from .scenario import Block, Domain, Output, Scenario, TimeControl, apply_overrides, load_scenario  # noqa: E402
from .simulation import RunResult, Simulation, resume  # noqa: E402
from .walls import Wall, box_walls  # noqa: E402


def run(scenario, output: str | None = None, device: str | None = None, overrides=None, **kwargs) -> RunResult:
    """Load (if given a path or scene name) and run a scenario; return the :class:`RunResult`."""
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(os.fspath(scenario), overrides)
    return Simulation(scenario, device=device).run(output, **kwargs)


__all__ = [
    "Block", "BondedCamClay", "CamClaySnow", "Domain", "Elastic", "InvalidArgument", "MPMError", "Output",
    "OutputError", "RunData", "RunResult", "Scenario", "ScenarioError", "Simulation", "SimulationBlowUp", "TimeControl",
    "Wall", "apply_overrides", "box_walls", "load_scenario", "read_run", "resume", "run", "scenarios_dir",
    "__version__",
]
