"""Crash safety of mpm_warp.io with real kills: every crash point leaves a readable, consistent run file.

Child processes writing run files are killed by signals at random times and,
under strace, at their K-th pwrite (new files and resumed ones): every
reported frame is there and nothing partial; the last complete checkpoint
resumes. The per-frame series rewritten in place keep each chunk inside one
4 KiB page, so a SIGKILL between pages cannot tear one (CPU only; the strace
tests are skipped without strace).
"""

from __future__ import annotations

import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from mpm_warp.io import RunWriter, read_checkpoint, read_run

pytestmark = pytest.mark.slow

CHILD = r"""
import signal, sys
import numpy as np
from mpm_warp.io import RunWriter, write_checkpoint
signal.signal(signal.SIGINT, signal.default_int_handler)
path, ckpt, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
base = np.random.default_rng(1).random((n, 3), dtype=np.float32)
fields = {"x": ((3,), "float32", "m"), "v": ((3,), "float32", "m/s"), "Jp": ((), "float32", "1")}
with RunWriter(path, n_particles=n, particle_fields=fields, wall_names=["floor"],
               scalar_series={"kinetic_energy": "J"}) as w:
    k = 0
    while True:
        w.write_frame(0.5 * k, 7 * k, {"x": base + k, "v": base - k, "Jp": np.full(n, k, np.float32)},
                      np.full((1, 3), float(k)), {"kinetic_energy": k})
        write_checkpoint(ckpt, {"x": base + k, "v": base - k}, {"frames": k + 1})
        print(k, flush=True)
        k += 1
"""


def _child_env() -> dict:
    """Environment of a child process that imports this checkout of mpm_warp."""
    root = str(pathlib.Path(__file__).resolve().parents[1])
    return {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}


def _check_killed_run(path, n, reported):
    run = read_run(path)
    assert reported + 1 <= run.n_frames <= reported + 2     # every reported frame, nothing partial
    base = np.random.default_rng(1).random((n, 3), dtype=np.float32)
    for k in range(run.n_frames):
        fr = run.frame(k)
        np.testing.assert_array_equal(fr["x"], base + k)
        np.testing.assert_array_equal(fr["v"], base - k)
        assert np.all(fr["Jp"] == k) and run.times[k] == 0.5 * k and run.steps[k] == 7 * k
        assert run.wall_forces[k, 0, 0] == k and run.scalars["kinetic_energy"][k] == k
    return run.n_frames


@pytest.mark.parametrize("sig", [signal.SIGKILL] * 3 + [signal.SIGTERM, signal.SIGINT],
                         ids=["SIGKILL-1", "SIGKILL-2", "SIGKILL-3", "SIGTERM", "SIGINT"])
def test_killed_writer_leaves_readable_file(tmp_path, sig):
    """A real child process writing 100k-particle frames is killed at a random time."""
    path, ckpt, n = tmp_path / "run.h5", tmp_path / "run.ckpt.h5", 100_000
    env = _child_env()
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(path), str(ckpt), str(n)],
                             stdout=subprocess.PIPE, text=True, env=env)
    rng = np.random.default_rng()
    try:
        assert child.stdout.readline().strip() == "0"
        t0 = time.perf_counter()
        assert child.stdout.readline().strip() == "1"
        time.sleep(rng.uniform(0.0, 1.5 * (time.perf_counter() - t0)))   # anywhere in a frame
        child.send_signal(sig)
        for _ in range(10):                               # KeyboardInterrupt may land in a GC callback
            try:
                child.wait(timeout=1)
                break
            except subprocess.TimeoutExpired:
                child.send_signal(sig)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    out = child.stdout.read().split()
    assert child.returncode == -sig
    n_frames = _check_killed_run(path, n, int(out[-1]) if out else 1)
    arrays, meta = read_checkpoint(ckpt)                  # the last complete checkpoint
    assert meta["frames"] in (n_frames - 1, n_frames)
    base = np.random.default_rng(1).random((n, 3), dtype=np.float32)
    np.testing.assert_array_equal(arrays["x"], base + (meta["frames"] - 1))
    if sig == signal.SIGINT:                              # closed by __exit__: a plain HDF5 file
        with h5py.File(path, "r"):
            pass
    with RunWriter.reopen(path, keep_frames=meta["frames"]) as w:   # resume from the checkpoint
        k = w.n_frames
        w.write_frame(0.5 * k, 7 * k, {"x": base + k, "v": base - k, "Jp": np.full(n, k, np.float32)},
                      np.full((1, 3), float(k)), {"kinetic_energy": k})
    assert read_run(path).n_frames == meta["frames"] + 1
    _check_killed_run(path, n, meta["frames"] - 1)


STRACE_CHILD = r"""
import sys
import numpy as np
from mpm_warp.io import RunWriter
path, mode = sys.argv[1], sys.argv[2]
base = np.random.default_rng(1).random((100, 3), dtype=np.float32)
if mode == "new":
    w = RunWriter(path, n_particles=100, particle_fields={"x": ((3,), "float32", "m")}, wall_names=["a"])
else:
    w = RunWriter.reopen(path, keep_frames=1)
with w:
    for k in range(w.n_frames, w.n_frames + 2):
        w.write_frame(0.5 * k, k, {"x": base + k}, np.full((1, 3), float(k)))
        print(k, flush=True)
"""


