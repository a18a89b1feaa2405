"""mpm_warp: Material Point Method in NVIDIA Warp for dynamic anticrack propagation in snow.

After Gaume, Gast, Teran, van Herwijnen and Jiang (2018), "Dynamic anticrack
propagation in snow", Nature Communications 9:3047. MLS-MPM with quadratic
B-splines, Hencky St Venant-Kirchhoff elasticity and cohesive Cam-Clay
plasticity; runs on CUDA when present and on the CPU otherwise.

The one way to run anything is :func:`run` (a scenario, a TOML file or a ready
scene) and :func:`resume`; the layers are described in ``docs/architecture.md``.
"""

from __future__ import annotations

import os

import warp as _wp

from .version import __version__

# Kernel compilation and cache messages are noise for users; MPM_WARP_VERBOSE=1 shows them.
if not os.environ.get("MPM_WARP_VERBOSE"):
    _wp.config.quiet = True
    if hasattr(_wp, "LOG_WARNING"):
        _wp.config.log_level = _wp.LOG_WARNING

from .config import Block, Domain, Output, Scenario, TimeControl  # noqa: E402
from .errors import InvalidArgument, MPMError, OutputError, ScenarioError, SimulationBlowUp  # noqa: E402
from .io import RunData, read_run  # noqa: E402
from .loader import apply_overrides, list_scenes, load_scenario, scenarios_dir  # noqa: E402
from .materials import BondedCamClay, CamClaySnow, CrackingSnow, Elastic  # noqa: E402
from .result import RunResult  # noqa: E402
from .runner import resume, run  # noqa: E402
from .simulation import Simulation  # noqa: E402
from .walls import Wall, box_walls  # noqa: E402

__all__ = [
    "Block", "BondedCamClay", "CamClaySnow", "CrackingSnow", "Domain", "Elastic", "InvalidArgument", "MPMError",
    "Output", "OutputError",
    "RunData", "RunResult", "Scenario", "ScenarioError", "Simulation", "SimulationBlowUp", "TimeControl",
    "Wall", "apply_overrides", "box_walls", "list_scenes", "load_scenario", "read_run", "resume", "run",
    "scenarios_dir", "__version__",
]
