"""Damaged files never hang and never read as wrong numbers (CPU only).

Run files closed by their writer open plainly (every metadata checksum verified at once); files
left open by a killed writer need an SWMR open, which on a damaged block retries for ever, so it
runs only after a child process probed the file within ``MPM_WARP_OPEN_TIMEOUT`` seconds. Data
carry HDF5's Fletcher-32 checksum, checkpoints a SHA-256. Every file here is damaged by flipping
one byte at offsets spread over the whole file, or by truncation.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp import io
from mpm_warp.errors import OutputError

TIMEOUT = 3.0        # s, MPM_WARP_OPEN_TIMEOUT in these tests
N = 400

CHILD = r"""
import os, signal, sys
import numpy as np
from mpm_warp.io import RunWriter
path, n, kill = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "kill"
base = np.random.default_rng(1).random((n, 3))
w = RunWriter(path, n_particles=n, particle_fields={"x": ((3,), "float32", "m"), "v": ((3,), "float64", "m/s")},
              wall_names=["floor"], scalar_series={"kinetic_energy": "J"},
              static_fields={"x0": (base, "m")}, attrs={"scenario": {"name": "damage"}})
for k in range(4):
    w.write_frame(0.1 * k, 10 * k, {"x": base + k, "v": base - k}, np.full((1, 3), float(k)), {"kinetic_energy": k})
if kill:
    os.kill(os.getpid(), signal.SIGKILL)
w.close()
"""


def _env() -> dict:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")]),
            "MPM_WARP_OPEN_TIMEOUT": str(TIMEOUT)}


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    """A run file closed by its writer and one whose writer was killed (superblock still 'open for write')."""
    d = tmp_path_factory.mktemp("src")
    out = {}
    for kind in ("closed", "killed"):
        path = str(d / f"{kind}.h5")
        p = subprocess.run([sys.executable, "-c", CHILD, path, str(N), "kill" if kind == "killed" else "close"],
                           env=_env(), capture_output=True, text=True)
        assert p.returncode == (-signal.SIGKILL if kind == "killed" else 0), p.stderr
        out[kind] = path
    with pytest.raises(OSError, match="already open for write"):   # what makes the SWMR open necessary
        h5py.File(out["killed"], "r")
    return out


def _read_all(path) -> dict:
    run = mw.read_run(path)
    data = {"times": run.times, "steps": run.steps, "walls": run.wall_forces, "x0": run.static["x0"],
            "ke": run.scalars["kinetic_energy"]}
    for i in range(run.n_frames):
        for k, a in run.frame(i).items():
            data[f"{k}{i}"] = a
    return data


def _flipped(src, dst, offset) -> str:
    shutil.copy(src, dst)
    with open(dst, "r+b") as fh:
        fh.seek(offset)
        b = fh.read(1)
        fh.seek(offset)
        fh.write(bytes([b[0] ^ 0xFF]))
    return str(dst)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["closed", "killed"])
def test_flipped_bytes_fail_fast_or_read_right(sources, tmp_path, monkeypatch, kind):
    """A byte flipped anywhere: read_run and every frame either read exactly the original numbers or raise one
    OutputError line, within the probe's time box; metadata and data flips are caught."""
    monkeypatch.setenv("MPM_WARP_OPEN_TIMEOUT", str(TIMEOUT))
    want = _read_all(sources[kind])
    assert (mw.read_run(sources[kind])._swmr) is (kind == "killed")
    size = os.path.getsize(sources[kind])
    offsets = sorted({*np.linspace(0, size - 1, 24 if kind == "closed" else 12).astype(int), 20, 60, 300})
    caught, slowest = 0, 0.0
    for off in offsets:
        path = _flipped(sources[kind], tmp_path / f"d{off}.h5", off)
        t0 = time.perf_counter()
        try:
            got = _read_all(path)
        except OutputError as e:
            assert "\n" not in str(e) and path in str(e)
            caught += 1
        else:
            assert got.keys() == want.keys()
            for k in want:
                np.testing.assert_array_equal(got[k], want[k], err_msg=f"offset {off}: {k} read wrong")
        slowest = max(slowest, time.perf_counter() - t0)
    assert slowest < TIMEOUT + 5.0
    assert caught >= len(offsets) // 2          # most of a small file is checksummed metadata or data


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["closed", "killed"])
def test_truncated_files_fail_fast(sources, tmp_path, monkeypatch, kind):
    monkeypatch.setenv("MPM_WARP_OPEN_TIMEOUT", str(TIMEOUT))
    size = os.path.getsize(sources[kind])
    for frac in (0.01, 0.2, 0.5, 0.9, 0.99):
        path = str(tmp_path / f"t{frac}.h5")
        shutil.copy(sources[kind], path)
        os.truncate(path, int(size * frac))
        t0 = time.perf_counter()
        with pytest.raises(OutputError, match="damaged"):
            _read_all(path)
        assert time.perf_counter() - t0 < TIMEOUT + 5.0


