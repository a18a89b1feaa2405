"""mpm_warp.studies: the convergence arithmetic against closed forms and the committed ladders, the snow ladder's
bookkeeping, the scripts' protocol and the environment record."""

import argparse
import json
import math
import os
import re

import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.finite_json import load_json
from mpm_warp.studies.convergence import (
    errors_against_reference,
    ladder_summary,
    loglog_slope,
    observed_order,
    richardson,
    time_to,
    time_to_target,
)
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.snow import field_level_dx, grid_bracket, merge_pst_parts, split_pst_parts

CONVERGENCE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks", "convergence",
                           "results")


# ----------------------------------------------------------------------------- convergence
def test_loglog_slope_of_a_power_law_and_its_missing_points():
    x = np.array([0.1, 0.2, 0.4, 0.8])
    assert loglog_slope(x, 3.0 * x**1.5) == pytest.approx(1.5, abs=1e-12)
    # non-finite and non-positive pairs are left out; fewer than two pairs left: nan
    y = 3.0 * x**1.5
    assert loglog_slope(x, [y[0], math.nan, 0.0, y[3]]) == pytest.approx(1.5, abs=1e-12)
    assert math.isnan(loglog_slope([0.1, 0.2], [0.3, math.inf]))
    assert observed_order([1.0, 0.5, 0.25], [0.4, 0.1, 0.025]) == pytest.approx(2.0, abs=1e-12)


@pytest.mark.parametrize("ratio", [2.0, 3.0])
def test_richardson_recovers_the_limit_and_order_of_a_second_order_ladder(ratio):
    h = [1.0 / ratio**k for k in range(4)]
    v = [1.25 + 0.7 * x**2 for x in h]      # v(h) = v0 + C h^p exactly: three levels give v0 and p
    value, p = richardson(h, v)
    assert value == pytest.approx(1.25, abs=1e-12) and p == pytest.approx(2.0, abs=1e-9)


def test_richardson_says_when_the_levels_are_not_asymptotic():
    h = [0.04, 0.02, 0.01]
    assert all(math.isnan(x) for x in richardson(h, [1.0, 1.1, 1.0]))        # not monotone
    assert all(math.isnan(x) for x in richardson(h, [1.0, math.nan, 1.0]))
    value, p = richardson(h, [1.0, 1.5, 1.5 + 0.5 / 64])                       # p = 6: outside [0.5, 4]
    assert math.isnan(value) and p == pytest.approx(6.0)
    with pytest.raises(ValueError, match="need one ratio"):
        richardson([0.04, 0.02, 0.005], [1.0, 1.5, 1.75])


def test_time_to_an_error_along_the_ladder():
    walls = [10.0, 100.0, 1000.0, 10000.0]
    # log-log between the levels that bracket 5 %: 10 % at 100 s, 2.5 % at 1000 s -> half way in log, 316 s
    r = time_to([0.4, 0.1, 0.025, 0.0], walls, 0.05)
    assert r["status"] == "interpolated" and r["wall_time_s"] == pytest.approx(1000.0 ** 0.5 * 10.0)
    assert r["between_levels"] == [1, 2] and r["fraction"] == pytest.approx(0.5)
    assert time_to([0.01, 0.005, 0.001, 0.0], walls, 0.05)["status"] == "already at the coarsest"
    # a critical cut in the same bracket from the third level on: met there, not only at the reference level
    r = time_to([float("nan"), 0.056, 0.0, 0.0], walls, 0.01)
    assert r == {"status": "met where the value first equals the finest's", "wall_time_s": 1000.0}
    assert time_to([0.3, 0.2, 0.1, 0.0], walls, 0.01) == {"status": "at the finest (the reference)",
                                                            "wall_time_s": 10000.0}
    assert time_to([0.3, 0.2, 0.1], walls[:3], 0.01)["status"] == "not reached"


def test_time_to_target_interpolates_the_spacing_too():
    runs = [{"dx": 0.4, "error": 0.04, "wall_time_s": 1.0}, {"dx": 0.2, "error": 0.01 / 2, "wall_time_s": 8.0},
            {"dx": 0.1, "error": None, "wall_time_s": 60.0}]          # a blow-up: no error, left out
    r = time_to_target(runs, 0.02)
    # ln(0.02) is a third of the way from ln(0.04) to ln(0.005): time 8^(1/3) = 2 s, dx 0.4 / 2^(1/3)
    assert r["status"] == "interpolated" and r["wall_time_s"] == pytest.approx(2.0)
    assert r["dx"] == pytest.approx(0.4 / 2 ** (1 / 3)) and [b["dx"] for b in r["between"]] == [0.4, 0.2]
    assert time_to_target(runs, 0.001) == {"status": "not reached", "error_at_finest_compared": 0.005,
                                           "error": 0.005, "wall_time_s": 8.0, "dx": 0.2}
    assert time_to_target(runs[2:], 0.01) == {"status": "no valid runs"}


