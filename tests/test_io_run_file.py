"""Run files and checkpoints of mpm_warp.io: layout, round trip, append and reopen, refusals (CPU only).

A run file written frame by frame reads back bit for bit (every compression),
also while it is written; its attributes, units, walls, scalar series and
static fields; reopening keeps the first frames and appends; a frame cut
short is ignored and trimmed; bad frames and bad layouts are refused naming
the field and the shapes; checkpoints round-trip and are replaced atomically.
"""

from __future__ import annotations

import datetime
import os

import h5py
import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument, OutputError
from mpm_warp.io import (
    FORMAT,
    FORMAT_VERSION,
    RunWriter,
    checkpoint_path_for,
    read_checkpoint,
    read_run,
    write_checkpoint,
)

N = 50
FIELDS = {"x": ((3,), "float32", "m"), "F": ((3, 3), "float32", "1"), "Jp": ((), "float64", "1")}
SCALARS = {"kinetic_energy": "J", "elastic_energy": "J", "front_position": "m"}
WALLS = ["floor", "left"]


def _frame(k: int, n: int = N) -> dict[str, np.ndarray]:
    base = np.random.default_rng(1).random((n, 3), dtype=np.float32)
    return {"x": base + k, "F": np.broadcast_to(np.eye(3, dtype=np.float32) * k, (n, 3, 3)),
            "Jp": np.full(n, 0.5 * k)}


def _write(w: RunWriter, k: int) -> int:
    return w.write_frame(0.01 * k, 100 * k, _frame(k), np.full((2, 3), -k, float),
                         {"kinetic_energy": k, "elastic_energy": 2 * k, "front_position": 0.1 * k})


def _check(run, frames) -> None:
    assert run.n_frames == len(frames)
    for i, k in enumerate(frames):
        got, want = run.frame(i), _frame(k)
        for name in FIELDS:
            np.testing.assert_array_equal(got[name], want[name].astype(FIELDS[name][1]))
        assert run.times[i] == 0.01 * k and run.steps[i] == 100 * k
        np.testing.assert_array_equal(run.wall_forces[i], np.full((2, 3), -k))
        assert run.scalars["elastic_energy"][i] == 2 * k


def _writer(path, **kw) -> RunWriter:
    kw.setdefault("attrs", {"scenario": '[slab]\nlength = 2.0\n', "versions": {"mpm_warp": "0.1.0"},
                            "device": "cpu", "precision": "float32"})
    return RunWriter(path, n_particles=N, particle_fields=FIELDS, wall_names=WALLS, scalar_series=SCALARS,
                     static_fields={"material": (np.arange(N, dtype=np.int32) % 2, "1")}, **kw)


@pytest.mark.parametrize("compression", ["gzip", "lzf", "none"])
def test_round_trip(tmp_path, compression):
    path = tmp_path / "run.h5"
    with _writer(path, compression=compression) as w:
        assert [_write(w, k) for k in range(2)] == [0, 1]
        _check(read_run(path), range(2))                  # a run can be read while it is written
        assert [_write(w, k) for k in range(2, 4)] == [2, 3]
        assert w.n_frames == 4
    run = read_run(path)
    _check(run, range(4))
    assert run.particle_fields == ["x", "F", "Jp"]
    assert run.attrs["format"] == FORMAT and run.attrs["format_version"] == FORMAT_VERSION
    assert run.attrs["device"] == "cpu" and run.attrs["versions"]["mpm_warp"] == "0.1.0"
    assert "h5py" in run.attrs["versions"] and run.attrs["units"]["length"] == "m"
    datetime.datetime.fromisoformat(run.attrs["created"])
    assert run.scenario == {"slab": {"length": 2.0}}
    assert run.units == {"time": "s", "step": "1", "x": "m", "F": "1", "Jp": "1", "material": "1",
                         "kinetic_energy": "J", "elastic_energy": "J", "front_position": "m",
                         "wall_forces": "N"}
    assert run.wall_names == WALLS and run.wall_forces.shape == (4, 2, 3)
    np.testing.assert_array_equal(run.static["material"], np.arange(N) % 2)
    np.testing.assert_allclose(run.scalars["front_position"], 0.1 * np.arange(4))
    assert run.field("F").shape == (4, N, 3, 3) and run.field("x").dtype == np.float32
    np.testing.assert_array_equal(run.frame(-1)["x"], run.frame(3)["x"])
    np.testing.assert_array_equal(run.frame(-4)["Jp"], run.frame(0)["Jp"])
    with h5py.File(path, "r") as f:                       # cleanly closed: plain HDF5 opens it
        assert f["particles/x"].chunks == (1, N, 3) and f["particles/x"].attrs["unit"] == "m"
        assert f["particles/x"].compression == {"none": None}.get(compression, compression)


