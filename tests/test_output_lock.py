"""Run files are never clobbered: existing outputs need overwrite, one writer per output (a real second
process is refused at once, naming the holder), the lock goes on every way out, a dead run's lock is taken
over with a message (CPU only)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp import io
from mpm_warp.cli import main
from mpm_warp.errors import OutputError

SHORT = ["time.end=0.04", "time.frame_interval=0.02"]

HOLDER = r"""
import sys, time
from mpm_warp.io import output_lock
with output_lock(sys.argv[1]):
    print("locked", flush=True)
    if sys.argv[2] == "die":
        import os, signal
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(60)
"""


def _env() -> dict:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}


def _holder(path, mode="hold") -> subprocess.Popen:
    p = subprocess.Popen([sys.executable, "-c", HOLDER, str(path), mode], stdout=subprocess.PIPE, text=True,
                         env=_env())
    assert p.stdout.readline().strip() == "locked"
    return p


def _no_leftovers(d) -> None:
    assert not [p.name for p in d.iterdir() if p.name.endswith((".lock", ".part", ".tmp"))]


def test_existing_output_needs_overwrite(tmp_path):
    out = str(tmp_path / "run.h5")
    first = mw.run("elastic_block", out, "cpu", SHORT)
    t_created = mw.read_run(out).attrs["created"]
    with pytest.raises(OutputError, match="run.h5: exists; pass --overwrite"):
        mw.run("elastic_block", out, "cpu", SHORT)
    with pytest.raises(OutputError, match="exists"):
        mw.Simulation(mw.load_scenario("elastic_block", SHORT), device="cpu").run(out)
    assert mw.read_run(out).attrs["created"] == t_created and first.frames == 2
    res = mw.run("elastic_block", out, "cpu", ["time.end=0.06", "time.frame_interval=0.02"], overwrite=True)
    assert res.frames == 3 and mw.read_run(out).n_frames == 4
    assert io.read_checkpoint_meta(io.checkpoint_path_for(out))["scenario"]["time"]["end"] == 0.06   # replaced too
    _no_leftovers(tmp_path)


def test_input_scenario_and_special_files_never_replaced(tmp_path):
    scene = tmp_path / "scene.toml"
    with open(os.path.join(mw.scenarios_dir(), "elastic_block.toml")) as fh:
        scene.write_text(fh.read())
    text = scene.read_bytes()
    with pytest.raises(OutputError, match="is the input scenario"):
        mw.run(str(scene), str(scene), "cpu", SHORT, overwrite=True)
    assert scene.read_bytes() == text
    os.mkfifo(tmp_path / "fifo.h5")
    with pytest.raises(OutputError, match="not a regular file"):
        mw.run(str(scene), str(tmp_path / "fifo.h5"), "cpu", SHORT, overwrite=True)
    with pytest.raises(OutputError, match="/dev/null: is not a regular file"):
        mw.run(str(scene), "/dev/null", "cpu", SHORT, overwrite=True)
    (tmp_path / "d.h5").mkdir()
    with pytest.raises(OutputError, match="is a directory"):
        mw.run(str(scene), str(tmp_path / "d.h5"), "cpu", SHORT, overwrite=True)
    _no_leftovers(tmp_path)


def test_second_run_on_a_live_output_fails_at_once_naming_the_holder(tmp_path, capsys):
    out = tmp_path / "run.h5"
    mw.run("elastic_block", str(out), "cpu", SHORT)
    before = out.read_bytes()
    holder = _holder(out)
    try:
        assert io.is_live(out)
        t0 = time.perf_counter()
        with pytest.raises(OutputError) as info:
            mw.run("elastic_block", str(out), "cpu", SHORT, overwrite=True)
        assert time.perf_counter() - t0 < 2.0
        msg = str(info.value)
        assert f"in use by another run (pid {holder.pid} on {socket.gethostname()}, started 20" in msg
        assert main(["run", "elastic_block", "--out", str(out), "--quiet", "--overwrite"]) == 2
        line, = capsys.readouterr().err.strip().splitlines()
        assert line.startswith("mpm-warp: error: ") and f"pid {holder.pid}" in line
        assert main(["resume", str(out), "--quiet"]) == 2
        assert f"pid {holder.pid}" in capsys.readouterr().err
    finally:
        holder.kill()
        holder.wait()
    assert out.read_bytes() == before


@pytest.mark.slow
def test_two_cli_runs_started_together_one_wins(tmp_path):
    """Two `mpm-warp run` on the same --out started together: one writes the run, the other exits 2 at once."""
    out = str(tmp_path / "run.h5")
    cmd = [sys.executable, "-m", "mpm_warp.cli", "run", "elastic_block", "--out", out, "--quiet", "--device", "cpu",
           "--set", "time.end=0.6", "--set", "time.frame_interval=0.1"]
    procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
             for _ in range(2)]
    results = [(p.wait(timeout=300), p.stderr.read()) for p in procs]
    assert sorted(rc for rc, _ in results) == [0, 2], results
    err = next(e for rc, e in results if rc == 2)
    line, = err.strip().splitlines()
    assert "in use by another run (pid " in line or "exists" in line      # the loser came late: the file exists
    assert mw.read_run(out).n_frames == 7
    _no_leftovers(tmp_path)


def test_lock_released_on_every_way_out(tmp_path):
    out = tmp_path / "run.h5"
    mw.run("elastic_block", str(out), "cpu", SHORT)                          # normal end
    assert not io.is_live(out) and not os.path.exists(io.lock.lock_path_for(out))

    def fail(sim, k):
        raise RuntimeError("callback failed")

    def interrupt(sim, k):
        raise KeyboardInterrupt

    for cb, exc in ((fail, RuntimeError), (interrupt, KeyboardInterrupt)):
        with pytest.raises(exc):
            mw.run("elastic_block", str(out), "cpu", SHORT, overwrite=True, callback=cb)
        assert not os.path.exists(io.lock.lock_path_for(out))
    c_p = mw.Elastic(1.0e6, 0.3, 250.0).p_wave_speed
    dt = 3.0 * 0.02 / c_p
    with pytest.raises(mw.SimulationBlowUp):                                   # a blow-up
        mw.run("elastic_block", str(out), "cpu", [f"time.dt={dt!r}", f"time.end={60 * dt!r}",
                                                  f"time.frame_interval={20 * dt!r}",
                                                  "time.allow_unstable_dt=true"], overwrite=True)
    with pytest.raises(mw.InvalidArgument):                                    # refused after the lock was taken
        mw.run("elastic_block", str(out), "cpu", ["materials.snow.E=-1"], overwrite=True)
    _no_leftovers(tmp_path)
    res = mw.run("elastic_block", str(out), "cpu", SHORT, overwrite=True)     # and the output is free again
    assert res.frames == 2


#: a signal that raises (as the CLI's handler does before a run steps) arriving the moment the lock file exists
SIGNAL_IN_ACQUIRE = r"""
import os, signal, sys
from mpm_warp.io import lock

