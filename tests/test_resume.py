"""Checkpoints and resume: bit for bit on the CPU (plain blocks, a PST, a shear test), from the API and the CLI."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE
from helpers_scenes import RUNNING_PST, TINY_PST, assert_same_series

import mpm_warp as mw
from mpm_warp import io

TINY = ["time.end=0.06", "time.frame_interval=0.01", "output.checkpoint_every=2"]


def _run(path, overrides=TINY):
    sc = mw.load_scenario("elastic_block", overrides)
    return mw.Simulation(sc, device=DEVICE).run(str(path))


def test_resumed_run_matches_uninterrupted_bit_for_bit(tmp_path):
    full = tmp_path / "full.h5"
    _run(full)
    # the same run stopped after frame 3 (a checkpoint exists at frame 2), then resumed
    part = tmp_path / "part.h5"
    sc = mw.load_scenario("elastic_block", TINY)
    mw.Simulation(sc, device=DEVICE).run(str(part), callback=lambda sim, k: k < 3)
    assert mw.read_run(str(part)).n_frames == 4  # frames 0..3
    res = mw.resume(str(part), device=DEVICE)
    a, b = mw.read_run(str(full)), mw.read_run(str(part))
    assert a.n_frames == b.n_frames == 7
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_array_equal(a.steps, b.steps)
    for k in range(a.n_frames):
        for name in a.particle_fields:
            np.testing.assert_array_equal(a.frame(k)[name], b.frame(k)[name])
    np.testing.assert_array_equal(a.wall_forces, b.wall_forces)
    assert res.sim_time == a.times[-1]


def test_a_run_file_without_a_series_of_this_release_resumes_without_it_and_says_so(tmp_path, caplog):
    """A file written before a monitor gained a series (here: its ``elastic_energy`` taken out) resumes: the
    series it holds go on, every frame kept, the new one is left out in one logged line."""
    import h5py

    part = tmp_path / "old.h5"
    sc = mw.load_scenario("elastic_block", TINY)
    mw.Simulation(sc, device=DEVICE).run(str(part), callback=lambda sim, k: k < 3)
    with h5py.File(part, "r+") as f:
        del f["scalars/elastic_energy"]
    with caplog.at_level("WARNING", logger="mpm_warp"):
        mw.resume(str(part), device=DEVICE)
    lines = [r.getMessage() for r in caplog.records if "older release" in r.getMessage()]
    assert len(lines) == 1 and "['elastic_energy']" in lines[0] and str(part) in lines[0]
    run = mw.read_run(str(part))
    assert run.n_frames == 7 and set(run.scalars) == {"kinetic_energy"} and len(run.scalars["kinetic_energy"]) == 7


def test_checkpoint_holds_the_full_state(tmp_path):
    path = tmp_path / "run.h5"
    _run(path)
    arrays, meta = io.read_checkpoint(io.checkpoint_path_for(str(path)))
    for k in ("x", "v", "C", "H", "clock", "steps", "vmax"):
        assert k in arrays
    assert meta["frame_index"] == 6
    run = mw.read_run(str(path))
    np.testing.assert_array_equal(arrays["x"], run.frame(-1)["x"])


@pytest.mark.slow
def test_cli_interrupted_by_signal_keeps_frames_and_resumes(tmp_path):
    """A real `mpm-warp run` gets SIGINT mid-run: it stops after a complete frame, exit 130, and resumes."""
    out = tmp_path / "cli.h5"
    cmd = [sys.executable, "-m", "mpm_warp.cli", "run", "elastic_block", "--out", str(out), "--quiet",
           "--set", "time.end=0.3", "--set", "time.frame_interval=0.005", "--set", "output.checkpoint_every=50",
           "--device", DEVICE]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while time.time() < deadline:
        if out.exists():
            try:
                if mw.read_run(str(out)).n_frames >= 3:
                    break
            except mw.OutputError:
                pass
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "resume with" in err
    run = mw.read_run(str(out))
    assert 3 <= run.n_frames < 61
    assert os.path.exists(io.checkpoint_path_for(str(out)))
    res = subprocess.run([sys.executable, "-m", "mpm_warp.cli", "resume", str(out), "--device", DEVICE],
                         capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    run = mw.read_run(str(out))
    assert run.n_frames == 61 and abs(run.times[-1] - 0.3) < 1e-12


# ------------------------------------------------------------------ scenes: the monitors' state is checkpointed
#: a small PST (0.6 m column, 3.6k particles): settled by 0.04 s, sawn from then on, run to 0.08 s
PST = TINY_PST + ["time.end=0.08", "output.checkpoint_every=1"]
#: a small shear test (560 particles): settled by 0.05 s, pushed from then on, run to 0.09 s
TINY_SHEAR = ["scene.dx=0.01", "scene.sample_length=0.1", "scene.settle.gravity_ramp=0.03",
              "scene.settle.duration=0.05", "time.end=0.09", "time.frame_interval=0.005",
              "output.checkpoint_every=1", 'output.fields=["x", "log_jp"]']


def _same_result(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


def _interrupted_equals_uninterrupted(tmp_path, scene: str, overrides: list, t_stop: float, device_keys) -> None:
    """Run straight through; run again stopped at ``t_stop`` (after settling) and resumed: bit for bit equal."""
    full = mw.run(scene, str(tmp_path / "full.h5"), DEVICE, overrides, n_threads=1)
    part = str(tmp_path / "part.h5")
    stopped = mw.run(scene, part, DEVICE, overrides, n_threads=1, callback=lambda sim, k: sim.time < t_stop - 1e-12)
    assert stopped.sim_time == pytest.approx(t_stop)
    arrays, meta = io.read_checkpoint(io.checkpoint_path_for(part))
    name = stopped.monitor.name
    assert meta["monitors"] == [name] and arrays["vmax"].size == 1
    for k in device_keys:   # the scene's device state at the stop is not trivial: losing it would show
        assert f"monitors/{name}/device/{k}" in arrays
    res = mw.resume(part, device=DEVICE, n_threads=1)
    a, b = mw.read_run(str(tmp_path / "full.h5")), mw.read_run(part)
    assert a.n_frames == b.n_frames and a.particle_fields == b.particle_fields
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_array_equal(a.steps, b.steps)
    for k in range(a.n_frames):
        fa, fb = a.frame(k), b.frame(k)
        for n in a.particle_fields:
            np.testing.assert_array_equal(fa[n], fb[n], err_msg=f"frame {k} {n}")
    assert a.scalars.keys() == b.scalars.keys()
    for n in a.scalars:
        np.testing.assert_array_equal(a.scalars[n], b.scalars[n], err_msg=n)
    assert full.monitor.times == res.monitor.times
    assert_same_series(full.monitor.series, res.monitor.series)
    _same_result(full.scene_result, res.scene_result)
    return full, res, arrays


@pytest.mark.slow
def test_pst_interrupted_after_settling_resumes_bit_for_bit(tmp_path):
    full, res, arrays = _interrupted_equals_uninterrupted(
        tmp_path, "pst_demo", PST, 0.055, ["weak_layer/ref", "weak_layer/sawn", "weak_layer/arrival", "base_y_ref",
                                           "base_arrival"])
    ck = "monitors/pst/device/"
    assert (arrays[ck + "weak_layer/sawn"] == 1).any()              # sawn particles at the stop
    assert np.isfinite(arrays[ck + "weak_layer/arrival"]).any()      # and damage times
    assert len(arrays["monitors/pst/series/times"]) == 12            # frames 0..11 recorded before the stop
    np.testing.assert_array_equal(full.monitor.weak.arrival.numpy(), res.monitor.weak.arrival.numpy())
    np.testing.assert_array_equal(full.monitor.weak.ref.numpy(), res.monitor.weak.ref.numpy())
    np.testing.assert_array_equal(full.monitor.base_arrival.numpy(), res.monitor.base_arrival.numpy())


@pytest.mark.slow
def test_pst_resumed_after_the_saw_stopped_on_runaway_keeps_the_stop(tmp_path):
    """saw.stop = "runaway": the blade stops near 0.18 m at 0.22 s; stopped at 0.25 s and resumed, the blade stays
    there (it would go on to 0.5 m) and the run is the uninterrupted one, bit for bit."""
    over = RUNNING_PST + ["scene.saw.cut_length=0.5", "scene.saw.stop=runaway", "time.end=0.3",
                          "output.checkpoint_every=1"]
    full, res, arrays = _interrupted_equals_uninterrupted(tmp_path, "pst_demo", over, 0.25, ["saw_stopped_at"])
    stop = arrays["monitors/pst/device/saw_stopped_at"][0]
    assert 0.1 < stop < 0.3 and stop == full.monitor.stopped_at == res.monitor.stopped_at
    assert float(res.monitor.weak.blade_end.numpy()[0]) == stop
    np.testing.assert_array_equal(full.monitor.weak.sawn.numpy(), res.monitor.weak.sawn.numpy())
    assert res.scene_result["saw_stopped_at"] == stop


def test_shear_test_interrupted_while_pushing_resumes_bit_for_bit(tmp_path):
    _, res, arrays = _interrupted_equals_uninterrupted(tmp_path, "shear_test", TINY_SHEAR, 0.07,
                                                       ["impulse", "last", "weak_layer/ref"])
    ck = "monitors/shear_test/device/"
    assert arrays[ck + "impulse"][0] != 0.0 and arrays[ck + "last"][0] == pytest.approx(0.07)
    assert res.monitor.series["shear_stress"][-1] != 0.0
    assert "log_jp_ref" in mw.read_run(str(tmp_path / "part.h5")).particle_fields     # compared frame by frame


def test_resume_on_another_thread_count(tmp_path):
    """vmax is stored as one number: a run checkpointed on 2 threads resumes on 1 (same steps, round-off apart)."""
    overrides = ["time.end=0.06", "time.frame_interval=0.01", "output.checkpoint_every=1"]
    full = mw.run("elastic_block", str(tmp_path / "full.h5"), DEVICE, overrides, n_threads=2)
    part = str(tmp_path / "part.h5")
    mw.run("elastic_block", part, DEVICE, overrides, n_threads=2, callback=lambda sim, k: k < 3)
    arrays, _ = io.read_checkpoint(io.checkpoint_path_for(part))
    assert arrays["vmax"].size == 1 and arrays["vmax"] > 0.0
    res = mw.resume(part, device=DEVICE, n_threads=1)
    a, b = mw.read_run(str(tmp_path / "full.h5")), mw.read_run(part)
    assert res.steps + int(b.steps[3]) == full.steps      # the same step sizes: the speed bound carried over
    np.testing.assert_allclose(b.frame(-1)["x"], a.frame(-1)["x"], atol=1e-6)


@pytest.mark.slow
def test_pst_with_the_interface_closure_resumes_bit_for_bit(tmp_path):
    """The closure's factors come from the initial positions (docs/model.md §5b), so a resume rebuilds them and
    continues bit for bit."""
    full, res, _ = _interrupted_equals_uninterrupted(tmp_path, "pst_demo", PST + ["scene.interface_closure=true"],
                                                     0.055, ["weak_layer/ref"])
    assert full.monitor.sim.stepper._closure and res.monitor.sim.stepper._closure
