"""The health check of a running simulation: device flags read back as one clear error.

One launch over all particles flags the first non-finite ``x``, ``v`` or ``F_E`` and the first
particle that moved more than :data:`MAX_CELLS_PER_STEP` cells in its last step (``|v| dt > dx``);
in plane strain one launch per plastic group flags a non-finite ``F_E,zz``. With
``output.on_inversion = "stop"`` the inversions and singular-value floor events the step counted
stop the run too. Any of them raises :class:`~mpm_warp.errors.SimulationBlowUp` naming the step,
the particle, the field and the cause. The host reads three integers (and the event counts).
"""

from __future__ import annotations

import warp as wp

from .errors import SimulationBlowUp
from .kernels.diagnostics import INT_MAX, health_kernel, health_zz_kernel

__all__ = ["MAX_CELLS_PER_STEP", "MIN_DT_SHARE", "check_health"]

#: a particle may not move more than this many cells in one step (health check)
MAX_CELLS_PER_STEP = 1.0
#: a step below this share of the elastic step (``cfl dx / c_p``) means a nodal speed a million times the
#: P-wave speed, or a non-finite one: the run stops instead of crawling (or, at a step of 0, never ending)
MIN_DT_SHARE = 1e-6


def check_health(sim, bad: wp.array) -> None:
    """Run the device health check of simulation ``sim``; raise SimulationBlowUp on failure.

    Parameters
    ----------
    sim : Simulation
        The simulation (its state, model, stepper and ``output.on_inversion``).
    bad : wp.array
        Three int32 flags on ``sim.device``, reset here: the smallest offending particle index per
        cause (``kernels/diagnostics.py``, :func:`~mpm_warp.kernels.diagnostics.health_kernel`).
    """
    bad.fill_(INT_MAX)
    s = sim.state
    T = sim.model.T
    wp.launch(health_kernel(sim.model.dim, T), sim.model.n_particles,
              inputs=[s.x, s.v, s.H, s.clock, T(sim.model.dx), T(MAX_CELLS_PER_STEP), bad],
              device=sim.device)
    if s.hzz is not None:
        for g in sim.model.groups:
            if g.plastic_start >= 0:
                hzz = s.hzz[g.plastic_start:g.plastic_start + g.count]
                wp.launch(health_zz_kernel(T), g.count, inputs=[hzz, g.start, bad], device=sim.device)
    flags = bad.numpy()
    causes = [("x/v/F", "non-finite value (NaN or Inf)"),
              ("v", f"moved more than {MAX_CELLS_PER_STEP:g} cell in one step (|v| dt > dx): "
                    "time step too large for this speed; lower time.cfl or time.dt")]
    for k, (fld, cause) in enumerate(causes):
        if flags[k] != INT_MAX:
            t, dt, steps = sim.stepper.clock()
            raise SimulationBlowUp(steps, int(flags[k]), fld, f"{cause} at t = {t:.6g} s")
    if sim.scenario.output.on_inversion == "stop":
        floors, inversions = sim.stepper.deformation_events()
        if floors or inversions:
            t, dt, steps = sim.stepper.clock()
            raise SimulationBlowUp(steps, -1, "F", (
                f"{inversions} inversion{'s' * (inversions != 1)} (det F_tr <= 0) and {floors} singular-value "
                f"floor event{'s' * (floors != 1)} by t = {t:.6g} s (output.on_inversion = 'stop'; 'report' "
                "runs on and counts them)"))
