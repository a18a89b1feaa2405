"""Propagation Saw Test: scene builder, saw and front kernels, and a small PST run end to end."""

import math

import numpy as np
import pytest
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp import read_run
from mpm_warp.errors import InvalidArgument, ScenarioError
from mpm_warp.kernels.types import mat33, vec3
from mpm_warp.loader import load_scenario, scenario_from_dict
from mpm_warp.scenes.pst.kernels import pst_action_kernel
from mpm_warp.scenes.weak_layer import weak_layer_kernel

G = 9.81


# ----------------------------------------------------------------------------- builder
def test_pst_flat_layout():
    sc = load_scenario("pst_flat")
    s = sc.scene
    L, D, Dwl = s.length, s.slab_thickness, s.weak_layer_thickness
    blocks = {b.name: b for b in sc.blocks}
    assert blocks["weak_layer"].lo == (0.0, 0.0, 0.0) and blocks["weak_layer"].hi[:2] == (L, Dwl)
    assert blocks["slab"].lo[1] == Dwl and blocks["slab"].hi[1] == pytest.approx(Dwl + D)
    assert blocks["slab"].hi[2] == pytest.approx(sc.domain.dx)  # plane strain: one cell in z
    assert sc.domain.boundary == "slip" and sc.domain.boundary_faces == "z"
    (floor,) = sc.walls
    assert floor.kind == "sticky" and floor.normal == (0.0, 1.0, 0.0)
    assert sc.time.gravity == pytest.approx((0.0, -G, 0.0))
    assert sc.time.damping_until == s.settle.duration == s.saw_start
    sigma_n = 250.0 * G * D
    assert sc.materials["weak_layer"].p0_ini == pytest.approx(3.0 * sigma_n)
    assert s.sigma_n == pytest.approx(sigma_n)
    # the hardening law gives ~20 % collapse under this slab (how xi was chosen)
    assert s.references()["collapse_fraction_law"] == pytest.approx(0.20, abs=0.005)
    assert len(s.markers()) == round(L / s.marker_spacing)


def test_pst_slope_rotates_gravity():
    sc = load_scenario("pst_slope")
    th = math.radians(sc.scene.slope_angle)
    assert sc.time.gravity == pytest.approx((G * math.sin(th), -G * math.cos(th), 0.0))
    assert sc.scene.sigma_n == pytest.approx(250.0 * G * 0.5 * math.cos(th))


def test_pst_width_gives_3d_column():
    sc = load_scenario("pst_demo", ["scene.width=0.1"])
    assert sc.domain.boundary == "none"
    assert all(b.hi[2] == pytest.approx(0.1) for b in sc.blocks)


@pytest.mark.parametrize("override, match", [
    ("scene.slab.Ee=1e6", "scene.slab.Ee"),
    ("scene.weak_layer_thickness=0.02", "cells"),
    ("scene.saw.from_end='middle'", "from_end"),
    ("time.gravity=[0.0, -9.81, 0.0]", "time.gravity"),
    ("scene.weak_layer.failure='ductile'", "failure"),
])
def test_pst_bad_input(override, match):
    with pytest.raises((ScenarioError, InvalidArgument), match=match):
        load_scenario("pst_demo", [override])


def test_pst_generated_sections_are_not_accepted():
    raw = {"scene": {"kind": "pst"}, "blocks": [], "time": {"end": 1.0, "frame_interval": 0.1}}
    with pytest.raises(ScenarioError, match="generated"):
        scenario_from_dict(raw)


def test_pst_scene_round_trips_through_the_run_file_dict():
    """The typed parameters survive Scenario.to_dict (run files, checkpoints): resume rebuilds the same scene."""
    from mpm_warp.loader import resolved_scenario

    sc = load_scenario("pst_slope", ["scene.saw.from_end='right'", "scene.substratum='separate'"])
    back = resolved_scenario(sc.to_dict())
    assert back == sc and back.scene.saw.from_end == "right" and back.walls[0].kind == "separate"


# ----------------------------------------------------------------------------- kernels
@pytest.mark.parametrize("T", [wp.float32, wp.float64])
def test_saw_and_front_tracker(T):
    npT = np.float32 if T == wp.float32 else np.float64
    n = 11
    xs = np.zeros((n, 3), npT)
    xs[:, 0] = (np.arange(n) + 0.5) * 0.1  # 0.05, 0.15, ..., 1.05 m: particle i in bin i
    x = wp.array(xs, dtype=vec3(T), device=DEVICE)
    ljp0 = np.full(n, -0.5, npT)
    ljp0[7] = -0.5 + math.log(0.9)  # particle 7 collapsed by 10 % since the reference
    log_jp = wp.array(ljp0, dtype=T, device=DEVICE)
    ref = wp.array(np.full(n, -0.5, npT), dtype=T, device=DEVICE)
    failed = wp.zeros(n, dtype=wp.uint8, device=DEVICE)
    failed_np = np.zeros(n, np.uint8)
    failed_np[9] = 1  # failed but not (yet) collapsed
    failed.assign(failed_np)
    clock = wp.array([0.05, 1e-4, 1.0], dtype=wp.float64, device=DEVICE)
    arr_c = wp.full(10, np.inf, dtype=wp.float64, device=DEVICE)
    arr_f = wp.full(10, np.inf, dtype=wp.float64, device=DEVICE)
    k = pst_action_kernel(T)
    # blade: starts at t = 0.1 s from x = 0, 4 m/s, stops at 0.4 m; bins of 0.1 m; threshold 5 %
    args = [x, log_jp, ref, failed, clock, 0.1, 0.0, 1.0, 4.0, 0.4, T(5.0), T(math.log(0.95)), 0.1, arr_c, arr_f]
    wp.launch(k, n, inputs=args, device=DEVICE)  # before the saw starts: nothing happens
    assert np.all(log_jp.numpy() == ljp0) and np.all(np.isinf(arr_c.numpy()))
    clock.assign([0.16, 1e-4, 1.0])  # blade at 0.24 m
    wp.launch(k, n, inputs=args, device=DEVICE)
    lj, fl = log_jp.numpy(), failed.numpy()
    assert np.all(lj[:2] == 5.0) and np.all(fl[:2] == 2)  # 0.05 and 0.15 m sawn
    assert np.all(lj[2:] == ljp0[2:])
    a_c, a_f = arr_c.numpy(), arr_f.numpy()
    assert np.all(a_c[:2] == 0.16) and a_c[7] == 0.16  # sawn bins, and the collapsed particle's bin
    assert np.isinf(a_c[2]) and np.isinf(a_c[9])
    assert a_f[9] == 0.16 and np.isinf(a_f[7])  # failure front: failed or sawn
    clock.assign([10.0, 1e-4, 20.0])  # long after: the blade stopped at 0.4 m
    wp.launch(k, n, inputs=args, device=DEVICE)
    assert np.all(log_jp.numpy()[:4] == 5.0) and log_jp.numpy()[4] == ljp0[4]
    assert a_c[0] == 0.16  # arrival keeps the first time


