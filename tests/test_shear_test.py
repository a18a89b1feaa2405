"""Shear test of the weak layer (SI Note 2): scene builder and a coarse run with peak and softening."""

import numpy as np
import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.errors import ScenarioError
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.shear_test import shear_curves

G = 9.81


def test_shear_test_layout():
    sc = load_scenario("shear_test")
    s = sc.scene
    sigma_n = 250.0 * G * 0.5
    assert s.sigma_n == pytest.approx(sigma_n)
    assert sc.materials["load"].density == pytest.approx(sigma_n / (G * s.load_thickness))
    assert sc.materials["weak_layer"].p0_ini == pytest.approx(3.0 * sigma_n)
    blocks = {b.name: b for b in sc.blocks}
    assert blocks["weak_layer"].hi[:2] == pytest.approx((s.sample_length, s.weak_layer_thickness))
    assert blocks["load"].lo[1] == pytest.approx(s.weak_layer_thickness)
    assert blocks["load"].hi[0] == pytest.approx(s.sample_length)
    (floor,) = sc.walls  # the push is a device action on the loading block, not a wall
    assert floor.kind == "sticky"
    assert s.push_start == s.settle.duration


def test_shear_test_bad_input():
    with pytest.raises(ScenarioError, match="scene.wall_sped"):
        load_scenario("shear_test", ["scene.wall_sped=0.1"])


#: coarse shear test: 1 cm grid (2 cells across the layer), 3 mm of push, 0.4 s
COARSE = ["scene.dx=0.01", "time.end=0.4", "time.frame_interval=0.001"]


def test_shear_test_peak_then_softening():
    res = mw.run("shear_test", device=DEVICE, overrides=COARSE, n_threads=1)
    mon = res.monitor
    series = {k: np.asarray(v) for k, v in mon.series.items()}
    c = shear_curves(mon.params, mon.times, series)
    ex = res.scene_result
    n0 = len(mon.times) - len(c["tau"])
    failed = series["failed_fraction"][n0:]
    assert failed[0] == 0.0  # at rest under the slab's load the layer is intact
    ip = int(np.argmax(c["tau"]))
    assert 0 < ip < len(c["tau"]) - 5
    # peak: elastic loading up to a strength of the order of the normal load (Cam-Clay, M = 1.2)
    assert 100.0 < ex["peak_shear_stress"] < 2.0 * ex["sigma_n"]
    assert failed[ip] < 0.5
    # softening: the stress falls well below the peak afterwards, the layer fails and collapses
    assert c["tau"][ip:].min() < 0.5 * ex["peak_shear_stress"]
    assert ex["residual_shear_stress"] < ex["peak_shear_stress"]
    assert failed[-1] > 0.9
    # collapse: about the hardening law's value under sigma_n (20 %), SI Note 2 reports ~20 %
    assert ex["collapse_fraction"] == pytest.approx(ex["collapse_fraction_law"], abs=0.06)
    assert np.isfinite(ex["softening_displacement"]) and ex["softening_displacement"] > 0.0
    # displacement control: the block moves at the push speed once the push has started
    u = c["u"]
    assert u[-1] == pytest.approx(0.01 * (c["t"][-1] - c["t"][0]), rel=0.05)
    # the layer's own mean shear stress is lower (free ends, grid coupling of the driven top) but of that order
    late = c["t"] > c["t"][-1] - 0.1
    layer = series["layer_shear_stress"][n0:]
    assert 0.4 * np.mean(c["tau"][late]) < np.mean(layer[late]) < np.mean(c["tau"][late])
