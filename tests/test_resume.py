"""Checkpoints and resume: bit for bit on the CPU, from the API and from a real interrupted CLI run."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

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


def test_checkpoint_holds_the_full_state(tmp_path):
    path = tmp_path / "run.h5"
    _run(path)
    arrays, meta = io.read_checkpoint(io.checkpoint_path_for(str(path)))
    for k in ("x", "v", "C", "H", "clock", "steps", "vmax"):
        assert k in arrays
    assert meta["frame_index"] == 6
    run = mw.read_run(str(path))
    np.testing.assert_array_equal(arrays["x"], run.frame(-1)["x"])


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
