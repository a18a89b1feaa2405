"""A write that finds no room (docs/robustness.md): one line saying how many complete frames are safe and how to go
on, no temporary left, the lock released, never a crash; then the resume, after space is freed, is bit for bit.

Two stand-ins for a full disk, neither needing a mount:

- a file-size limit (``RLIMIT_FSIZE``, as ``ulimit -f``): the kernel refuses any write past N bytes of a file
  (``EFBIG``), inside HDF5 too, at a byte chosen from the run's own file sizes. It reaches the paths a real
  full disk reached before: a checkpoint's datasets failing under h5py crashed the process (SIGSEGV, rc 139)
  and left ``*.ckpt.h5.tmp`` and a stale lock;
- ``ENOSPC`` raised in-process at the n-th frame, checkpoint or record (the free-space check and plain writes).

A real small tmpfs is exercised by ``benchmarks/robustness/disk_full.py`` (needs root and mount).
"""

from __future__ import annotations

import errno
import os
import subprocess
import sys

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp import io
from mpm_warp.cli import main

SETS = ["time.end=0.05", "time.frame_interval=0.005", "output.checkpoint_every=3"]
CHILD = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), int(sys.argv[1])))
from mpm_warp.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted run (11 frames, checkpoints at frames 0, 3, 6, 9) and its checkpoint's size."""
    d = tmp_path_factory.mktemp("reference")
    mw.run("elastic_block", str(d / "r.h5"), "cpu", SETS)
    return str(d / "r.h5"), os.path.getsize(d / "r.ckpt.h5")


def assert_same_run(a: str, b: str) -> None:
    ra, rb = mw.read_run(a), mw.read_run(b)
    assert ra.n_frames == rb.n_frames
    np.testing.assert_array_equal(ra.times, rb.times)
    for k in range(ra.n_frames):
        for name in ra.particle_fields:
            np.testing.assert_array_equal(ra.frame(k)[name], rb.frame(k)[name])
    np.testing.assert_array_equal(ra.wall_forces, rb.wall_forces)


def _leftovers(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith((".tmp", ".part", ".lock")))


def _limited_run(tmp_path, limit: int) -> tuple[int, str]:
    out = tmp_path / "r.h5"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                                          os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-c", CHILD, str(limit), "run", "elastic_block", "--out", str(out), "--quiet",
                        "--device", "cpu", *[a for s in SETS for a in ("--set", s)]],
                       capture_output=True, text=True, timeout=300, env=env)
    return p.returncode, "\n".join(ln for ln in p.stderr.splitlines() if "CUDA" not in ln)


@pytest.mark.slow
@pytest.mark.parametrize("phase", ["run file", "first checkpoint", "frame"])
def test_file_size_limit_is_one_line_and_resumes_bit_for_bit(reference, tmp_path, capsys, phase):
    """The limit at 8 KiB (the run file's layout), 4 KiB under the checkpoint's size (its first checkpoint, where
    h5py crashed) and 64 KiB over it (a frame, with a checkpoint intact)."""
    ref, ckpt_size = reference
    limit = {"run file": 8192, "first checkpoint": ckpt_size - 4096, "frame": ckpt_size + 65536}[phase]
    rc, err = _limited_run(tmp_path, limit)
    assert rc == 2, err                                        # not 139 (SIGSEGV), not a traceback
    assert err.count("\n") == 0 and err.startswith("mpm-warp: error: ") and "File too large (errno EFBIG)" in err
    assert _leftovers(tmp_path) == []                          # no .tmp, .part, nor a stale lock
    out = str(tmp_path / "r.h5")
    if phase == "run file":
        assert "while writing the run file" in err and "0 complete frames" in err and "--overwrite" in err
        assert not os.path.exists(out)
        return
    if phase == "first checkpoint":
        assert "while writing the checkpoint; 1 complete frame is safe in" in err and "--overwrite" in err
        assert mw.read_run(out).n_frames == 1 and not os.path.exists(io.checkpoint_path_for(out))
        assert main(["run", "elastic_block", "--out", out, "--quiet", "--overwrite", "--device", "cpu",
                     *[a for s in SETS for a in ("--set", s)]]) == 0
    else:
        n = int(err.split(" complete frames are safe")[0].rsplit(" ", 1)[1])
        assert 4 <= n < 11 and f"while writing frame {n};" in err and f"mpm-warp resume {out}" in err
        # the failed flush left the superblock's end of file past the file (no room to pad it under the limit):
        # readers refuse it as truncated, the message says so, and the resume pads it with a hole
        short = os.path.getsize(out) < io.hdf5.stored_eof(out)
        assert short == ("readers refuse it as truncated" in err)
        if short:
            with pytest.raises(mw.OutputError, match="truncated"):
                mw.read_run(out)
        assert main(["resume", out, "--quiet", "--device", "cpu"]) == 0         # space freed: no limit here
    capsys.readouterr()
    assert_same_run(ref, out)