def test_scenario_dict_and_no_walls(tmp_path):
    path = tmp_path / "run.h5"
    with RunWriter(path, n_particles=3, particle_fields={"x": ((3,), "float32", "m")},
                   attrs={"scenario": {"grid": {"dx": 0.01}}}) as w:
        w.write_frame(0.0, 0, {"x": np.zeros((3, 3))})
    run = read_run(path)
    assert run.scenario == {"grid": {"dx": 0.01}} and run.scalars == {} and run.static == {}
    assert run.wall_forces.shape == (1, 0, 3) and run.wall_names == []


def test_bad_indices(tmp_path):
    path = tmp_path / "run.h5"
    with _writer(path) as w:
        _write(w, 0)
    run = read_run(path)
    with pytest.raises(InvalidArgument, match="frame"):
        run.frame(1)
    with pytest.raises(InvalidArgument, match="frame"):
        run.frame(-2)
    with pytest.raises(InvalidArgument, match="'v'"):
        run.field("v")


def test_write_frame_errors_name_field_and_shapes(tmp_path):
    path = tmp_path / "run.h5"
    w = _writer(path)
    _write(w, 0)
    good = dict(time=1.0, step=1, particles=_frame(1), wall_forces=np.zeros((2, 3)),
                scalars={"kinetic_energy": 1, "elastic_energy": 1, "front_position": 1})
    bad_cases = [
        ({"particles": {**_frame(1), "x": np.zeros((N, 2))}}, r"particles\['x'\].shape = \(50, 2\).*\(50, 3\)"),
        ({"particles": {**_frame(1), "F": np.zeros((N - 1, 3, 3))}}, r"\(49, 3, 3\).*\(50, 3, 3\)"),
        ({"particles": {"x": _frame(1)["x"]}}, "declared fields"),
        ({"particles": {**_frame(1), "Jp": np.zeros(N, complex)}}, "dtype"),
        ({"wall_forces": None}, "wall_forces"),
        ({"wall_forces": np.zeros(3)}, r"wall_forces.shape = \(3,\)"),
        ({"scalars": {"kinetic_energy": 1}}, "declared series"),
        ({"time": float("nan")}, "time"),
    ]
    for change, match in bad_cases:
        with pytest.raises(InvalidArgument, match=match):
            w.write_frame(**{**good, **change})
    assert w.n_frames == 1
    w.close()
    assert read_run(path).n_frames == 1                   # nothing of the bad frames was written
    with pytest.raises(OutputError):
        w.write_frame(**good)


def test_constructor_errors(tmp_path):
    path = tmp_path / "run.h5"
    with pytest.raises(InvalidArgument, match="n_particles"):
        RunWriter(path, n_particles=0, particle_fields=FIELDS)
    with pytest.raises(InvalidArgument, match="compression"):
        RunWriter(path, n_particles=N, particle_fields=FIELDS, compression="zstd")
    with pytest.raises(InvalidArgument, match=r"static_fields\['m'\].shape"):
        RunWriter(path, n_particles=N, particle_fields=FIELDS, static_fields={"m": (np.zeros(3), "1")})
    with pytest.raises(InvalidArgument, match="attrs"):
        RunWriter(path, n_particles=N, particle_fields=FIELDS, attrs={"format": "x"})
    with pytest.raises(InvalidArgument, match="particle_fields"):
        RunWriter(path, n_particles=N, particle_fields={"a/b": ((), "float32", "m")})
    with pytest.raises(InvalidArgument, match="unique"):
        RunWriter(path, n_particles=N, particle_fields=FIELDS, scalar_series={"x": "m"})
    with pytest.raises(InvalidArgument, match="4 GiB"):
        RunWriter(path, n_particles=2**30, particle_fields=FIELDS)
    assert not path.exists()
    _writer(path).close()
    with pytest.raises(OutputError, match="exists"):
        _writer(path, overwrite=False)


