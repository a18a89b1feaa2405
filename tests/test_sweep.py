"""Parameter sweeps on Dask (mpm_warp.sweep), on the CPU.

Four tiny elastic_block runs (t_end 0.02 s, two frames) on a two-worker LocalCluster reached by
its scheduler address (the ``--scheduler`` path); the embedded-cluster path is exercised by the
command line, run in a subprocess that is SIGKILLed after its first finished run and then resumed.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import os
import signal
import subprocess
import sys
import time

import distributed  # noqa: E402,F401  (a test dependency: the sweep tests must run, never skip)
import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.sweep import _tasks, expand_cases, parse_vary, read_cases, run_sweep, split_values

SCENE = "elastic_block"
TINY = ["time.end=0.02", "time.frame_interval=0.01"]
VARY = {"materials.snow.E": ["1e6", "2e6"], "time.cfl": ["0.3", "0.4"]}


@pytest.fixture(scope="module")
def scheduler():
    """Address of a two-worker LocalCluster (processes, one thread each) shared by this module."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster:
        yield cluster.scheduler_address


def _ok_jsons(folder) -> dict:
    out = {}
    for name in os.listdir(folder):
        if name.endswith(".json"):
            with open(os.path.join(folder, name)) as fh:
                if json.load(fh)["status"] == "ok":
                    out[name] = os.stat(os.path.join(folder, name)).st_mtime_ns
    return out


def _runs(folder) -> list:
    return sorted(n for n in os.listdir(folder) if n.endswith(".h5") and not n.endswith((".ckpt.h5", ".part.h5")))


# ------------------------------------------------------------------------------------- cases
def test_cases_product_csv_and_values():
    assert split_values("0, 10,[1, 2],'a,b'") == ["0", "10", "[1, 2]", "'a,b'"]
    assert parse_vary(["a.b=1,2", "c=[0, 1],[2, 3]"]) == {"a.b": ["1", "2"], "c": ["[0, 1]", "[2, 3]"]}
    cases = expand_cases({"x": "1,2", "y": [3, 4, 5]}, [{"z": 0}, {"z": 1}])
    assert len(cases) == 12 and cases[0] == {"z": 0, "x": "1", "y": 3} and cases[-1] == {"z": 1, "x": "2", "y": 5}
    assert expand_cases() == [{}]
    with pytest.raises(mw.InvalidArgument, match="--vary"):
        parse_vary(["nokey"])


def test_cases_file(tmp_path):
    p = tmp_path / "cases.csv"
    p.write_text("materials.snow.E,time.cfl\n1e6,0.3\n2e6,\n\n")
    assert read_cases(p) == [{"materials.snow.E": "1e6", "time.cfl": "0.3"}, {"materials.snow.E": "2e6"}]


def test_run_id_is_hash_of_effective_scenario():
    raw = {"name": "s", "time": {"end": 1.0}, "scene": {"slope_angle": 0}}
    cases = [{"time.end": "2.0"}, {"time.end": 2.0}, {"time.end": "3.0"}, {"slope_angle": 30},
             {"scene.slope_angle": 30}]
    ids = [t["id"] for t in _tasks(raw, "s.toml", cases, [], ".", None, None)]
    assert ids[0].startswith("s-") and len(ids) == 3          # 2.0 == "2.0"; slope_angle means scene.slope_angle
    assert _tasks(raw, "s.toml", [{}], [("time.end", 2.0)], ".", None, None)[0]["id"] == ids[0]


