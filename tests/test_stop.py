"""Stopping on request never waits for a far frame: the run stops after its current batch of steps with a
mid-frame checkpoint that resumes bit for bit (CPU); the CLI's signal handling and resume messages."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers_scenes import TINY_PST, assert_same_series

import mpm_warp as mw
from mpm_warp import io
from mpm_warp.cli import StopRequest, main


def _stop_when(sim, condition) -> None:
    """Ask ``sim`` to stop (as a signal handler would) after the first batch of steps where ``condition(sim)``."""
    steps = sim.stepper.steps

    def batch(n):
        steps(n)
        if condition(sim):
            sim.request_stop()

    sim.stepper.steps = batch


def _same_runs(a_path, b_path) -> None:
    a, b = mw.read_run(a_path), mw.read_run(b_path)
    assert a.n_frames == b.n_frames and a.particle_fields == b.particle_fields
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_array_equal(a.steps, b.steps)
    np.testing.assert_array_equal(a.wall_forces, b.wall_forces)
    for n in a.scalars:
        np.testing.assert_array_equal(a.scalars[n], b.scalars[n], err_msg=n)
    for k in range(a.n_frames):
        fa, fb = a.frame(k), b.frame(k)
        for n in a.particle_fields:
            np.testing.assert_array_equal(fa[n], fb[n], err_msg=f"frame {k} {n}")


def _stopped_mid_frame_then_resumed(tmp_path, scene, overrides, condition, threads=1):
    full = mw.run(scene, str(tmp_path / "full.h5"), "cpu", overrides, n_threads=threads)
    part = str(tmp_path / "part.h5")
    stopped = mw.run(scene, part, "cpu", overrides, n_threads=threads, on_start=lambda s: _stop_when(s, condition))
    assert stopped.stopped and stopped.sim_time < full.sim_time
    arrays, meta = io.read_checkpoint(io.checkpoint_path_for(part))
    run = mw.read_run(part)
    assert run.n_frames == meta["frame_index"] + 1
    assert run.times[-1] < meta["time"] < run.times[-1] + overrides_frame(overrides)    # mid-frame
    assert meta["time"] == stopped.sim_time and arrays["clock"][0] == stopped.sim_time
    res = mw.resume(part, device="cpu", n_threads=threads)
    assert not res.stopped and res.sim_time == full.sim_time and stopped.steps + res.steps == full.steps
    _same_runs(str(tmp_path / "full.h5"), part)
    return full, res


def overrides_frame(overrides) -> float:
    return float(next(o.split("=")[1] for o in overrides if o.startswith("time.frame_interval=")))


@pytest.mark.slow
def test_block_stopped_mid_frame_resumes_bit_for_bit(tmp_path):
    """An elastic block dropped on a frictional floor, stopped 100 steps into a 277-step frame (wall impulse
    half summed): the resumed run equals the straight one, wall forces included, on 1 and on 2 threads."""
    overrides = ["time.end=0.06", "time.frame_interval=0.03", 'output.fields=["x", "v", "p", "q"]',
                 "output.health_every=7", "output.checkpoint_every=1"]
    for threads in (1, 2):
        d = tmp_path / f"t{threads}"
        d.mkdir()
        _stopped_mid_frame_then_resumed(d, "elastic_block", overrides,
                                        lambda s: s.stepper.clock()[2] > 100, threads)


@pytest.mark.slow
def test_pst_stopped_mid_frame_while_sawing_resumes_bit_for_bit(tmp_path):
    """A PST stopped half-way through a frame after settling (the saw cutting, yielded flags half collected)."""
    overrides = TINY_PST + ["time.end=0.065", "output.checkpoint_every=4", 'output.fields=["x", "log_jp", "yielded"]']
    full, res = _stopped_mid_frame_then_resumed(tmp_path, "pst_demo", overrides, lambda s: s.time > 0.0525)
    assert_same_series(full.monitor.series, res.monitor.series)
    assert full.scene_result.keys() == res.scene_result.keys()
    for k in full.scene_result:
        np.testing.assert_array_equal(np.asarray(full.scene_result[k]), np.asarray(res.scene_result[k]))
    assert mw.read_run(str(tmp_path / "part.h5")).field("yielded").any()


# ------------------------------------------------------------------------------------------------------- CLI
class _Sim:
    def __init__(self):
        self.stops = 0

    def request_stop(self):
        self.stops += 1


def test_stop_request_decides_between_the_frame_and_the_next_batch(capsys):
    with StopRequest(far_s=2.0) as stop:
        sim = _Sim()
        stop.attach(sim)
        assert stop.frame_due_in() == math.inf
        stop._handle(signal.SIGINT, None)               # no frame finished yet: the frame may be far away
        assert stop.requested and sim.stops == 1
    with StopRequest(far_s=2.0) as stop:
        sim = _Sim()
        stop.attach(sim)
        stop.frame_done()                               # frames take about no time: let this one finish
        stop._handle(signal.SIGTERM, None)
        assert stop.requested and sim.stops == 0
        stop._handle(signal.SIGTERM, None)              # a second signal: the next batch
        assert sim.stops == 1
        with pytest.raises(KeyboardInterrupt):          # a third: at once
            stop._handle(signal.SIGTERM, None)
    with StopRequest(far_s=2.0) as stop:                # a signal before the simulation exists: ends at once
        with pytest.raises(KeyboardInterrupt) as info:
            stop._handle(signal.SIGTERM, None)
        assert info.value.signum == signal.SIGTERM and stop.sim is None
    err = capsys.readouterr().err
    assert "finishing the current frame" in err and "stopping after the current batch of steps" in err


def _env() -> dict:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}


@pytest.mark.slow
def test_cli_signal_during_a_long_frame_stops_within_seconds_and_resumes_exactly(tmp_path):
    """One frame of 0.8 s of simulated time (~5 s of wall time): SIGINT during it stops the run within seconds
    (exit 130) with a mid-frame checkpoint; `mpm-warp resume` ends on the uninterrupted run's last frame."""
    sets = ["time.end=0.8", "time.frame_interval=0.8"]
    out = tmp_path / "run.h5"
    cmd = [sys.executable, "-m", "mpm_warp.cli", "run", "elastic_block", "--out", str(out), "--quiet",
           "--device", "cpu", *[a for s in sets for a in ("--set", s)]]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
    deadline = time.time() + 120
    while time.time() < deadline and not os.path.exists(io.checkpoint_path_for(out)):
        time.sleep(0.05)                                # the initial checkpoint is written as stepping starts
    time.sleep(1.0)
    t0 = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert time.perf_counter() - t0 < 10.0
    assert "stopping after the current batch of steps" in err and "resume with" in err
    assert not os.path.exists(io.lock.lock_path_for(out))                  # released on the way out
    meta = io.read_checkpoint_meta(io.checkpoint_path_for(out))
    assert meta["frame_index"] == 0 and 0.0 < meta["time"] < 0.8
    p = subprocess.run([sys.executable, "-m", "mpm_warp.cli", "resume", str(out)], capture_output=True, text=True,
                       env=_env(), timeout=300)
    assert p.returncode == 0, p.stderr
    assert f"resuming {out} after frame 0, at t = {meta['time']:.6g} s (step {meta['step']}), to t = 0.8 s" in p.stderr
    assert "[" in p.stderr and "t = 0.8/0.8 s" in p.stderr                   # the progress bar
    full = str(tmp_path / "full.h5")
    mw.run("elastic_block", full, "cpu", sets)
    _same_runs(full, str(out))


def test_cli_resume_messages_and_end(tmp_path, capsys):
    out = str(tmp_path / "run.h5")
    mw.run("elastic_block", out, "cpu", ["time.end=0.04", "time.frame_interval=0.02", "output.checkpoint_every=1"])
    assert main(["resume", out, "--end", "0.02"]) == 2                       # before the last frame's t = 0.04 s
    line, = capsys.readouterr().err.strip().splitlines()
    assert line == (f"mpm-warp: error: end_time = 0.02 is invalid: expected a time after the last frame's t = 0.04 s: "
                    f"{out} holds 3 frames to there and a resume never removes frames")
    assert main(["resume", out, "--end", "0.08"]) == 0
    cap = capsys.readouterr()
    steps = int(mw.read_run(out).steps[2])
    assert f"mpm-warp: resuming {out} after frame 2, at t = 0.04 s (step {steps}), to t = 0.08 s" in cap.err
    assert "t = 0.08/0.08 s  frame 4" in cap.err and cap.out.startswith("done: 2 frames")
    assert mw.read_run(out).n_frames == 5
