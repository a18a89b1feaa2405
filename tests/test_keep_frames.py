"""Users' frames are never removed: a resume keeps every frame of its file, ``overwrite`` is a bool, a checkpoint
resumes only its own run file.

The run: the elastic block to 0.02 s, a frame every 5 ms, a checkpoint every 3 frames (at 0.015 s): its file
holds one frame (0.02 s) after its checkpoint, as a run killed between two checkpoints does.
"""

from __future__ import annotations

import json
import math
import shutil

import h5py
import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp import io
from mpm_warp.cli import main

SETS = ["time.end=0.02", "time.frame_interval=0.005", "output.checkpoint_every=3"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run (frames at 0, 5, 10, 15, 20 ms; checkpoint at 15 ms) and the same run uninterrupted to 0.03 s."""
    d = tmp_path_factory.mktemp("finished")
    mw.run("elastic_block", str(d / "run.h5"), "cpu", SETS)
    mw.run("elastic_block", str(d / "long.h5"), "cpu", SETS + ["time.end=0.03"])
    return d


def _copy(finished, tmp_path) -> str:
    for name in ("run.h5", "run.ckpt.h5"):
        shutil.copy(finished / name, tmp_path / name)
    return str(tmp_path / "run.h5")


def _files(tmp_path) -> dict:
    return {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}


def assert_same_frames(a: str, b: str, n: int | None = None) -> None:
    ra, rb = mw.read_run(a), mw.read_run(b)
    n = ra.n_frames if n is None else n
    assert rb.n_frames >= n
    np.testing.assert_array_equal(ra.times[:n], rb.times[:n])
    np.testing.assert_array_equal(ra.steps[:n], rb.steps[:n])
    for k in range(n):
        for name in ra.particle_fields:
            np.testing.assert_array_equal(ra.frame(k)[name], rb.frame(k)[name])
    np.testing.assert_array_equal(ra.wall_forces[:n], rb.wall_forces[:n])


def test_the_fixture_has_a_frame_after_its_checkpoint(finished):
    run = mw.read_run(str(finished / "run.h5"))
    meta = io.read_checkpoint_meta(str(finished / "run.ckpt.h5"))
    assert run.n_frames == 5 and run.times[-1] == pytest.approx(0.02)
    assert meta["frame_index"] == 3 and meta["time"] == pytest.approx(0.015)


@pytest.mark.parametrize("end, needle", [
    ("0.01", "before the checkpoint"), ("0.0175", "between the checkpoint and the last frame"),
    (None, "the run's own end"), ("0.02", "the last frame"),
])
def test_resume_before_the_last_frame_is_refused_and_keeps_the_file(finished, tmp_path, capsys, end, needle):
    """The issue's case (``--end 0.01`` deleted the frames at 0.015 and 0.02 s, exit 0): refused, naming the last
    frame's time; nothing in the folder changes."""
    path = _copy(finished, tmp_path)
    before = _files(tmp_path)
    assert main(["resume", path, "--quiet"] + (["--end", end] if end else [])) == 2, needle
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("mpm-warp: error: end_time = ")
    assert "after the last frame's t = 0.02 s" in err and "never removes frames" in err
    assert _files(tmp_path) == before


def test_resume_keeps_the_frames_after_its_checkpoint(finished, tmp_path, monkeypatch):
    """Resumed to 0.03 s from the checkpoint at 0.015 s: the frame at 0.02 s is kept (stepped over, not rewritten)
    and the file equals the uninterrupted run's, bit for bit."""
    path = _copy(finished, tmp_path)
    written = []
    write = io.RunWriter.write_frame
    monkeypatch.setattr(io.RunWriter, "write_frame",
                        lambda self, t, *a, **k: written.append(t) or write(self, t, *a, **k))
    res = mw.resume(path, device="cpu", end_time=0.03)
    assert written == pytest.approx([0.025, 0.03])                  # the frames at 0.02 s and before: kept as they were
    assert res.frames == 3 and res.sim_time == pytest.approx(0.03)
    assert mw.read_run(path).n_frames == 7
    assert_same_frames(str(finished / "long.h5"), path)


def test_an_interrupted_resume_loses_no_frame(finished, tmp_path):
    """A resume stopped while it steps over the kept frame (before writing anything) leaves all 5 frames."""
    path = _copy(finished, tmp_path)

    def interrupt(sim, frame):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        mw.resume(path, device="cpu", end_time=0.03, callback=interrupt)
    assert_same_frames(str(finished / "run.h5"), path)


@pytest.mark.parametrize("end, needle", [
    ("nan", "a finite number"), ("inf", "a finite number"), ("-1", "(0, inf)"), ("0", "(0, inf)"),
    ("1e12", "at most 1e+08 steps"),
])
def test_resume_end_is_checked_as_time_end(finished, tmp_path, capsys, end, needle):
    """``--end nan`` (ValueError), ``inf`` (OverflowError) and ``1e12`` (ran on) before: one line, exit 2."""
    path = _copy(finished, tmp_path)
    before = _files(tmp_path)
    assert main(["resume", path, "--quiet", "--end", end]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"mpm-warp: error: end_time = {float(end)!r}") and needle in err
    assert _files(tmp_path) == before
    assert not list(tmp_path.glob("*.lock"))


@pytest.mark.parametrize("value", ["no", "yes", 1, 0, None, "False"])
def test_overwrite_must_be_a_bool(finished, tmp_path, value):
    """``overwrite="no"`` replaced an existing file (any truthy value was a yes): every non-bool is refused by name."""
    path = _copy(finished, tmp_path)
    before = _files(tmp_path)
    with pytest.raises(mw.InvalidArgument, match=r"^overwrite = .* expected True or False$"):
        mw.run("elastic_block", path, "cpu", SETS, overwrite=value)
    with pytest.raises(mw.InvalidArgument, match=r"^overwrite = "):
        mw.Simulation(mw.load_scenario("elastic_block", SETS), device="cpu").run(path, overwrite=value)
    assert _files(tmp_path) == before
    assert math.isfinite(mw.read_run(path).times[-1])


# ------------------------------------------------------------------ a checkpoint resumes only its own run file
def _pair(d, sets, name="run", old=False, monkeypatch=None):
    """A run of the elastic block (its file and checkpoint in ``d``); ``old``: written without a run id."""
    if old:
        monkeypatch.setattr(mw.frames, "new_run_id", lambda: None)
    out = str(d / f"{name}.h5")
    mw.run("elastic_block", out, "cpu", sets)
    if old:
        monkeypatch.undo()
    return out


def test_run_id_in_the_file_and_its_checkpoints(finished):
    rid = mw.read_run(str(finished / "run.h5")).attrs["run_id"]
    assert isinstance(rid, str) and len(rid) == 32 and int(rid, 16) >= 0
    assert io.read_checkpoint_meta(str(finished / "run.ckpt.h5"))["run_id"] == rid
    assert mw.read_run(str(finished / "long.h5")).attrs["run_id"] != rid


def test_checkpoint_of_another_run_is_refused(finished, tmp_path, capsys):
    """The issue's case: the checkpoint of another run of the same scene, with another frame interval, rewrote the
    file with mixed frame intervals. Refused in one line, nothing changed."""
    path = _copy(finished, tmp_path)
    (tmp_path / "other").mkdir()
    other = _pair(tmp_path / "other", SETS[:1] + ["time.frame_interval=0.01", "output.checkpoint_every=1"])
    shutil.copy(io.checkpoint_path_for(other), io.checkpoint_path_for(path))
    before = _files(tmp_path)
    assert main(["resume", path, "--quiet", "--end", "0.03"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run.ckpt.h5: is not the checkpoint of" in err and "run_id" in err
    assert "it would mix two runs in one file" in err
    assert _files(tmp_path) == before


def test_files_without_run_id(tmp_path, monkeypatch):
    """Files written before run ids existed: resumed when the checkpoint's scenario is the run file's (bit for bit),
    refused when it is another's; a run file with an id never takes a checkpoint without one."""
    old = _pair(tmp_path, SETS, "old", old=True, monkeypatch=monkeypatch)
    assert "run_id" not in mw.read_run(old).attrs and io.read_checkpoint_meta(io.checkpoint_path_for(old))["run_id"] \
        is None
    with h5py.File(old, "r+") as f:               # as an older version wrote it: no time.allow_unstable_dt
        sc = json.loads(f.attrs["scenario"])
        del sc["time"]["allow_unstable_dt"]
        f.attrs["scenario"] = json.dumps(sc)
    assert mw.resume(old, device="cpu", end_time=0.025).sim_time == pytest.approx(0.025)
    assert mw.resume(old, device="cpu", end_time=0.03).sim_time == pytest.approx(0.03)   # its checkpoint has the key
    long = _pair(tmp_path, SETS + ["time.end=0.03"], "long")
    assert_same_frames(long, old)
    other = _pair(tmp_path, SETS[:1] + ["time.frame_interval=0.01"], "other", old=True, monkeypatch=monkeypatch)
    shutil.copy(io.checkpoint_path_for(other), io.checkpoint_path_for(old))
    with pytest.raises(mw.OutputError, match=r"is not the checkpoint of .*its scenario differs from the run file's"):
        mw.resume(old, device="cpu", end_time=0.06)
    shutil.copy(io.checkpoint_path_for(other), io.checkpoint_path_for(long))     # an id in the file, none in it
    with pytest.raises(mw.OutputError, match=r"is not the checkpoint of .*run_id None, the run file's is [0-9a-f]{32}"):
        mw.resume(long, device="cpu", end_time=0.06)