def stop(signum, frame):
    raise KeyboardInterrupt
signal.signal(signal.SIGTERM, stop)
acquire = lock._acquire

def acquire_then_signal(path):
    fd = acquire(path)
    os.kill(os.getpid(), signal.SIGTERM)  # the handler runs at the next chance Python gets
    return fd
lock._acquire = acquire_then_signal
try:
    with lock.output_lock(sys.argv[1]):
        print("body ran")
except KeyboardInterrupt:
    print("interrupted")
print("lock file left" if os.path.exists(lock.lock_path_for(sys.argv[1])) else "lock file removed")
"""


def test_a_signal_while_the_lock_is_taken_leaves_no_lock_file(tmp_path):
    """SIGTERM arriving between the lock file's creation and the block that removes it (hit by a CLI run stopped
    while it read its scenario, on a loaded machine): the signal waits until that block, which removes the file."""
    out = tmp_path / "run.h5"
    proc = subprocess.run([sys.executable, "-c", SIGNAL_IN_ACQUIRE, str(out)], capture_output=True, text=True,
                          env=_env(), timeout=60)
    assert proc.stdout.split("\n")[:2] == ["interrupted", "lock file removed"], proc.stdout + proc.stderr
    assert not os.path.exists(io.lock.lock_path_for(out))


def test_stale_lock_of_a_dead_run_is_taken_over_with_a_message(tmp_path, capsys):
    out = tmp_path / "run.h5"
    holder = _holder(out, "die")
    holder.wait()
    assert holder.returncode == -signal.SIGKILL
    assert io.lock.holder(out)["pid"] == holder.pid and not io.is_live(out)
    assert main(["run", "elastic_block", "--out", str(out), "--quiet", "--set", "time.end=0.04",
                 "--set", "time.frame_interval=0.02"]) == 0
    err = capsys.readouterr().err
    assert f"run.h5: taking over the stale lock of pid {holder.pid} on {socket.gethostname()}" in err
    assert "which is no longer running" in err
    _no_leftovers(tmp_path)


LIVE_WRITER = r"""
import sys, time
import numpy as np
from mpm_warp.io import RunWriter, output_lock
with output_lock(sys.argv[1]), RunWriter(sys.argv[1], n_particles=5, particle_fields={"x": ((3,), "f4", "m")}) as w:
    w.write_frame(0.0, 0, {"x": np.zeros((5, 3))})
    print("written", flush=True)
    time.sleep(60)
"""


def test_live_files_are_read_in_swmr_mode_closed_ones_plainly(tmp_path):
    live = str(tmp_path / "live.h5")
    p = subprocess.Popen([sys.executable, "-c", LIVE_WRITER, live], stdout=subprocess.PIPE, text=True, env=_env())
    try:
        assert p.stdout.readline().strip() == "written"
        run = mw.read_run(live)
        assert run._swmr and run.n_frames == 1
        np.testing.assert_array_equal(run.frame(0)["x"], np.zeros((5, 3)))
    finally:
        p.kill()
        p.wait()
    done = str(tmp_path / "done.h5")
    mw.run("elastic_block", done, "cpu", SHORT)
    assert not mw.read_run(done)._swmr