def test_ladder_summary_reproduces_the_committed_snow_ladders():
    """The summary stored with the snow ladders (error_vs_runtime_snow.json) follows from its levels."""
    data = load_json(os.path.join(CONVERGENCE, "error_vs_runtime_snow.json"))   # nan where it has null + reason
    quantities = {"pst": ("critical_cut", "speed", "touchdown", "collapse_height"),
                  "shear": ("peak", "delta_s", "delta_s_whole_layer", "collapse")}
    for ladder, levels in data["ladders"].items():
        got = ladder_summary([lv for lv in levels if lv["precision"] == "float32"], quantities[ladder])
        want = data["summary"][ladder]
        assert set(got) == set(want)
        for q, s in got.items():
            np.testing.assert_array_equal(s["values"], want[q]["values"])
            np.testing.assert_array_equal(s["error_vs_finest"], want[q]["error_vs_finest"])
            np.testing.assert_array_equal(s["error_vs_richardson"], want[q]["error_vs_richardson"])
            for t, r in s["time_to"].items():
                assert r == want[q]["time_to"][t]
    # the PST's crack speed: Richardson over 6, 12, 24 cells, order 1.7
    speed = data["summary"]["pst"]["speed"]
    assert speed["richardson"] == pytest.approx(22.41, abs=0.01)
    assert speed["observed_order"] == pytest.approx(1.69, abs=0.01)


def test_a_level_off_the_ladder_is_measured_against_the_ladders_own_reference():
    """The field protocol's level (4 cells across the ladder's 6 cm layer: dx 15 mm) against the committed PST
    ladder: the crack speed against its Richardson value (22.41 m/s), the touchdown against the finest level's
    (0.7413 m); a missing value has no error; the critical cut's bisection bracket gives its half width."""
    assert field_level_dx() == pytest.approx(0.015, rel=1e-15)
    data = load_json(os.path.join(CONVERGENCE, "error_vs_runtime_snow.json"))
    summ = data["summary"]["pst"]
    rec = {"speed": 20.0, "touchdown": 0.70, "collapse_height": math.nan, "critical_cut": 0.353125,
           "critical_cut_bracket": [0.34375, 0.3625]}
    got = errors_against_reference(rec, summ, ("critical_cut", "speed", "touchdown", "collapse_height"))
    assert got["speed"]["reference_is"] == "richardson"
    assert got["speed"]["error"] == pytest.approx(1.0 - 20.0 / summ["speed"]["richardson"], rel=1e-12)
    assert got["speed"]["error"] == pytest.approx(0.1075, abs=1e-4)
    assert got["touchdown"]["reference_is"] == "finest level"
    assert got["touchdown"]["error"] == pytest.approx(1.0 - 0.70 / 0.7413022939415157, rel=1e-12)
    assert math.isnan(got["collapse_height"]["error"])
    assert got["critical_cut"]["error"] == pytest.approx(0.353125 / 0.334375 - 1.0, rel=1e-12)   # 5.6 %
    assert got["critical_cut"]["half_width"] == pytest.approx(0.5 * 0.01875 / 0.353125, rel=1e-12)


def test_observed_orders_of_the_committed_reference_problems():
    with open(os.path.join(CONVERGENCE, "error_vs_runtime.json")) as fh:
        data = json.load(fh)
    for name, p in data["problems"].items():
        ok = [r for r in p["dx_ladder"] if r.get("error") is not None and r["error"] > 0]
        assert observed_order([r["dx"] for r in ok], [r["error"] for r in ok]) == \
            pytest.approx(p["summary"]["observed_order_dx"], rel=1e-12), name


# ----------------------------------------------------------------------------- the snow ladder's bookkeeping
def test_narrowed_bracket_must_lie_on_the_full_searchs_grid():
    """A narrowed search ends in one of the full search's final brackets: [0.1, 0.7] m to 2 cm is a grid of
    0.6 / 32 = 0.01875 m, so 0.30625 and 0.34375 m (points 11 and 13) are allowed and 0.31 m is not."""
    assert grid_bracket(0.30625, 0.34375) == {"lo": 0.30625, "hi": 0.34375, "tol": 0.02}
    with pytest.raises(InvalidArgument, match=r"bracket lo = 0.31 is invalid: expected a point of the bisection grid "
                                              r"0.1 \+ k \* 0.01875 m inside \[0.1, 0.7\] m"):
        grid_bracket(0.31, 0.34375)
    with pytest.raises(InvalidArgument, match="bracket hi = 0.75 is invalid"):
        grid_bracket(0.1, 0.75)
    with pytest.raises(InvalidArgument, match="expected lo < hi"):
        grid_bracket(0.34375, 0.30625)


