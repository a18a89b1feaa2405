"""Propagation Saw Test: scene builder, saw and front kernels, forks of a run, a small PST end to end."""

import dataclasses
import math

import numpy as np
import pytest
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument, ScenarioError
from mpm_warp.kernels.types import vec
from mpm_warp.loader import load_scenario, resolved_scenario, scenario_from_dict
from mpm_warp.scenes.pst import critical_cut
from mpm_warp.scenes.pst.kernels import deflection_kernel
from mpm_warp.scenes.pst.monitor import attach
from mpm_warp.scenes.weak_layer import weak_layer_kernel

G = 9.81


# ----------------------------------------------------------------------------- builder
def test_pst_flat_layout():
    sc = load_scenario("pst_flat")
    s = sc.scene
    L, D, d_wl, d_sub = s.length, s.slab_thickness, s.weak_layer_thickness, s.substratum_thickness
    assert L >= 8.0 and sc.domain.dimension == 2  # issue 10: an 8 m column; plane strain in true 2D
    assert d_wl / s.dx >= 4.0 - 1e-9        # at least 4 cells across the weak layer
    assert 0.10 <= d_sub <= 0.20            # old snow between the layer and the bed
    blocks = {b.name: b for b in sc.blocks}
    assert blocks["substratum"].lo[:2] == (0.0, 0.0) and blocks["substratum"].hi[:2] == pytest.approx((L, d_sub))
    assert blocks["weak_layer"].lo[1] == pytest.approx(d_sub)
    assert blocks["weak_layer"].hi[1] == pytest.approx(d_sub + d_wl)
    assert blocks["slab"].lo[1] == pytest.approx(d_sub + d_wl) and blocks["slab"].hi[1] == pytest.approx(s.base_y + D)
    (bed,) = sc.walls
    assert bed.kind == "sticky" and bed.normal[:2] == (0.0, 1.0) and bed.point[1] == 0.0
    assert sc.time.gravity == pytest.approx((0.0, -G))
    assert sc.time.damping_until == s.settle.duration == s.saw_start
    assert s.saw.speed <= 1.0
    # the weak layer is the bonded Cam-Clay calibrated under this slab
    wl = sc.materials["weak_layer"]
    cal = s.calibrated()
    assert wl == cal.material and wl.model == "bonded_camclay" and wl.p_bond > 0
    assert wl.kappa_s * d_wl > cal.w_f          # the debonding work per unit area: the softening work and more
    assert s.sigma_n == pytest.approx(250.0 * G * D)
    assert cal.h_c == pytest.approx(4.70e-3 * (1.0 - math.exp(-d_wl / 7.78e-3)), rel=1e-12)  # WEAC fit


def test_pst_slope_rotates_gravity():
    sc = load_scenario("pst_slope")
    th = math.radians(sc.scene.slope_angle)
    assert sc.scene.slope_angle == 30.0
    assert sc.time.gravity == pytest.approx((G * math.sin(th), -G * math.cos(th)))
    assert sc.scene.sigma_n == pytest.approx(250.0 * G * sc.scene.slab_thickness * math.cos(th))
    # the same layer, calibrated under the slope's loads (normal and bed-parallel)
    cal = sc.scene.calibrated()
    assert cal.tau_slope == pytest.approx(250.0 * G * sc.scene.slab_thickness * math.sin(th))


def test_pst_width_gives_3d_column():
    sc = load_scenario("pst_demo", ["scene.width=0.1"])
    assert sc.domain.dimension == 3
    assert all(b.hi[2] == pytest.approx(0.1) for b in sc.blocks)


