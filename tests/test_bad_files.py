"""Hostile files and paths on the command line (docs/robustness.md): exit 2 with one line naming the file and the
cause, within seconds, no traceback; nothing is written or replaced."""

from __future__ import annotations

import os
import shutil
import time

import h5py
import pytest
from helpers_bad_input import BASE, one_line, sub

import mpm_warp as mw
from mpm_warp.cli import main


# ------------------------------------------------------------ files and paths (CLI: exit 2, one line)
@pytest.fixture(scope="module")
def made_run(tmp_path_factory):
    """A finished run of BASE (3 frames to t = 0.01 s, a checkpoint at every frame) and its scenario file."""
    d = tmp_path_factory.mktemp("made")
    (d / "scene.toml").write_text(sub("checkpoint_every = 5", "checkpoint_every = 1"))
    mw.run(str(d / "scene.toml"), str(d / "run.h5"), "cpu")
    return d


def _read_only_dir(tmp_path) -> str:
    """A folder nobody may create files in (root ignores permission bits, but not sysfs)."""
    if os.geteuid() == 0:
        return "/sys"
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    return str(ro)


def _copy_run(made, tmp_path) -> str:
    for name in ("run.h5", "run.ckpt.h5", "scene.toml"):
        shutil.copy(made / name, tmp_path / name)
    return str(tmp_path / "run.h5")


def _flip(path, offset: int) -> None:
    with open(path, "r+b") as fh:
        fh.seek(offset)
        b = fh.read(1)
        fh.seek(offset)
        fh.write(bytes([b[0] ^ 0xFF]))


def _case_binary(made, tmp):
    (tmp / "s.toml").write_bytes(bytes(range(256)) * 8)
    return ["run", str(tmp / "s.toml")], ("not UTF-8",)


def _case_utf16(made, tmp):
    (tmp / "s.toml").write_text(BASE, encoding="utf-16")
    return ["run", str(tmp / "s.toml")], ("not UTF-8", "UTF-16")


def _case_nested(made, tmp):
    (tmp / "s.toml").write_text(sub("lo = [0.1, 0.02, 0.0]", "lo = " + "[" * 500 + "0.1" + "]" * 500))
    return ["run", str(tmp / "s.toml")], ("nested too deeply",)


def _case_nested_16(made, tmp):  # too deep for a scenario, far from Python's recursion limit
    (tmp / "s.toml").write_text(sub("lo = [0.1, 0.02, 0.0]", "lo = " + "[" * 16 + "0.1" + "]" * 16))
    return ["run", str(tmp / "s.toml")], ("nested too deeply", "more than 16 levels")


def _case_scenario_dir(made, tmp):
    return ["run", str(tmp)], ("is a directory",)


def _case_scenario_fifo(made, tmp):
    """A FIFO with no writer: opening it would wait for ever (it hung for 643 s); refused before it is opened."""
    os.mkfifo(tmp / "fifo.toml")
    return ["run", str(tmp / "fifo.toml"), "--out", str(tmp / "run.h5")], ("fifo.toml: is not a regular file",)


def _case_scenario_device(made, tmp):
    return ["run", "/dev/zero"], ("/dev/zero: is not a regular file",)


def _case_scenario_socket(made, tmp):
    import socket

    s = socket.socket(socket.AF_UNIX)
    s.bind(str(tmp / "sock.toml"))                 # left bound: the path is a socket while the CLI looks at it
    return ["run", str(tmp / "sock.toml")], ("sock.toml: is not a regular file",)


def _case_out_dir(made, tmp):
    (tmp / "out").mkdir()
    return ["run", str(made / "scene.toml"), "--out", str(tmp / "out")], ("is a directory",)


def _case_out_missing_dir(made, tmp):
    return ["run", str(made / "scene.toml"), "--out", str(tmp / "missing" / "run.h5")], ("does not exist",)


def _case_out_read_only(made, tmp):
    return ["run", str(made / "scene.toml"), "--out", _read_only_dir(tmp) + "/run.h5"], ("not writable",)


def _case_out_exists(made, tmp):
    path = _copy_run(made, tmp)
    return ["run", str(made / "scene.toml"), "--out", path], ("exists", "--overwrite")


def _case_out_is_scenario(made, tmp):
    path = _copy_run(made, tmp)
    scene = path.replace("run.h5", "scene.toml")
    return ["run", scene, "--out", scene, "--overwrite"], ("is the input scenario", "even with overwrite")


def _case_out_fifo(made, tmp):
    os.mkfifo(tmp / "fifo.h5")
    return ["run", str(made / "scene.toml"), "--out", str(tmp / "fifo.h5"), "--overwrite"], ("not a regular file",)


def _case_out_dev_null(made, tmp):
    return ["run", str(made / "scene.toml"), "--out", "/dev/null", "--overwrite"], ("not a regular file",)


def _case_memory_domain(made, tmp):
    """A 40 m domain at dx = 1 cm: 6.4e10 grid nodes, 1 TiB."""
    return ["run", str(made / "scene.toml"), "--set", "domain.hi=[40.0, 40.0, 40.0]", "--set", "domain.dx=0.01"], \
        ("domain.lo/hi", "needed", "available (MemAvailable)", "shrink the domain")