def _level_parts() -> tuple[dict, dict]:
    """A 24-cell level's base run (commit a) and narrowed critical-cut search (commit b), run apart."""
    base = {"dx": 0.0025, "precision": "float32", "level": 3, "note": "base run only (critical cut not bisected)",
            "critical_cut": float("nan"), "speed": 22.0, "touchdown": 0.74, "collapse_height": 0.007,
            "wall_time_s": 8000.0, "steps": 130000, "n_particles": 591360, "git_commit": "a"}
    cut = {"dx": 0.0025, "precision": "float32", "level": 3, "part": "critical_cut", "critical_cut": 0.315625,
           "critical_cut_bracket": [0.30625, 0.325], "bracketed": True, "critical_cut_note": "", "trials": [{}],
           "critical_cut_wall_s": 3000.0, "critical_cut_steps": 100000, "bisection": {"lo": 0.30625},
           "speed": float("nan"), "wall_time_s": 3000.0, "steps": 100000, "n_particles": 591360, "git_commit": "b"}
    return base, cut


def test_a_levels_base_run_and_critical_cut_merge_in_either_order():
    base, cut = _level_parts()
    for merged in (merge_pst_parts(cut, base), merge_pst_parts({**base, "part": "base_run"}, cut)):
        assert merged["part"] == "both" and merged["critical_cut"] == 0.315625 and merged["speed"] == 22.0
        assert merged["wall_time_s"] == 11000.0 and merged["steps"] == 230000
        assert merged["git_commit"] == "b" and merged["git_commit_base_run"] == "a"
    assert merge_pst_parts(cut, None)["part"] == "critical_cut"
    assert merge_pst_parts({**base, "part": "base_run"}, None)["part"] == "base_run"


def test_a_critical_cut_run_again_replaces_only_that_part_of_a_merged_level():
    """Rerunning a level's narrowed critical cut (``--redo --pst-bracket``) over a record of both parts keeps
    the base run's speed, wall time, steps and commit, and takes the new search's cut, time and commit."""
    base, cut = _level_parts()
    both = merge_pst_parts(cut, base)
    again = {**cut, "critical_cut": 0.334375, "critical_cut_wall_s": 2500.0, "critical_cut_steps": 90000,
             "wall_time_s": 2500.0, "steps": 90000, "git_commit": "c"}
    merged = merge_pst_parts(again, both)
    assert merged["part"] == "both" and merged["critical_cut"] == 0.334375 and merged["speed"] == 22.0
    assert merged["wall_time_s"] == 10500.0 and merged["steps"] == 220000
    assert merged["git_commit"] == "c" and merged["git_commit_base_run"] == "a"
    parts = split_pst_parts(both)
    assert parts["base_run"]["wall_time_s"] == 8000.0 and parts["base_run"]["git_commit"] == "a"
    assert parts["critical_cut"]["critical_cut"] == 0.315625 and parts["critical_cut"]["git_commit"] == "b"




# ----------------------------------------------------------------------------- protocol and environment
def _args(**kw):
    return argparse.Namespace(**{"device": "cpu", "quick": False, "out": None, **kw})


def test_a_quick_run_never_writes_over_the_committed_results(tmp_path):
    committed = str(tmp_path / "results")
    quick = out_dir(_args(quick=True), committed, "x")
    assert os.path.isdir(quick) and os.path.realpath(quick) != os.path.realpath(committed)
    assert out_dir(_args(quick=True, out=str(tmp_path / "mine")), committed) == str(tmp_path / "mine")
    assert out_dir(_args(), committed) == committed             # a full run: the committed results
    assert result_name("leave_out", _args(quick=True)) == "leave_out_cpu_quick"
    assert result_name("leave_out", _args(device="cuda:0")) == "leave_out_cuda"
    a = parser("doc", "small").parse_args(["--quick", "--out", "d"])
    assert (a.device, a.quick, a.out) == ("cpu", True, "d")


def test_environment_record_is_written_with_the_load_at_the_end(tmp_path):
    env = environment("cpu")
    for key in ("date", "device", "load_average_1_5_15_min", "cpu", "cpu_count", "mpm_warp", "warp", "numpy",
                "h5py", "python", "git_commit"):
        assert key in env, key
    assert env["device"] == "cpu" and len(env["load_average_1_5_15_min"]) == 3
    if os.path.exists("/proc/cpuinfo"):      # the host's CPU generation, e.g. "AMD EPYC family 25 model 17 avx512f"
        assert re.fullmatch(r".+ family \d+ model \d+( avx512f)?", env["cpu_model"]), env["cpu_model"]
    path = write_json("r", {"environment": env, "x": np.float64(0.5)}, str(tmp_path / "out"))
    with open(path) as fh:
        back = json.load(fh)
    assert back["x"] == 0.5 and len(back["environment"]["load_average_at_end_1_5_15_min"]) == 3
    assert os.listdir(tmp_path / "out") == ["r.json"]           # no temporary file left