@pytest.mark.slow
def test_data_flip_is_caught_by_the_chunk_checksum(sources, tmp_path):
    """One byte of frame 2's positions, in a closed file: Fletcher-32 fails that frame, the others read."""
    with h5py.File(sources["closed"], "r") as f:
        info = f["particles/x"].id.get_chunk_info(2)
        assert f["particles/x"].fletcher32 and f["time"].fletcher32 and f["static/x0"].fletcher32
    path = _flipped(sources["closed"], tmp_path / "chunk.h5", info.byte_offset + info.size // 2)
    run = mw.read_run(path)
    run.frame(1)
    with pytest.raises(OutputError, match=r"damaged \(frame 2"):
        run.frame(2)


@pytest.mark.slow
def test_cli_on_a_damaged_killed_run_exits_2_within_seconds(sources, tmp_path):
    """`plot`, `render`, `resume` on a killed writer's file with a flipped metadata byte: exit 2, one line, in
    about the probe's time box (the SWMR open itself would never return)."""
    path = _flipped(sources["killed"], tmp_path / "run.h5", 20)          # the superblock's checksummed part
    for argv in (["plot", path], ["render", path], ["resume", path]):
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "mpm_warp.cli", *argv], env=_env(), capture_output=True,
                           text=True, timeout=120)
        assert p.returncode == 2, p.stderr
        lines = p.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("mpm-warp: error: ") and "Traceback" not in p.stderr
        assert "damaged" in lines[0] or "checkpoint" in lines[0]
        assert time.perf_counter() - t0 < TIMEOUT + 20.0


# --------------------------------------------------------------------------------------------- checkpoints
def test_flipped_checkpoint_never_reads_as_other_numbers(tmp_path):
    """A byte flipped anywhere in a checkpoint: the same arrays and meta, or 'checkpoint is corrupt'."""
    path = str(tmp_path / "c.ckpt.h5")
    arrays = {"x": np.random.default_rng(2).random((N, 3)).astype(np.float32), "clock": np.arange(4.0),
              "monitors/m/series/t": np.linspace(0, 1, 7)}
    io.write_checkpoint(path, arrays, {"frame_index": 3, "scenario": {"name": "c"}})
    size = os.path.getsize(path)
    corrupt = 0
    for off in np.linspace(0, size - 1, 40).astype(int):
        p = _flipped(path, tmp_path / f"c{off}.h5", off)
        try:
            got, meta = io.read_checkpoint(p)
        except OutputError as e:
            assert "\n" not in str(e)
            corrupt += "checkpoint is corrupt" in str(e)
            continue
        assert meta == {"frame_index": 3, "scenario": {"name": "c"}}
        for k in arrays:
            np.testing.assert_array_equal(got[k], arrays[k])
    assert corrupt > 0
    with h5py.File(path, "r") as f:                # no HDF5 checksum covers raw array bytes: the SHA-256 does
        offset, nbytes = f["x"].id.get_offset(), f["x"].nbytes
    for k, off in enumerate(np.linspace(offset, offset + nbytes - 1, 10).astype(int)):
        with pytest.raises(OutputError, match=r"x\d\.h5: checkpoint is corrupt \(checksum mismatch\)"):
            io.read_checkpoint(_flipped(path, tmp_path / f"x{k}.h5", off))
    assert not io.checkpoint_is_intact(str(tmp_path / "x0.h5")) and io.checkpoint_is_intact(path)