def _case_memory_particles(made, tmp):
    """dx = 0.2 mm with 8 particles per cell and axis: 1.5e10 particles, 1.3 TiB."""
    return ["run", str(made / "scene.toml"), "--set", "domain.dx=0.0002", "--set", "blocks.0.particles_per_cell=8"], \
        ("domain.dx = 0.0002", "1.54e+10 particles", "available (MemAvailable)", "raise domain.dx")


def _case_max_memory(made, tmp):
    return ["run", str(made / "scene.toml"), "--max-memory", "50k"], ("domain.dx", "available (max_memory)")


def _out_folder(command, how):
    """``command``'s ``--out`` folder (render: frames, plot: plots) missing, a file, or in a read-only folder."""
    def case(made, tmp):
        name = "frames" if command == "render" else "plots"
        if how == "is-file":
            (tmp / "f").write_text("x")
        out = {"missing-folder": str(tmp / "missing" / name), "is-file": str(tmp / "f"),
               "read-only": _read_only_dir(tmp) + "/" + name}[how]
        why = {"missing-folder": "does not exist", "is-file": "not a folder", "read-only": "not writable"}[how]
        return [command, str(made / "run.h5"), "--out", out], (why,)
    return case


def _case_resume_end_before(made, tmp):
    return ["resume", _copy_run(made, tmp), "--end", "0.004", "--quiet"], ("end_time = 0.004", "t = 0.01 s")


def _case_resume_corrupt_checkpoint(made, tmp):
    path = _copy_run(made, tmp)
    ckpt = path.replace("run.h5", "run.ckpt.h5")
    with h5py.File(ckpt, "r") as f:
        offset = f["x"].id.get_offset()           # raw bytes of the positions: no HDF5 checksum covers them
    _flip(ckpt, offset + 5)
    return ["resume", path, "--quiet", "--end", "0.02"], ("run.ckpt.h5: checkpoint is corrupt (checksum mismatch)",)


def _damaged(command, how):
    def case(made, tmp):
        path = _copy_run(made, tmp)
        if how == "truncated":
            os.truncate(path, os.path.getsize(path) // 2)
        else:   # a metadata block (the positions' header) or data: frame 1 of the positions (plot: the times)
            with h5py.File(path, "r") as f:
                d = f["time"] if command == "plot" else f["particles/x"]
                offset = h5py.h5o.get_info(d.id).addr + 20 if how == "header" else \
                    d.id.get_chunk_info(d.id.get_num_chunks() - 1 if command == "plot" else 1).byte_offset + 10
            _flip(path, offset)
        extra = {"resume": ["--quiet", "--end", "0.02"], "render": ["--field", "displacement"]}.get(command, [])
        return [command, path, *extra], ("run.h5: damaged",)
    return case


FILE_CASES = [
    ("binary-scenario", _case_binary), ("utf16-scenario", _case_utf16), ("nested-500", _case_nested),
    ("nested-16-arrays", _case_nested_16),
    ("scenario-is-directory", _case_scenario_dir), ("scenario-fifo", _case_scenario_fifo),
    ("scenario-device", _case_scenario_device), ("scenario-socket", _case_scenario_socket),
    ("out-is-directory", _case_out_dir),
    ("out-missing-folder", _case_out_missing_dir), ("out-read-only-folder", _case_out_read_only),
    ("out-exists", _case_out_exists), ("out-is-the-scenario", _case_out_is_scenario), ("out-fifo", _case_out_fifo),
    ("out-dev-null", _case_out_dev_null), ("memory-40m-domain", _case_memory_domain),
    ("memory-1.5e10-particles", _case_memory_particles), ("max-memory", _case_max_memory),
    *((f"{cmd}-out-{how}", _out_folder(cmd, how)) for cmd in ("render", "plot")
      for how in ("missing-folder", "is-file", "read-only")),
    ("resume-end-before-checkpoint", _case_resume_end_before),
    ("resume-corrupt-checkpoint", _case_resume_corrupt_checkpoint),
] + [(f"{cmd}-{how}-run-file", _damaged(cmd, how)) for cmd in ("plot", "render", "resume")
     for how in ("header", "chunk", "truncated")]


@pytest.mark.parametrize("make", [pytest.param(f, id=i) for i, f in FILE_CASES])
def test_cli_files_one_line_exit_2(made_run, tmp_path, capsys, make):
    """Hostile files and paths: exit 2 with one line naming the file and the cause, within seconds, no traceback;
    nothing is written or replaced."""
    argv, needles = make(made_run, tmp_path)
    before = {p: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < 20
    _, err = capsys.readouterr()
    line = one_line(err)
    assert line.startswith("mpm-warp: error: ") and "Traceback" not in err and "last good" not in line
    for n in needles:
        assert n in line, f"{n!r} not in {line!r}"
    assert {p: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith((".lock", ".part", ".tmp"))]
