"""The block benchmarks' shared code (mpm_warp.studies.perf): grid sizes, the block timed in mpm_warp, the update's
cost on known trial states, and the Taichi peer (its checks without Taichi; a run where Taichi is installed)."""

import importlib.util
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from mpm_warp.studies import plastic_block as pb
from mpm_warp.studies.blocks import expected_com_y
from mpm_warp.studies.perf import taichi_mpm, taichi_peer
from mpm_warp.studies.perf.throughput import MIN_N_GRID_ELASTIC, n_grid_for, run

HAS_TAICHI = importlib.util.find_spec("taichi") is not None


def test_n_grid_for_rounds_to_the_even_grid_with_the_closest_particle_count():
    assert n_grid_for(4096, 3) == 16                      # 16**3 = 4096 particles
    assert n_grid_for(4096, 2) == 64
    assert n_grid_for(1.0e6, 2) == 1000 and n_grid_for(1.0e6, 3) == 100
    assert n_grid_for(250_000, 3) == 62                   # 62.996: 62**3 = 238,328 is closer than 64**3 = 262,144
    assert n_grid_for(100, 3) == MIN_N_GRID_ELASTIC == 16  # 4.6 -> the elastic minimum
    assert n_grid_for(4096, 3, "plastic") == pb.MIN_N_GRID == 24


def test_the_package_modules_import_without_taichi():
    """A plain import of every module of the subpackage leaves Taichi unimported (it is the optional extra)."""
    mods = ", ".join(f"mpm_warp.studies.perf.{m}" for m in ("taichi_peer", "taichi_mpm", "taichi_camclay",
                                                             "throughput", "update_cost", "warp_block"))
    code = f"import sys\nimport {mods}\nassert 'taichi' not in sys.modules, 'taichi imported'\n"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_the_taichi_side_refuses_bad_arguments_before_it_needs_taichi():
    with pytest.raises(ValueError, match="steps and repeats"):
        taichi_peer.run_taichi_block(32, 0)
    with pytest.raises(ValueError, match="p2g_scatter"):
        taichi_peer.run_taichi_block(32, 5, p2g_scatter="fast")
    with pytest.raises(ValueError, match="arch"):
        taichi_peer.run_taichi_block(32, 5, arch="tpu")
    with pytest.raises(ValueError, match="dim must be 2 or 3"):
        taichi_mpm.build(None, 32, 4, "elastic")
    with pytest.raises(ValueError, match="material must be"):
        taichi_mpm.build(None, 32, 3, "snow")


@pytest.mark.skipif(HAS_TAICHI, reason="checks the answer without Taichi")
def test_without_taichi_the_peer_says_so_without_a_child():
    res, err = taichi_peer.run_taichi_block_subprocess(32, 5)
    assert res is None and "taichi is not installed" in err


@pytest.mark.slow
@pytest.mark.skipif(HAS_TAICHI, reason="checks the answers without Taichi")
def test_without_taichi_the_child_answers_exit_status_3(tmp_path):
    # another interpreter (a wrapper of this one): the child runs as python -m and answers exit status 3
    other = tmp_path / "python"
    other.write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    other.chmod(0o755)
    res, err = taichi_peer.run_taichi_block_subprocess(32, 5, python=str(other), timeout_s=120)
    assert res is None and err == f"taichi is not installed for {other}"
    proc = subprocess.run([sys.executable, "-m", taichi_peer.MODULE, "--n-grid", "16"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 3 and "taichi is not installed" in proc.stderr


@pytest.mark.slow
def test_taichi_peer_runs_the_elastic_block_in_its_own_interpreter():
    pytest.importorskip("taichi")
    res, err = taichi_peer.run_taichi_block_subprocess(16, 2, cpu_max_num_threads=1, repeats=1, dim=2, warmup=1,
                                                       timeout_s=300)
    assert err is None, err
    assert res["n_particles"] == 256 and res["steps"] == 2 and res["warmup"] == 1 and res["threads"] == 1
    assert res["com_y_after"] == pytest.approx(res["com_y_expected"], abs=1e-6)
    assert res["bytes_per_particle"] == 4.0 * (2 * 2 + 2 * 4)   # x, v, C, F in float32


@pytest.mark.slow
def test_run_times_the_block_and_writes_its_json(tmp_path):
    """A 2D elastic block of 16 cells per axis: 256 particles, free fall to float32 rounding, one JSON."""
    out = run([2], ["elastic"], [256], steps=2, device="cpu", threads_list=[1], taichi=True, name="t", repeats=1,
              results_dir=str(tmp_path), env={"device": "cpu"})
    with open(tmp_path / "t.json") as fh:
        assert json.load(fh)["rows"] == json.loads(json.dumps(out["rows"]))
    assert list(out["seconds"]) == ["2d_elastic_16_1"] and out["environment"]["device"] == "cpu"
    w = out["rows"][0]
    assert (w["engine"], w["n_grid"], w["n_particles"], w["warmup"], w["steps"]) == ("mpm_warp", 16, 256, 3, 2)
    assert w["com_y"] == pytest.approx(expected_com_y(w["warmup"] + w["steps"], w["dt"]), abs=1e-6)
    assert w["bytes_per_particle"] == 48.0                # x, v (8 B each), C, H (16 B each) in float32
    assert w["particle_steps_per_s"] == pytest.approx(256 / w["s_per_step"]) and set(w["stages_s"])
    if not HAS_TAICHI:
        assert out["rows"][1]["engine"] == "taichi" and "not installed" in out["rows"][1]["error"]


@pytest.mark.slow
def test_update_cost_on_known_trial_states():
    """The struck block's particles given one trial state each: at rest (no particle yields) and compressed by
    tr eps = -0.01 in plane strain (p = K 0.01 = 8.3 kPa beyond p0 = 3.7 kPa on the p axis: every particle
    yields, on the cap)."""
    from mpm_warp.studies.blocks import block_simulation
    from mpm_warp.studies.perf.update_cost import update_cost

    sim = block_simulation(2, "plastic", pb.MIN_N_GRID)
    s, n = sim.state, sim.model.n_particles
    dt = float(sim.scenario.time.dt)
    zeros = np.zeros((n, 2, 2), dtype=np.float32)
    s.H.assign(zeros)
    s.hzz.assign(np.zeros(n, dtype=np.float32))
    s.log_jp.assign(np.full(n, pb.initial_log_jp(), dtype=np.float32))
    s.C.assign(zeros)
    rest = update_cost(sim, repeats=1)
    assert (rest["series_says_yielding"], rest["series_range_fraction"], rest["return_yielded"]) == (0.0, 1.0, 0.0)
    assert set(rest["engine_vs_principal_path"].values()) == {0.0}     # elastic: the same arithmetic both ways
    c = math.expm1(-0.005) / dt                                # F = (1 + dt c) I: eps = -0.005 in plane
    s.C.assign(np.tile(np.float32(c) * np.eye(2, dtype=np.float32), (n, 1, 1)))
    squeezed = update_cost(sim, repeats=1)
    assert squeezed["series_says_yielding"] == squeezed["return_yielded"] == squeezed["series_range_fraction"] == 1.0
    for cost in (rest, squeezed):
        assert all(cost[k] > 0.0 for k in ("update_s", "principal_path_update_s", "series_check_s", "principal_s",
                                           "return_s"))
    diff = squeezed["engine_vs_principal_path"]  # the two paths agree to float32 rounding (tau ~ 4 kPa: 5e-4 Pa an ulp)
    assert diff["tau_Pa"] < 1e-2 and diff["log_jp"] < 1e-6 and diff["H"] < 1e-7 and diff["hzz"] < 1e-7