@pytest.mark.parametrize("override, match", [
    ("scene.slab.E=-1e6", "scene.slab.E"),
    ("scene.weak_layer_thickness=0.01", "cells"),
    ("scene.saw.cut_from='middle'", "cut_from"),
    ("scene.saw.speed=2.0", r"scene.saw.speed.*2"),
    ("scene.saw.cut_length=30.0", "scene.saw.cut_length"),
    ("scene.front.deflection=1.5", "scene.front.deflection"),
    ("scene.substratum_thickness=0.001", "scene.substratum_thickness"),
    ("scene.weak_layer.delta_s=0.002", "w_f/delta_s"),   # both given
    ("time.gravity=[0.0, -9.81, 0.0]", "time.gravity"),
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
    sc = load_scenario("pst_slope", ["scene.saw.cut_from='downslope'", "scene.bed='separate'",
                                     "scene.weak_layer.w_f=0.0", "scene.weak_layer.delta_s=0.002"])
    back = resolved_scenario(sc.to_dict())
    assert back == sc and back.scene.saw.cut_from == "downslope" and back.walls[0].kind == "separate"
    assert back.materials["weak_layer"] == sc.materials["weak_layer"]


# ----------------------------------------------------------------------------- kernels
@pytest.mark.parametrize("T", [wp.float32, wp.float64])
def test_saw_kerf_reference_and_damage_times(T):
    npT = np.float32 if T == wp.float32 else np.float64
    n = 6
    xs = np.zeros((n, 2), npT)
    xs[:, 0] = [0.05, 0.15, 0.25, 0.35, 0.45, 0.55]
    x = wp.array(xs, dtype=vec(2, T), device=DEVICE)
    lj0 = np.full(n, -0.2, npT)
    log_jp = wp.array(lj0, dtype=T, device=DEVICE)
    kappa_s = 0.1
    k0 = np.array([0.0, 0.0, 0.0, 0.06, 0.02, 0.0], npT)  # particle 3: bond 0.4 (damaged), 4: bond 0.8
    kappa = wp.array(k0, dtype=T, device=DEVICE)
    ref = wp.zeros(n, dtype=T, device=DEVICE)
    sawn = wp.zeros(n, dtype=wp.uint8, device=DEVICE)
    arrival = wp.full(n, np.inf, dtype=wp.float64, device=DEVICE)
    clock = wp.array([0.05, 1e-4, 1.0, 1e-4], dtype=wp.float64, device=DEVICE)
    k = weak_layer_kernel(2, T)
    # reference until t_ref = 0.1 s; saw from t = 0.1 s at 1 m/s from x = 0, stops at 0.2 m; damage at bond 0.5
    blade_end = wp.array([0.2], dtype=wp.float64, device=DEVICE)   # the blade's end: read at every launch
    args = [x, log_jp, kappa, ref, sawn, arrival, clock, 0.1, T(kappa_s), T(0.5), 0.1, 1.0, blade_end, 0.0, 1.0, 0.0]
    wp.launch(k, n, inputs=args, device=DEVICE)   # settling: the reference follows, nobody sawn
    assert np.all(ref.numpy() == lj0) and np.all(sawn.numpy() == 0)
    assert arrival.numpy()[3] == 0.05 and np.isinf(arrival.numpy()[[0, 1, 2, 4, 5]]).all()
    log_jp.assign(lj0 - 0.1)                      # the layer compacts after settling
    clock.assign([0.26, 1e-4, 1.0, 1e-4])         # blade at 0.16 m
    wp.launch(k, n, inputs=args, device=DEVICE)
    assert np.all(ref.numpy() == lj0)             # the reference is the settled state
    kk = kappa.numpy()
    assert kk[0] == npT(kappa_s) and kk[1] == npT(kappa_s) and kk[2] == 0.0  # a kerf: the bond removed, no more
    assert sawn.numpy().tolist() == [1, 1, 0, 0, 0, 0]
    assert np.all(log_jp.numpy() == lj0 - 0.1)    # the saw does not touch the compaction state
    a = arrival.numpy()
    assert a[0] == a[1] == 0.26 and a[3] == 0.05 and np.isinf(a[[2, 4, 5]]).all()
    clock.assign([5.0, 1e-4, 6.0, 1e-4])          # long after: the blade stopped at 0.2 m
    wp.launch(k, n, inputs=args, device=DEVICE)
    assert sawn.numpy().tolist() == [1, 1, 0, 0, 0, 0] and kappa.numpy()[2] == 0.0
    assert arrival.numpy()[0] == 0.26             # arrival keeps the first time
    blade_end.assign([0.3])                       # the host moves the blade's end: the next launch reads it
    wp.launch(k, n, inputs=args, device=DEVICE)
    assert sawn.numpy().tolist() == [1, 1, 1, 0, 0, 0] and kappa.numpy()[2] == npT(kappa_s)
    # a pre-cut of 0.2 m: the kerf is there while settling; the blade then advances from its end
    kappa.assign(k0)
    sawn.zero_()
    clock.assign([0.0, 1e-4, 1.0, 1e-4])
    pre = [*args[:-1], 0.2]
    wp.launch(k, n, inputs=pre, device=DEVICE)
    assert sawn.numpy().tolist() == [1, 1, 0, 0, 0, 0]
    clock.assign([0.16, 1e-4, 1.0, 1e-4])         # 0.06 s of sawing from 0.2 m: the blade at 0.26 m
    wp.launch(k, n, inputs=pre, device=DEVICE)
    assert sawn.numpy().tolist() == [1, 1, 1, 0, 0, 0]


@pytest.mark.parametrize("dim", [2, 3])
def test_deflection_tracker(dim):
    T = wp.float32
    xs = np.zeros((3, dim), np.float32)
    xs[:, 1] = 0.2
    x = wp.array(xs, dtype=vec(dim, T), device=DEVICE)
    index = wp.array([0, 2], dtype=wp.int32, device=DEVICE)
    y_ref = wp.zeros(2, dtype=wp.float64, device=DEVICE)
    arrival = wp.full(2, np.inf, dtype=wp.float64, device=DEVICE)
    clock = wp.array([0.05, 1e-4, 1.0, 1e-4], dtype=wp.float64, device=DEVICE)
    k = deflection_kernel(dim, T)
    args = [x, index, y_ref, arrival, clock, 0.1, 0.001]
    wp.launch(k, 2, inputs=args, device=DEVICE)
    assert np.allclose(y_ref.numpy(), 0.2) and np.isinf(arrival.numpy()).all()
    xs[2, 1] = 0.2 - 0.0015                       # particle 2 (slot 1) came down 1.5 mm, particle 0 by 0.5 mm
    xs[0, 1] = 0.2 - 0.0005
    x.assign(xs)
    clock.assign([0.3, 1e-4, 1.0, 1e-4])
    wp.launch(k, 2, inputs=args, device=DEVICE)
    assert np.isinf(arrival.numpy()[0]) and arrival.numpy()[1] == 0.3
    assert np.allclose(y_ref.numpy(), 0.2)        # fixed after settling


# ----------------------------------------------------------------------------- forks of a run
#: a tiny PST: 0.6 m column, 10 cm slab, 1 cm grid (3 cells across a 3 cm layer), short settling
TINY = ["scene.length=0.6", "scene.slab_thickness=0.1", "scene.dx=0.01", "scene.weak_layer_thickness=0.03",
        "scene.substratum_thickness=0.03", "scene.margin=0.03", "scene.settle.gravity_ramp=0.01",
        "scene.settle.duration=0.02", "time.end=0.12", "time.frame_interval=0.01"]


def _sim(scenario):
    sim = mw.Simulation(scenario, device=DEVICE, n_threads=1)
    return sim, attach(sim)


@pytest.mark.slow
def test_a_fork_with_a_shorter_cut_is_the_run_with_that_cut():
    """A run forked from a snapshot taken before its saw stops equals the run made with that cut from t = 0."""
    sc = load_scenario("pst_demo", TINY + ["scene.saw.cut_length=0.08"])
    longer = dataclasses.replace(sc, scene=dataclasses.replace(sc.scene, saw=dataclasses.replace(
        sc.scene.saw, cut_length=0.3)))
    t_fork = sc.scene.saw_start + 0.05 / sc.scene.saw.speed   # blade at 5 cm: both runs alike until then
    base, _ = _sim(longer)
    base.step_to(t_fork)
    snap = base.snapshot()
    fork, fmon = _sim(sc)
    fork.load_snapshot(*snap)
    ref, rmon = _sim(sc)
    ref.step_to(t_fork)
    t_end = sc.scene.saw_end + 0.03
    for s in (fork, ref, base):
        s.step_to(t_end)
    for name in ("x", "v", "H", "log_jp", "kappa"):
        assert np.array_equal(getattr(fork.state, name).numpy(), getattr(ref.state, name).numpy()), name
    assert np.array_equal(fmon.weak.sawn.numpy(), rmon.weak.sawn.numpy())
    assert np.array_equal(fmon.weak.arrival.numpy(), rmon.weak.arrival.numpy(), equal_nan=True)
    assert fmon.weak.sawn.numpy().sum() < base.monitors["pst"].weak.sawn.numpy().sum()  # the base sawed on


def test_critical_cut_reports_a_bracket_it_cannot_hold():
    """A cut of hi that arrests (here: no time to run) is reported with its trials, not bisected."""
    sc = load_scenario("pst_demo", TINY + ["time.end=0.2"])
    res = critical_cut(sc, 0.05, 0.1, tol=0.02, free_run=0.005, run_distance=0.4, device=DEVICE, n_threads=1)
    assert not res.bracketed and math.isnan(res.value) and "0.1 m arrested" in res.note
    assert [t["cut"] for t in res.trials] == [0.1, 0.05] and not any(t["propagated"] for t in res.trials)
    # the trials ran to the saw's stop plus the free run, from a snapshot before the blade got there
    p = sc.scene
    assert all(t["t_end"] == pytest.approx(p.saw_start + t["cut"] / p.saw.speed + 0.005) for t in res.trials)


@pytest.mark.slow
@pytest.mark.parametrize("workers", [1, 2])
def test_critical_cut_bisects_and_runs_the_first_two_trials_at_once(monkeypatch, workers):
    """The search's bookkeeping, with each trial's outcome set by its cut (threshold 0.07 m): the bracket,
    the trials' order and the result are the same with ``workers=2``, whose trials of ``lo`` and the first
    midpoint must run at the same time (each waits for the other at a barrier)."""
    import threading

    from mpm_warp.scenes.pst import critical as cc

    real, meet = cc._trial, threading.Barrier(2, timeout=60)

    def trial(sim, mon, cut, run_distance, free_run, check_interval, classify=False):
        if workers == 2 and cut in (0.05, 0.5 * (0.05 + 0.1)):
            meet.wait()                    # BrokenBarrierError unless both run concurrently
        out = real(sim, mon, cut, run_distance, free_run, check_interval, classify)
        return {**out, "propagated": cut > 0.07, "class": "END" if cut > 0.07 else "ARR"}

    monkeypatch.setattr(cc, "_trial", trial)
    sc = load_scenario("pst_demo", TINY)
    res = critical_cut(sc, 0.05, 0.1, tol=0.02, free_run=0.005, run_distance=0.4, device=DEVICE, n_threads=1,
                       workers=workers)
    assert res.bracketed and (res.lo, res.hi, res.value) == pytest.approx((0.0625, 0.075, 0.06875), abs=1e-15)
    assert [t["cut"] for t in res.trials] == pytest.approx([0.1, 0.05, 0.075, 0.0625], abs=1e-15)
    assert [t["propagated"] for t in res.trials] == [True, False, True, False]
    assert res.classes == {"below": "ARR", "above": "END"}             # the class on each side of the cut
    assert res.weac["critical_cut"] > 0 and res.weac["cut"] == res.value  # weac's static answer beside it
    # each trial from the last snapshot before its cut, and run to its saw's stop plus the free run
    p = sc.scene
    assert all(t["t_end"] == pytest.approx(p.saw_start + t["cut"] / p.saw.speed + 0.005) for t in res.trials[1:])
    assert all(t["t_start"] <= p.saw_start + t["cut"] / p.saw.speed + 1e-12 for t in res.trials)


def test_critical_cut_rejects_three_workers():
    with pytest.raises(ValueError, match="workers = 3"):
        critical_cut(load_scenario("pst_demo", TINY), 0.05, 0.1, workers=3)


# ----------------------------------------------------------------------------- end to end
#: pst_demo at 1 cm (3 cells across the layer, the minimum) on a 1.2 m column, settled by 0.05 s, sawn up to
#: 0.5 m at 1 m/s: 18k particles, 31k steps (about a minute on one core)
SMALL_DEMO = ["scene.length=1.2", "scene.dx=0.01", "scene.substratum_thickness=0.05", "scene.saw.cut_length=0.5",
              "scene.settle.gravity_ramp=0.025", "scene.settle.duration=0.05", "time.end=0.75",
              "time.frame_interval=0.005"]


@pytest.mark.slow
def test_pst_demo_small_crack_runs_away_from_the_saw(tmp_path):
    out = str(tmp_path / "pst.h5")
    res = mw.run("pst_demo", output=out, device=DEVICE, overrides=SMALL_DEMO, n_threads=1)
    mon, ex = res.monitor, res.scene_result
    p = mon.params
    t = np.asarray(mon.times)
    front, saw = np.asarray(mon.series["front"]), np.asarray(mon.series["saw"])
    print({k: v for k, v in ex.items() if not isinstance(v, (dict, list))})
    # intact until the saw starts; the damage front only moves forward, never behind the blade
    assert np.all(front[t < p.saw_start] == 0.0) and np.all(np.diff(front) >= 0.0)
    assert np.all(front >= saw - 2 * p.bin_width)
    # the crack started at the saw (no bin damaged ahead of the contiguous front), led the blade when it stopped
    # (measured 0.1 m) and then ran by itself into the far end zone (measured 0.6 m in 0.09 s)
    assert ex["max_damage_lead"] <= 2 * p.bin_width
    k_stop = int(np.searchsorted(t, p.saw_end - 1e-9))
    assert front[k_stop] >= p.saw.cut_length + 5 * p.bin_width
    assert ex["ran_to_end"]
    i_end = int(np.searchsorted(front, p.length - p.slab_thickness))
    assert t[i_end] < p.saw_end + 0.2
    # sub-Rayleigh, and the slab followed the layer: the deflection front ran with the damage front
    assert ex["damage_speed_max"] < ex["rayleigh_speed"]
    assert ex["deflection_front_final"] >= p.length - p.slab_thickness
    # the debonded layer collapsed under the slab: by 0.75 s 39 % of the calibrated law's 4.6 mm for 3 cm
    # (1.78 mm measured; at 3 cells across the layer the collapse is under-resolved and still going on, as on the
    # PST ladder's 3-cell level). A layer that collapses half as much, or past the law, fails here.
    assert ex["collapse_height"] / ex["collapse_height_calibrated"] == pytest.approx(0.387, abs=0.04)
    # the series are in the run file, with units
    run = mw.read_run(out)
    assert run.units["front"] == "m" and run.units["deflection_front"] == "m" and run.units["marker0_uy"] == "m"
    assert np.allclose(run.scalars["front"], front[: run.n_frames])
