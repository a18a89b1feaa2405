"""The reference problems as an API (mpm_warp.validation): one coarse run each, on the CPU.

Each function returns the fixed record (error beside run time). Bounds are the
validation tests' tolerances at the same resolutions; measured (CPU, this
commit): bar period +0.72 % at dx = 1 (float32), column RMS stress error
1.17 % at H/8 (float64), weak-layer collapse -1.50 % at 8 cells across the layer
(float64).
"""

from __future__ import annotations

import math

import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

from mpm_warp import InvalidArgument
from mpm_warp.validation import PROBLEMS, axial_bar, self_weight_column, weak_layer_collapse

FIELDS = {"problem", "dx", "cfl", "dt", "error", "signed_error", "measured", "reference", "wall_time_s", "steps",
          "n_particles", "particle_steps_per_s", "device", "precision", "warp_version", "n_threads",
          "sim_time_s", "dt_mean_s", "details"}


def _check_record(r: dict, problem: str, dx: float, bound: float) -> None:
    assert FIELDS <= set(r), f"missing fields {FIELDS - set(r)}"
    assert r["problem"] == problem and r["dx"] == dx and r["device"] == DEVICE
    assert math.isfinite(r["error"]) and 0.0 <= r["error"] < bound, r["error"]
    assert r["error"] == abs(r["signed_error"])
    assert r["wall_time_s"] > 0.0 and r["steps"] > 0 and r["n_particles"] > 0
    assert r["particle_steps_per_s"] == pytest.approx(r["n_particles"] * r["steps"] / r["wall_time_s"])
    assert r["warp_version"] and r["precision"] in ("float32", "float64")


def test_axial_bar_record():
    """Mode-1 period of the fixed-free bar at dx = 1 (25 cells): within 1 % of 4 L / c = 10 s."""
    r = axial_bar(1.0, device=DEVICE)
    _check_record(r, "axial_bar", 1.0, 0.01)
    assert r["reference"] == pytest.approx(10.0)
    assert r["signed_error"] > 0.0  # the discrete bar is slightly too soft: period too long
    assert r["dt"] is None and r["cfl"] == 0.4
    assert r["dt_mean_s"] == pytest.approx(0.4 * 1.0 / 10.0, rel=0.05)  # CFL step, not the frame interval


def test_axial_bar_fixed_step():
    """A fixed step is honoured and reported."""
    r = axial_bar(1.0, dt=0.02, device=DEVICE)
    _check_record(r, "axial_bar", 1.0, 0.01)
    assert r["dt"] == 0.02
    assert r["dt_mean_s"] == pytest.approx(0.02, rel=1e-6)


def test_self_weight_column_record():
    """Column under self-weight at H/8: RMS sigma_yy error away from the floor below 2 % of rho g H."""
    r = self_weight_column(1.0 / 8.0, device=DEVICE)
    _check_record(r, "self_weight_column", 1.0 / 8.0, 0.02)
    assert r["precision"] == "float64"
    assert r["details"]["samples"] == 20
    assert r["measured"] == pytest.approx(r["reference"], rel=0.02)


@pytest.mark.slow
def test_weak_layer_collapse_record():
    """Weak layer under a slab, 8 cells across it: mean 1 - J_P within 3 % of the closed form."""
    r = weak_layer_collapse(1.0 / 256.0, device=DEVICE)
    _check_record(r, "weak_layer_collapse", 1.0 / 256.0, 0.03)
    assert 0.05 < r["reference"] < 0.15  # xi 0.04, slab rho 1200: 0.0907
    assert r["details"]["cells_across_layer"] == 8


def test_registry_and_bad_dx():
    """Every problem is registered; a dx that does not fit the geometry fails naming dx."""
    assert set(PROBLEMS) == {"axial_bar", "self_weight_column", "weak_layer_collapse"}
    with pytest.raises(InvalidArgument, match="dx"):
        axial_bar(0.3, device=DEVICE)
    with pytest.raises(InvalidArgument, match="dx"):
        weak_layer_collapse(0.01, device=DEVICE)