def test_weak_layer_brittle_failure_kernel():
    T = wp.float32
    E, nu = 1e6, 0.3
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    K = lam + 2 * mu / 3
    xi, M, beta, p0_ini = 0.0066, 1.2, 0.3, 3000.0
    lj0 = -math.asinh(p0_ini / K) / xi
    Hs = np.zeros((3, 3, 3), dtype=np.float32)  # the kernel reads H = F_E - I
    Hs[1, 0, 1] = 0.001  # small shear: inside the ellipse
    Hs[2, 0, 1] = 0.02   # large shear: q = mu * 0.02 ~ 7.7 kPa > q_max (~2 kPa): on or beyond the surface
    F = wp.array(Hs, dtype=mat33(T), device=DEVICE)
    log_jp = wp.array(np.full(3, lj0, np.float32), dtype=T, device=DEVICE)
    ref = wp.zeros(3, dtype=T, device=DEVICE)
    failed = wp.zeros(3, dtype=wp.uint8, device=DEVICE)
    clock = wp.array([0.05, 1e-4, 1.0], dtype=wp.float64, device=DEVICE)
    args = [F, log_jp, ref, failed, clock, 0.1, 1, T(mu), T(lam), T(M), T(beta), T(xi), T(1e-5 * K), T(0.0),
            T(1e-3)]
    k = weak_layer_kernel(T)
    wp.launch(k, 3, inputs=args, device=DEVICE)  # settling: reference snapshot, no failure
    assert np.all(failed.numpy() == 0) and np.allclose(ref.numpy(), lj0)
    clock.assign([0.2, 1e-4, 1.0])
    wp.launch(k, 3, inputs=args, device=DEVICE)
    assert failed.numpy().tolist() == [0, 0, 1]
    assert log_jp.numpy()[2] == 0.0 and ref.numpy()[2] == 0.0  # cohesion lost, collapse measured from there
    assert np.allclose(log_jp.numpy()[:2], lj0) and np.allclose(ref.numpy()[:2], lj0)
    args[6] = 0  # brittle off: the engine's model only
    failed.zero_()
    log_jp.assign(np.full(3, lj0, np.float32))
    wp.launch(k, 3, inputs=args, device=DEVICE)
    assert np.all(failed.numpy() == 0) and np.allclose(log_jp.numpy(), lj0)


# ----------------------------------------------------------------------------- end to end
#: pst_demo shortened: 1.5 m column, 0.2 m cut, quicker settling (about 4k steps of 18k particles)
SMALL_DEMO = ["scene.length=1.5", "scene.saw.cut_length=0.2", "scene.settle.gravity_ramp=0.03",
              "scene.settle.duration=0.06", "time.end=0.14"]


def test_pst_demo_small_crack_runs(tmp_path):
    out = str(tmp_path / "pst.h5")
    res = mw.run("pst_demo", output=out, device=DEVICE, overrides=SMALL_DEMO, n_threads=1)
    mon = res.monitor
    ex = res.scene_result
    t = np.asarray(mon.times)
    front = np.asarray(mon.series["front"])
    L, cut = 1.5, 0.2
    t_saw = mon.params.saw_start
    # intact until the saw starts, then a front that only moves forward and crosses the column
    assert np.all(front[t < t_saw] == 0.0)
    assert np.all(np.diff(front) >= 0.0)
    assert ex["propagated"] and ex["ran_to_end"] and front[-1] == pytest.approx(L)
    assert ex["initiated_at_saw"] and ex["apparent_speed"] == pytest.approx(ex["speed"], rel=0.3)
    assert np.asarray(mon.series["failure_front"])[t < t_saw].max() == 0.0
    # it ran by itself past the cut at a finite speed (well beyond the saw's 4 m/s)
    assert 10.0 < ex["speed"] < 200.0
    i_cross = np.nonzero(front >= 0.8 * L)[0][0]
    assert mon.saw_position(t[i_cross]) <= cut + 1e-9
    # the layer collapsed behind the front by about the hardening law's height
    law = mon.params.references()["collapse_height_law"]
    assert 0.5 * law < ex["collapse_height"] < 2.0 * law
    assert np.isfinite(ex["touchdown"]) and 0.0 < ex["touchdown"] < L
    # the series are in the run file, with units
    run = read_run(out)
    assert run.units["front"] == "m" and run.units["marker0_uy"] == "m"
    assert np.allclose(run.scalars["front"], front[: run.n_frames])