def _free_until(monkeypatch, module, n_calls: int) -> None:
    """Free space is plenty for the first ``n_calls`` checks of ``module``, then none."""
    calls = []
    monkeypatch.setattr(module, "ensure_space", lambda path, nbytes, what, real=io.space.ensure_space: (
        calls.append(what), real(path, nbytes if len(calls) <= n_calls else 2**62, what))[1])


def test_no_space_for_a_frame_then_resume_bit_for_bit(reference, tmp_path, monkeypatch):
    """ENOSPC at frame 5 (its free-space check): frames 0-4 kept, the checkpoint of frame 3 intact; resumed bit for
    bit once there is room."""
    out = str(tmp_path / "r.h5")
    _free_until(monkeypatch, io.runfile, 6)                     # the run file, then frames 0-4
    with pytest.raises(io.OutOfSpace) as info:
        mw.run("elastic_block", out, "cpu", SETS)
    msg = str(info.value)
    assert msg.startswith(f"{out}: No space left on device (errno ENOSPC) while writing frame 5: needs ")
    assert f"5 complete frames are safe in {out} (to t = 0.02 s)" in msg
    assert f"resume from its checkpoint (t = 0.015 s): mpm-warp resume {out}" in msg and "\n" not in msg
    assert info.value.errno == errno.ENOSPC and info.value.frames == 5 and _leftovers(tmp_path) == []
    monkeypatch.undo()
    mw.resume(out, device="cpu")
    assert_same_run(reference[0], out)


def test_no_space_for_a_checkpoint_keeps_the_previous_one(reference, tmp_path, monkeypatch):
    """ENOSPC half-way through the checkpoint of frame 6: no temporary left, the checkpoint of frame 3 intact."""
    out = str(tmp_path / "r.h5")
    written = []

    def short_write(path, data, real=io.space.write_image):
        written.append(path)
        if len(written) == 3:                                   # checkpoints of frames 0, 3, then 6
            with open(path, "wb") as fh:
                fh.write(data[: len(data) // 2])
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(path, data)

    monkeypatch.setattr(io.checkpoint, "write_image", short_write)
    with pytest.raises(io.OutOfSpace) as info:
        mw.run("elastic_block", out, "cpu", SETS)
    msg = str(info.value)
    assert msg.startswith(f"{io.checkpoint_path_for(out)}: No space left on device (errno ENOSPC) while writing the "
                          "checkpoint; 7 complete frames are safe") and "(t = 0.015 s)" in msg
    assert _leftovers(tmp_path) == [] and io.checkpoint_is_intact(io.checkpoint_path_for(out))
    monkeypatch.undo()
    mw.resume(out, device="cpu")
    assert_same_run(reference[0], out)


def test_no_space_for_a_sweep_record_leaves_no_temporary(tmp_path, monkeypatch):
    from mpm_warp import sweep

    def full(tmp):
        with open(tmp, "w") as fh:
            fh.write("{")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(sweep.json, "dump", lambda *a, **k: full(a[1].name))
    with pytest.raises(io.OutOfSpace, match=r"run\.json: No space left on device \(errno ENOSPC\) while writing a "
                                             r"sweep record$"):
        sweep._write_json(str(tmp_path / "run.json"), {"id": 1})
    assert list(tmp_path.iterdir()) == []