# --------------------------------------------------------------------------------- the sweep
@pytest.mark.slow
def test_sweep_equals_runs_made_one_by_one(scheduler, tmp_path):
    out = tmp_path / "sweep"
    res = run_sweep(SCENE, VARY, out_dir=out, overrides=TINY, scheduler=scheduler, device="cpu", progress=False)
    assert len(res.rows) == 4 and not res.failed and res.skipped == 0
    assert len(_runs(out)) == 4 and sorted(r["output"] for r in res.rows) == _runs(out)
    with open(res.path, newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["id"] for r in table] == [r["id"] for r in res.rows]
    assert list(table[0])[:4] == ["id", "status", "materials.snow.E", "time.cfl"]
    with open(res.figure, "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    for i, (row, line) in enumerate(zip(res.rows, table, strict=True)):
        case = [f"{k}={row[k]}" for k in VARY]
        ref = mw.run(SCENE, output=str(tmp_path / f"serial{i}.h5"), device="cpu", overrides=TINY + case)
        a, b = mw.read_run(out / row["output"]), mw.read_run(ref.output)
        assert (row["steps"], row["frames"], row["sim_time"], row["n_particles"]) == (
            ref.steps, ref.frames, ref.sim_time, ref.n_particles)
        for name in ("kinetic_energy", "elastic_energy"):
            assert row[f"final_{name}"] == b.scalars[name][-1] == float(line[f"final_{name}"])
        np.testing.assert_array_equal(a.frame(-1)["x"], b.frame(-1)["x"])
        np.testing.assert_array_equal(a.frame(-1)["v"], b.frame(-1)["v"])
        assert int(line["steps"]) == ref.steps and line["status"] == "ok" and line["error"] == ""
        with open(out / (row["id"] + ".json")) as fh:
            rec = json.load(fh)
        assert rec["status"] == "ok" and rec["result"]["steps"] == ref.steps and rec["n_frames"] == 3


@pytest.mark.slow
def test_failed_case_reported_others_complete(scheduler, tmp_path):
    cases = tmp_path / "cases.csv"
    cases.write_text("materials.snow.E,materials.snow.nu\n1e6,\n2e6,\n1e6,0.7\n3e6,0.25\n")
    stream = io.StringIO()
    res = run_sweep(SCENE, cases=str(cases), out_dir=tmp_path / "sweep", overrides=TINY, scheduler=scheduler,
                    device="cpu", progress=stream)
    assert [r["status"] for r in res.rows] == ["ok", "ok", "failed", "ok"]
    assert "materials.snow.nu = 0.7" in res.failed[0]["error"] and res.failed[0]["output"] is None
    assert len(_runs(tmp_path / "sweep")) == 3
    assert "4/4 done (1 failed, 0 skipped)" in stream.getvalue()
    with open(tmp_path / "sweep" / (res.failed[0]["id"] + ".json")) as fh:
        assert json.load(fh)["error"].startswith("InvalidArgument: materials.snow.nu")


@pytest.mark.slow
def test_killed_sweep_resumes_without_recomputing(scheduler, tmp_path):
    out = tmp_path / "sweep"
    vary = ["--vary", "materials.snow.E=1e6,2e6,3e6,4e6"]
    sets = [a for o in TINY for a in ("--set", o)]
    cmd = [sys.executable, "-m", "mpm_warp.cli", "sweep", SCENE, *vary, *sets, "--out", str(out),
           "--workers", "1", "--device", "cpu", "--quiet"]
    with open(tmp_path / "log.txt", "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            deadline = time.monotonic() + 60
            while not (out.exists() and _ok_jsons(out)) and proc.poll() is None and time.monotonic() < deadline:
                time.sleep(0.02)
        finally:
            os.killpg(proc.pid, signal.SIGKILL)   # the sweep and its workers (its own session)
            proc.wait()
    before = _ok_jsons(out)
    assert 1 <= len(before) < 4, (tmp_path / "log.txt").read_text()
    h5 = {n: os.stat(out / n).st_mtime_ns for n in _runs(out)}
    assert len(h5) == len(before)

    res = run_sweep(SCENE, parse_vary(vary[1:]), out_dir=out, overrides=TINY, scheduler=scheduler, device="cpu",
                    progress=False)
    assert res.skipped == len(before) and not res.failed and len(_runs(out)) == 4
    after = _ok_jsons(out)
    assert all(after[n] == t for n, t in before.items())
    assert all(os.stat(out / n).st_mtime_ns == t for n, t in h5.items())
    with open(res.path, newline="") as fh:
        assert [r["status"] for r in csv.DictReader(fh)] == ["ok"] * 4


def dying_runner(scenario, output, device):
    """Kill the worker process on the first attempt of the E = 2 MPa case; run normally otherwise."""
    marker = os.path.join(os.path.dirname(output), "died-once")
    if scenario.materials["snow"].E == 2e6 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return mw.run(scenario, output, device)


@pytest.mark.slow
def test_run_of_dead_worker_is_retried(scheduler, tmp_path):
    out = tmp_path / "sweep"
    res = run_sweep(SCENE, {"materials.snow.E": [1e6, 2e6]}, out_dir=out, overrides=TINY, scheduler=scheduler,
                    device="cpu", runner=dying_runner, progress=False)
    assert (out / "died-once").exists()
    assert [r["status"] for r in res.rows] == ["ok", "ok"] and len(_runs(out)) == 2