def test_blow_up_never_names_a_corrupt_checkpoint(tmp_path):
    """A run that blows up after its checkpoint was damaged reports no checkpoint (never 'last good')."""
    c_p = mw.Elastic(1.0e6, 0.3, 250.0).p_wave_speed
    dt = 3.0 * 0.02 / c_p                      # three times the stable step: blows up within 40 steps
    overrides = [f"time.dt={dt!r}", f"time.end={40 * dt!r}", f"time.frame_interval={2 * dt!r}",
                 "output.checkpoint_every=0", "output.health_every=1", "blocks.0.velocity=[0.0, -1.0, 0.0]",
                 "time.allow_unstable_dt=true"]
    out = str(tmp_path / "run.h5")
    ckpt = io.checkpoint_path_for(out)

    def damage(sim, k):
        if k == 1:
            with h5py.File(ckpt, "r") as f:
                offset = f["x"].id.get_offset()
            _flipped(ckpt, tmp_path / "bad.h5", offset + 3)
            os.replace(tmp_path / "bad.h5", ckpt)

    with pytest.raises(mw.SimulationBlowUp) as info:
        mw.run("elastic_block", out, "cpu", overrides, callback=damage)
    assert info.value.checkpoint is None and "checkpoint" not in str(info.value)
    assert info.value.step > 2                  # it blew up after the damage (frame 1 ends at step 2)
    with pytest.raises(mw.SimulationBlowUp) as info:     # the same run with an intact checkpoint names it
        mw.run("elastic_block", out, "cpu", overrides, overwrite=True)
    assert info.value.checkpoint == ckpt and "last good checkpoint" in str(info.value)


# ------------------------------------------------------------------------------------------------- resume
@pytest.fixture
def made(tmp_path):
    out = str(tmp_path / "run.h5")
    mw.run("elastic_block", out, "cpu", ["time.end=0.06", "time.frame_interval=0.02", "output.checkpoint_every=1"])
    return out


def _files(d) -> dict:
    return {p.name: p.read_bytes() for p in d.iterdir()}


def test_resume_refuses_a_last_frame_unlike_its_checkpoint(made, tmp_path):
    """Frame 3 rewritten with other (checksum-valid) positions: resume refuses it and changes nothing."""
    with h5py.File(made, "r+") as f:
        f["particles/x"][3] = f["particles/x"][3] + 1e-3
    before = _files(tmp_path)
    with pytest.raises(OutputError, match=r"frame 3 differs from the state of its checkpoint"):
        mw.resume(made, device="cpu", end_time=0.08)
    assert _files(tmp_path) == before


def test_resume_refuses_a_damaged_kept_frame(made, tmp_path):
    """A flipped byte in frame 1 (kept by the resume): refused, the file is left as it was, nothing copied."""
    with h5py.File(made, "r") as f:
        info = f["particles/v"].id.get_chunk_info(1)
    _flipped(made, tmp_path / "bad.h5", info.byte_offset + 4)
    os.replace(tmp_path / "bad.h5", made)
    before = _files(tmp_path)
    with pytest.raises(OutputError, match=r"run\.h5: damaged \(frame 1"):
        mw.resume(made, device="cpu", end_time=0.08)
    assert _files(tmp_path) == before


def test_resume_of_an_intact_run_keeps_its_frames(made):
    before = mw.read_run(made)
    res = mw.resume(made, device="cpu", end_time=0.1)
    after = mw.read_run(made)
    assert after.n_frames == 6 and res.frames == 2
    for k in range(4):
        np.testing.assert_array_equal(after.frame(k)["x"], before.frame(k)["x"])
