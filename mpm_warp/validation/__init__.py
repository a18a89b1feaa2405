"""Reference problems with known answers, run at a chosen resolution (docs/validation.md).

Each problem runs one case at a grid spacing ``dx`` (and CFL factor or fixed
step, precision, device) and returns its error against the exact or closed-form
answer beside its run time: "a run that has a reference answer reports its
error beside its run time". The record (a plain dict) holds

``problem, dx, cfl, dt, error, signed_error, measured, reference, wall_time_s,
steps, n_particles, particle_steps_per_s, device, precision, warp_version,
n_threads, sim_time_s, dt_mean_s, details``

where ``error`` is relative and non-negative (defined per problem below),
``wall_time_s`` the stepping time of :meth:`Simulation.run` (kernel
compilation and the host-side measurements between frames excluded), ``dt``
the fixed step (s) or None for the automatic step ``cfl dx / c_p``.

Problems (:data:`PROBLEMS`)
---------------------------
:func:`axial_bar`
    Fixed-free bar in its first mode: period against ``4 L / c``.
:func:`self_weight_column`
    Column under self-weight with lateral rollers: RMS ``sigma_yy`` error against
    ``-rho g (H - Y)`` away from the floor.
:func:`weak_layer_collapse`
    Cam-Clay weak layer under an elastic slab: mean ``1 - J_P`` against the
    uniaxial-strain closed form of the hardening rule (:func:`oedometric_collapse`).

The set-ups, closed forms and measurements are the ones of the validation tests
(``tests/test_validation_elastic.py``, ``tests/test_weak_layer.py``); the
derivations are in those tests' docstrings. Every length is in m, time in s,
stress in Pa, density in kg/m^3. ``benchmarks/convergence/error_vs_runtime.py`` runs the
ladders of ``dx`` and CFL factor; their orders and times to an error are
:mod:`mpm_warp.studies.convergence`.
"""

from __future__ import annotations

from .common import G, com_velocity, zero_crossings
from .elastic import axial_bar, bar_period, column_scenario, fixed_free_bar, self_weight_column
from .weak_layer import (
    measure_column,
    oedometric_collapse,
    oedometric_state,
    run_column,
    weak_layer_collapse,
    weak_layer_column,
)

__all__ = [
    "PROBLEMS", "G", "axial_bar", "self_weight_column", "weak_layer_collapse",
    "fixed_free_bar", "bar_period", "column_scenario", "weak_layer_column", "run_column", "measure_column",
    "oedometric_collapse", "oedometric_state", "com_velocity", "zero_crossings",
]

#: the problems by name: ``PROBLEMS[name](dx, cfl=..., dt=..., precision=..., device=...) -> record``
PROBLEMS = {"axial_bar": axial_bar, "self_weight_column": self_weight_column,
            "weak_layer_collapse": weak_layer_collapse}