@pytest.mark.parametrize("compression", ["lzf", "none"])
def test_reopen_keeps_frames_and_appends(tmp_path, compression):
    path = tmp_path / "run.h5"
    with _writer(path, compression=compression) as w:
        for k in range(5):
            _write(w, k)
    before = read_run(path)
    with RunWriter.reopen(path, keep_frames=3, attrs={"resumed_by": "test"}) as w:   # from a checkpoint
        assert w.n_frames == 3
        assert _write(w, 10) == 3
    _check(read_run(path), [0, 1, 2, 10])
    with _writer(path, append=True) as w:                 # same layout given explicitly
        _write(w, 11)
    run = read_run(path)
    _check(run, [0, 1, 2, 10, 11])
    assert [h["kept_frames"] for h in run.attrs["resumed"]] == [3, 4]
    assert run.attrs["resumed_by"] == "test" and run.scenario == before.scenario
    assert {k: run.attrs[k] for k in ("created", "device", "versions")} == \
        {k: before.attrs[k] for k in ("created", "device", "versions")}
    np.testing.assert_array_equal(run.static["material"], before.static["material"])
    with h5py.File(path, "r") as f:
        assert f["particles/x"].compression == {"none": None}.get(compression, compression)
    assert sorted(os.listdir(tmp_path)) == ["run.h5"]
    with pytest.raises(InvalidArgument, match="keep_frames"):
        RunWriter.reopen(path, keep_frames=6)
    with pytest.raises(InvalidArgument, match="layout"):
        RunWriter(path, n_particles=N, particle_fields={"x": FIELDS["x"]}, append=True)


def test_partial_frame_is_ignored_and_trimmed(tmp_path):
    path = tmp_path / "run.h5"
    with _writer(path) as w:
        for k in range(3):
            _write(w, k)
    with h5py.File(path, "r+") as f:                      # a frame cut after its first dataset
        f["particles/x"].resize(4, axis=0)
        f["particles/x"][3] = -1
    _check(read_run(path), range(3))
    with RunWriter.reopen(path) as w:
        _write(w, 3)
    _check(read_run(path), range(4))


def test_not_a_run(tmp_path):
    with pytest.raises(OutputError, match="no such file"):
        read_run(tmp_path / "missing.h5")
    (tmp_path / "text.h5").write_text("not hdf5")
    with pytest.raises(OutputError, match="not a readable HDF5"):
        read_run(tmp_path / "text.h5")
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f["data"] = np.arange(3)
    with pytest.raises(OutputError, match="not an mpm_warp-run"):
        read_run(tmp_path / "other.h5")
    with pytest.raises(OutputError):
        RunWriter.reopen(tmp_path / "other.h5")
    write_checkpoint(tmp_path / "c.h5", {"x": np.zeros(2)}, {})
    with pytest.raises(OutputError, match="not an mpm_warp-run"):
        read_run(tmp_path / "c.h5")
    with pytest.raises(OutputError, match="not an mpm_warp-checkpoint"):
        read_checkpoint(tmp_path / "other.h5")


def test_checkpoint_round_trip_and_atomic_replace(tmp_path):
    path = tmp_path / "run.ckpt.h5"
    arrays = {"x": np.random.default_rng(0).random((N, 3)).astype(np.float32),
              "state/F": np.tile(np.eye(3), (N, 1, 1)), "step": np.int64(42)}
    meta = {"step": np.int64(42), "time": 0.5, "frames": 3, "scenario": {"dx": 0.01}}
    write_checkpoint(path, arrays, meta)
    got, got_meta = read_checkpoint(path)
    assert set(got) == set(arrays) and got_meta == {"step": 42, "time": 0.5, "frames": 3,
                                                     "scenario": {"dx": 0.01}}
    for name, a in arrays.items():
        np.testing.assert_array_equal(got[name], a)
        assert got[name].dtype == np.asarray(a).dtype
    with pytest.raises(TypeError):                        # fails mid-write: old checkpoint intact
        write_checkpoint(path, {"x": np.zeros(3), "bad": np.array([object()])}, {"step": 43})
    assert read_checkpoint(path)[1]["step"] == 42
    assert sorted(os.listdir(tmp_path)) == ["run.ckpt.h5"]
    write_checkpoint(path, {"x": np.ones(2)}, {"step": 43})
    assert read_checkpoint(path)[1]["step"] == 43 and list(read_checkpoint(path)[0]) == ["x"]


def test_checkpoint_path_for():
    assert checkpoint_path_for("out/run.h5") == "out/run.ckpt.h5"
    assert checkpoint_path_for("run.hdf5") == "run.ckpt.h5"
    assert checkpoint_path_for("run") == "run.ckpt.h5"
