"""Shear test of the weak layer (SI Note 2, issue 10): layout, and runs at 4 and 8 cells across the layer.

Checks: the whole sample's peak is the given shear strength less the free ends' share, ``a - b / L`` of
the free-ends study, within 1 % (the interior's, away from the free ends, within 3 % of the strength),
softening slip 2 +/- 0.5 mm for the SI's 2 mm, residual below the peak, the collapse between the
Cam-Clay law at the push's largest pressure with ``p0 = p_max`` and ``p0 = 2 p_max`` (critical state),
and peak and softening within 5 % between 4 and 8 cells through the layer.
"""

import math

import numpy as np
import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.errors import ScenarioError
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.shear_test import shear_curves

G = 9.81

#: The whole sample's peak over tau_p against its length L (m): a - b / L, fitted over L = 0.3, 0.6, 1.2 m by
#: benchmarks/snow/shear_free_ends.py (results/shear_free_ends_cpu.json, ``fit``; residuals below 2e-4):
#: the free ends unload a fixed length of the sample. The default sample is 0.3 m long.
FREE_ENDS_FIT = {4: (0.9791368326841222, 0.01814756459168516), 8: (0.9895966302871481, 0.01898580717999153)}


def test_shear_test_layout():
    sc = load_scenario("shear_test")
    s = sc.scene
    sigma_n = 250.0 * G * 0.5
    assert s.sigma_n == pytest.approx(sigma_n)
    assert sc.materials["load"].density == pytest.approx(sigma_n / (G * s.load_thickness))
    assert sc.materials["weak_layer"] == s.calibrated().material
    assert s.weak_layer.delta_s == 0.002 and s.weak_layer.tau_p == 1000.0   # the SI's case
    blocks = {b.name: b for b in sc.blocks}
    assert blocks["weak_layer"].hi[:2] == pytest.approx((s.sample_length, s.weak_layer_thickness))
    assert blocks["load"].lo[1] == pytest.approx(s.weak_layer_thickness)
    assert blocks["load"].hi[0] == pytest.approx(s.sample_length)
    (floor,) = sc.walls  # the push is a device action on the loading plate, not a wall
    assert floor.kind == "sticky"
    assert s.push_start == s.settle.duration


def test_shear_test_bad_input():
    with pytest.raises(ScenarioError, match="scene.wall_sped"):
        load_scenario("shear_test", ["scene.wall_sped=0.1"])


def _run(cells: int):
    sc = load_scenario("shear_test")
    dx = sc.scene.weak_layer_thickness / cells
    # 3.5 mm of push: past the peak (~0.1 mm), the softening (~2 mm of the layer's slip, ~2.7 mm of the
    # plate's) and the collapse (over by 0.44 s) into the residual
    res = mw.run("shear_test", device=DEVICE, n_threads=1,
                 overrides=[f"scene.dx={dx!r}", "time.end=0.45", "time.frame_interval=0.001"])
    return res


@pytest.fixture(scope="module")
def runs():
    return {n: _run(n) for n in (4, 8)}


@pytest.mark.slow
@pytest.mark.parametrize("cells", [4, 8])
def test_shear_test_peak_softening_collapse(runs, cells):
    res = runs[cells]
    ex = res.scene_result
    mon = res.monitor
    c = shear_curves(mon.params, mon.times, {k: np.asarray(v) for k, v in mon.series.items()})
    assert c["bond"][0] > 0.999                        # intact under the slab's load when the push starts
    # the whole sample's peak: the given strength less the free ends' share (0.919 and 0.926 tau_p here); a
    # change at the free ends or in the layer's peak moves it by more than 1 %
    a, b = FREE_ENDS_FIT[cells]
    expected = (a - b / mon.params.sample_length) * ex["tau_p_calibrated"]
    assert ex["peak_shear_stress"] == pytest.approx(expected, rel=0.01)
    # softening over the SI's ~2 mm of slip (the layer's own slip, top row against bottom row)
    assert ex["bond_lost"] and ex["softening_displacement"] == pytest.approx(0.002, abs=0.0005)
    assert ex["residual_shear_stress"] < 0.8 * ex["peak_shear_stress"]
    # collapse beside the law: more than the oedometric law at rest (q = 0, sigma_n), and within the Cam-Clay law
    # at the largest mean pressure of the push (the load falling into the debonded layer: ~1270 Pa, where the
    # final pressure, ~740 Pa, comes after it unloads): p0 = p_max (the cap) to 2 p_max (critical state),
    # 0.208-0.372 with 0.267 at 4 cells. The old bound, the critical state at the final pressure (+ 0.02), was
    # below the committed 8 mm benchmark's collapse (0.267 > 0.257, 0.289 > 0.269): it took the wrong pressure.
    assert ex["collapse_fraction_law"] < ex["collapse_fraction"]
    assert ex["collapse_fraction_isotropic_at_p_max"] < ex["collapse_fraction"] \
        < ex["collapse_fraction_critical_state_at_p_max"]
    assert ex["p_max"] > 1.5 * ex["p_final"]                 # the overshoot, not the final pressure, compacts it
    # the collapse is complete by 0.44 s: the benchmark's (8 mm of push) to 1 %
    assert ex["collapse_fraction"] == pytest.approx({4: 0.2674802401676202, 8: 0.28889560642261286}[cells], rel=0.01)
    # displacement control: the plate moves at the push speed once the push has started
    assert c["u"][-1] == pytest.approx(0.01 * (c["t"][-1] - c["t"][0]), rel=0.05)


@pytest.mark.slow
@pytest.mark.parametrize("cells", [4, 8])
def test_shear_test_interior_reaches_tau_p(runs, cells):
    """Away from the traction-free ends (one layer thickness) the layer's own peak is within 3 % of the given
    tau_p; the whole sample's is lower by the ends' share, which falls as 1/L (benchmarks/snow/shear_free_ends.py:
    an endless sample's peak 2 % and 1 % below tau_p at 4 and 8 cells)."""
    ex = runs[cells].scene_result
    assert ex["interior_peak_shear_stress"] == pytest.approx(ex["tau_p_calibrated"], rel=0.03)
    assert ex["peak_shear_stress"] < ex["interior_peak_shear_stress"]


@pytest.mark.slow
def test_shear_test_converges_across_4_and_8_cells(runs):
    a, b = runs[4].scene_result, runs[8].scene_result
    assert a["peak_shear_stress"] == pytest.approx(b["peak_shear_stress"], rel=0.05)
    assert a["softening_displacement"] == pytest.approx(b["softening_displacement"], rel=0.05)
    assert math.isfinite(a["w_f_calibrated"]) and a["w_f_calibrated"] > 0
