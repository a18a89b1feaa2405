"""The first time step of a scenario and what it must respect: the step budget and the stability limit.

The step is ``dt = cfl dx / (c_p + |v|)`` (``time.dt`` if fixed, capped by ``time.dt_max``). A run
may take at most :data:`MAX_STEPS` steps, an initial speed at most :data:`MAX_MACH` times the fastest
P-wave speed, and a fixed step at most the stability limit :data:`STABLE_DT` ``dx / c_p``
(docs/robustness.md). :func:`check_end_time` applies the budget to an end time given beside a
scenario (``Simulation.run``, ``resume``).
"""

from __future__ import annotations

import math
from typing import Any

from .checks import finite_number
from .errors import InvalidArgument

__all__ = ["MAX_STEPS", "MAX_MACH", "STABLE_DT", "first_step", "step_budget", "check_end_time", "run_times"]

#: most steps a run may need (its first step size times this reaches time.end): far beyond any snow experiment
#: (a PST of 1 s at dx = 2 mm takes ~1e6), so more means a typo in a modulus, a density, a speed or a time
MAX_STEPS = 1.0e8
#: fastest initial speed, in multiples of the fastest P-wave speed of the materials (snow: 70-300 m/s)
MAX_MACH = 100.0
#: the stability limit of a fixed step, in dx / c_p: measured 1.10 stable, 1.12 blowing up (docs/robustness.md);
#: a larger ``time.dt`` is refused unless ``time.allow_unstable_dt``
STABLE_DT = 1.11


def first_step(tc, dx: float, mats: dict, blocks) -> tuple[float, str, Any, str, float, str]:
    """The first step of a run, for the budget and stability checks (validated time, materials and blocks).

    ``dt = cfl dx / (c_p + |v|)`` (``time.dt`` if fixed, capped by ``time.dt_max``) with ``c_p`` the
    fastest P-wave speed of the materials in use and ``|v|`` the fastest constant initial speed (a
    Python velocity function is not evaluated here).

    Returns
    -------
    (dt [s], the field that sets it, its value, how it is set (words), c_p [m/s], the material's name)
    """
    name, fastest = max(((k, m) for k, m in mats.items() if any(b.material == k for b in blocks)),
                        key=lambda km: km[1].p_wave_speed)
    c_p = fastest.p_wave_speed
    vmax = max((math.sqrt(sum(c * c for c in b.velocity)) for b in blocks if not callable(b.velocity)), default=0.0)
    if tc.dt > 0:
        dt, field, value, why = tc.dt, "time.dt", tc.dt, "the fixed step"
    else:
        dt = tc.cfl * dx / (c_p + vmax)
        field, value = f"materials.{name} (E, density)", (fastest.E, fastest.density)
        why = (f"dt = cfl dx / (c_p + |v|) = {tc.cfl:g} x {dx:g} m / ({c_p:.3g} + {vmax:.3g} m/s) with c_p = "
               f"{c_p:.3g} m/s of materials.{name}")
    if tc.dt_max > 0 and tc.dt_max < dt:
        dt, field, value, why = tc.dt_max, "time.dt_max", tc.dt_max, "the step cap time.dt_max"
    return dt, field, value, why, c_p, name


def step_budget(tc, dx: float, mats: dict, blocks) -> None:
    """Refuse speeds, moduli and densities that would make a run take more than :data:`MAX_STEPS` steps,
    an initial speed above :data:`MAX_MACH` ``c_p``, and a fixed step above the stability limit
    :data:`STABLE_DT` ``dx / c_p`` (unless ``time.allow_unstable_dt``)."""
    dt, field, value, why, c_p, name = first_step(tc, dx, mats, blocks)
    for i, b in enumerate(blocks):
        if callable(b.velocity):
            continue
        speed = math.sqrt(sum(c * c for c in b.velocity))
        if speed > MAX_MACH * c_p:
            raise InvalidArgument(f"blocks[{i}].velocity", b.velocity, (
                f"a speed at most {MAX_MACH:g} times the fastest P-wave speed, {MAX_MACH * c_p:.3g} m/s "
                f"(c_p = {c_p:.3g} m/s of materials.{name}); |v| = {speed:.3g} m/s is Mach {speed / c_p:.3g}"))
    limit = STABLE_DT * dx / c_p
    if tc.dt > limit and not tc.allow_unstable_dt:
        raise InvalidArgument("time.dt", tc.dt, (
            f"a fixed step at most the stability limit {STABLE_DT:g} dx / c_p = {limit:.3g} s (dx = {dx:g} m, c_p = "
            f"{c_p:.3g} m/s of materials.{name}); it is {tc.dt / limit:.3g} times that (0 = the automatic step, "
            "or time.allow_unstable_dt = true for a stability study)"))
    steps = tc.end / dt
    if steps > MAX_STEPS:
        raise InvalidArgument(field, value, f"values giving at most {MAX_STEPS:.0e} steps to time.end = {tc.end:g} s: "
                              f"{why} makes dt = {dt:.3g} s and {steps:.3g} steps")


def check_end_time(scenario, value, field: str = "end_time") -> float:
    """An end time [s] given beside a validated ``scenario`` (``Simulation.run``, ``resume``), checked as
    ``time.end`` is: a finite number > 0 whose run takes at most :data:`MAX_STEPS` steps."""
    end = finite_number(field, value, lo=0.0, lo_open=True)
    dt, _, _, why, _, _ = first_step(scenario.time, scenario.domain.dx, scenario.materials, scenario.blocks)
    if end / dt > MAX_STEPS:
        raise InvalidArgument(field, value, f"a time giving at most {MAX_STEPS:.0e} steps: {why} makes dt = "
                              f"{dt:.3g} s and {end / dt:.3g} steps")
    return end


def run_times(scenario, end_time, frame_interval) -> tuple[float, float]:
    """End time and frame interval of a run of ``scenario`` [s]: the scenario's, or those given, checked as
    ``time.end`` (:func:`check_end_time`) and ``time.frame_interval`` are (finite, > 0, at most the end)."""
    tc = scenario.time
    end = tc.end if end_time is None else check_end_time(scenario, end_time)
    if frame_interval is None:
        return end, tc.frame_interval
    fi = finite_number("frame_interval", frame_interval, lo=0.0, lo_open=True)
    if fi > end:
        raise InvalidArgument("frame_interval", frame_interval, f"at most the end time {end:g} s")
    return end, fi