def _strace_works() -> bool:
    try:
        return subprocess.run(["strace", "-qq", "-o", os.devnull, "true"], timeout=10).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


@pytest.mark.skipif(not _strace_works(), reason="needs strace (and ptrace) for fault injection")
@pytest.mark.parametrize("mode", ["new", "resume"])
def test_kill_at_each_write(tmp_path, mode):
    """strace kills the writer at its K-th pwrite: every crash point leaves a consistent file."""
    env = _child_env()
    base = np.random.default_rng(1).random((100, 3), dtype=np.float32)
    path, source = tmp_path / "run.h5", tmp_path / "source.h5"
    subprocess.run([sys.executable, "-c", STRACE_CHILD, str(source), "new"], env=env, check=True)
    for K in range(1, 400, 7):
        shutil.copy(source, path) if mode == "resume" else path.unlink(missing_ok=True)
        p = subprocess.run(["strace", "-qq", "-o", os.devnull, "-e", "trace=pwrite64", "-e",
                            f"inject=pwrite64:signal=SIGKILL:when={K}", sys.executable, "-c",
                            STRACE_CHILD, str(path), mode], env=env, capture_output=True, text=True)
        if p.returncode == 0:
            assert K > 20                                 # the whole range of crash points was seen
            break
        done = [int(k) for k in p.stdout.split()]
        if not path.exists():                             # killed while building the file
            assert mode == "new" and not done
            continue
        run = read_run(path)
        lo = done[-1] + 1 if done else (0 if mode == "new" else 1)
        assert lo <= run.n_frames <= lo + 1, (K, done, run.n_frames)
        for k in range(run.n_frames):
            np.testing.assert_array_equal(run.frame(k)["x"], base + k)
            assert run.times[k] == 0.5 * k and run.wall_forces[k, 0, 0] == k


PAGE_CHILD = r"""
import sys
import numpy as np
from mpm_warp.io import RunWriter
path, n_frames = sys.argv[1], int(sys.argv[2])
base = np.random.default_rng(1).random((20, 3), dtype=np.float32)
with RunWriter(path, n_particles=20, particle_fields={"x": ((3,), "float32", "m")}, wall_names=["a", "b"],
               scalar_series={"kinetic_energy": "J"}) as w:
    for k in range(n_frames):
        w.write_frame(0.5 * k, k, {"x": base + k}, np.full((2, 3), float(k)), {"kinetic_energy": k})
"""


def test_series_chunks_fit_one_page(tmp_path):
    """The small per-frame series are rewritten in place at every frame until their chunk is full: each chunk
    (rows and Fletcher-32 checksum) must lie inside one 4 KiB page of a paged-aggregation file, so that a
    SIGKILL during the rewrite (Linux stops a write only between pages) cannot tear it and take every frame
    of the chunk with it."""
    path = tmp_path / "run.h5"
    subprocess.run([sys.executable, "-c", PAGE_CHILD, str(path), "1100"], env=_child_env(), check=True)
    with h5py.File(path, "r") as f:
        fcpl = f.id.get_create_plist()
        assert fcpl.get_file_space_strategy()[0] == h5py.h5f.FSPACE_STRATEGY_PAGE
        assert fcpl.get_file_space_page_size() == 4096
        for name, row in (("time", 8), ("step", 8), ("scalars/kinetic_energy", 8), ("walls/forces", 48)):
            d = f[name]
            assert d.shape[0] == 1100 and d.chunks[0] == (4096 - 4) // row, name
            n_chunks = d.id.get_num_chunks()
            assert n_chunks == -(-1100 // d.chunks[0]), name
            for i in range(n_chunks):
                info = d.id.get_chunk_info(i)
                assert info.size <= 4096 and info.byte_offset // 4096 == (info.byte_offset + info.size - 1) // 4096, \
                    (name, i, info.byte_offset, info.size)
        np.testing.assert_array_equal(f["walls/forces"][:, 1, 2], np.arange(1100.0))
        np.testing.assert_array_equal(f["time"][()], 0.5 * np.arange(1100))


@pytest.mark.skipif(not _strace_works(), reason="needs strace (and ptrace) to record the writes")
def test_no_write_in_place_straddles_a_page(tmp_path):
    """Every pwrite of a 1100-frame run that rewrites bytes written before (chunk index, headers, the series'
    partly filled chunks) stays inside one 4 KiB page; only new, not yet referenced chunks span pages."""
    path, log = tmp_path / "run.h5", tmp_path / "pwrite.log"
    subprocess.run(["strace", "-qq", "-o", str(log), "-e", "trace=pwrite64", sys.executable, "-c", PAGE_CHILD,
                    str(path), "1100"], env=_child_env(), check=True)
    written, straddling, n = set(), [], 0
    for line in log.read_text().splitlines():
        parts = line.rsplit(")", 1)[0].rsplit(",", 2)
        if not line.startswith("pwrite64(") or len(parts) < 3:
            continue
        size, offset = int(parts[1]), int(parts[2])
        n += 1
        if offset in written and offset // 4096 != (offset + size - 1) // 4096:
            straddling.append((offset, size))
        written.add(offset)
    assert n > 1100 * 4 and not straddling, (n, straddling[:5])
