"""The snow error-against-run-time ladders (issue 14): their two coarsest levels, in CI time.

``benchmarks/convergence/error_vs_runtime_snow.py`` halves dx over the shear test of SI Note 2 (3, 6, 12, 24 cells
across its 3 cm layer) and over a flat PST. Here the shear ladder's two coarsest levels run again
(the whole scene, as the benchmark runs it) and the error of each quantity against the ladder's finest
level must fall from 3 to 6 cells. The finest level's values are the benchmark's measurement
(``benchmarks/convergence/results/error_vs_runtime_snow.json``, 24 cells, float32, one thread, 2026-11-30: peak
932.6 Pa, softening slip 2.088 mm (the interior's bond), collapse 0.3055); the coarse values are
recomputed, so a change to the engine that breaks convergence fails here. (The softening slip is
read from frames 0.01 mm of push apart: its errors at 3 and 6 cells, 2.2 and 1.6 %, differ by about
1.4 frames.)

The PST ladder's two coarsest levels (2 and 1 cm: 3 and 6 cells across its 6 cm layer) run their base
run here, the one that measures the front speed, the touchdown and the collapse height (cut 0.7 m, the
crack run into the far end zone: :func:`mpm_warp.scenes.pst.cut_run`, as the benchmark's critical-cut
search runs it); the bisection of the critical cut (about 9 minutes for the two levels) stays in the
benchmark. Their errors are taken against the PST ladder's finest level (24 cells, 2026-11-30: speed
22.12 m/s, touchdown 0.741 m, collapse height 7.74 mm outside the far end zone). At 3 cells the crack
does not run at all: there a quantity of the running crack counts as 100 % wrong, and the ladder's
finding (it runs at 6 cells, not at 3) is asserted too.
"""

import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.pst import cut_run

#: the shear ladder's finest level (24 cells across the layer): error_vs_runtime_snow.json
FINEST = {"peak": 932.5898344665492, "delta_s": 0.0020884051965618265, "collapse": 0.3054789884530086}


#: the PST ladder's scene (benchmarks/convergence/error_vs_runtime_snow.py PST_SCENE): production snow, 2.2 m column
PST_SCENE = ["scene.length=2.2", "scene.slab_thickness=0.3", "scene.weak_layer_thickness=0.06",
             "scene.substratum_thickness=0.06", "scene.margin=0.05"]
#: the PST ladder's finest level (24 cells, dx 2.5 mm, float32, 2026-11-30): error_vs_runtime_snow.json (the collapse
#: height outside the far end zone, read from that run's last checkpoint)
PST_FINEST = {"speed": 22.12034446211075, "touchdown": 0.7413022939415157, "collapse_height": 0.007742506237744472}


def _level(cells: int) -> dict:
    dx = load_scenario("shear_test").scene.weak_layer_thickness / cells
    r = mw.run("shear_test", device=DEVICE, n_threads=1, overrides=[f"scene.dx={dx!r}"]).scene_result
    return {"peak": r["peak_shear_stress"], "delta_s": r["softening_displacement"], "collapse": r["collapse_fraction"]}


@pytest.fixture(scope="module")
def levels():
    return {cells: _level(cells) for cells in (3, 6)}


@pytest.mark.parametrize("quantity", ["peak", "delta_s", "collapse"])
def test_shear_ladder_error_falls_from_3_to_6_cells(levels, quantity):
    ref = FINEST[quantity]
    e3 = abs(levels[3][quantity] / ref - 1.0)
    e6 = abs(levels[6][quantity] / ref - 1.0)
    assert e6 < e3, f"{quantity}: error {e3:.3g} at 3 cells, {e6:.3g} at 6 (finest {ref:.6g})"


def _pst_level(dx: float) -> dict:
    sc = load_scenario("pst_flat", PST_SCENE + [f"scene.dx={dx!r}"])
    r = cut_run(sc, 0.7, run_distance=sc.scene.length, free_run=0.5, device=DEVICE)
    s = r["summary"]
    assert s["damage_speed_mean_over"] == pytest.approx([0.7, 1.9])   # the benchmark's distance
    h = r["series"]                                  # a frame every 0.01 s; the collapse height is the last frame's
    assert len(h["time"]) == len(h["collapse_height"]) and h["time"][-1] == pytest.approx(r["t_end"])
    assert h["collapse_height"][-1] == s["collapse_height"]
    return {"propagated": r["propagated"], "speed": s.get("damage_speed_mean"), "touchdown": s.get("touchdown"),
            "collapse_height": s.get("collapse_height")}


@pytest.fixture(scope="module")
def pst_levels():
    return {cells: _pst_level(0.06 / cells) for cells in (3, 6)}


def test_pst_ladder_crack_runs_at_6_cells_not_at_3(pst_levels):
    assert not pst_levels[3]["propagated"] and pst_levels[6]["propagated"]


@pytest.mark.parametrize("quantity", ["speed", "touchdown", "collapse_height"])
def test_pst_ladder_error_falls_from_3_to_6_cells(pst_levels, quantity):
    ref = PST_FINEST[quantity]

    def error(v):                     # a crack that does not run has no speed or touchdown: 100 % wrong
        return 1.0 if v is None or not v == v else abs(v / ref - 1.0)

    e3, e6 = error(pst_levels[3][quantity]), error(pst_levels[6][quantity])
    assert e6 < e3, f"{quantity}: error {e3:.3g} at 3 cells, {e6:.3g} at 6 (finest {ref:.6g})"


# ----------------------------------------------------------------------------- the benchmark's bookkeeping
def _bench():
    import importlib.util
    import os

    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks", "convergence",
                        "error_vs_runtime_snow.py")
    spec = importlib.util.spec_from_file_location("error_vs_runtime_snow", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_narrowed_bracket_must_lie_on_the_full_searchs_grid():
    """A narrowed search ends in one of the full search's final brackets: [0.1, 0.7] m to 2 cm is a grid of
    0.6 / 32 = 0.01875 m, so 0.30625 and 0.34375 m (points 11 and 13) are allowed and 0.31 m is not."""
    e = _bench()
    assert e.grid_bracket(0.30625, 0.34375) == {"lo": 0.30625, "hi": 0.34375, "tol": 0.02}
    with pytest.raises(ValueError, match="lo = 0.31 m: not on the bisection grid"):
        e.grid_bracket(0.31, 0.34375)
    with pytest.raises(ValueError, match="hi = 0.75 m"):
        e.grid_bracket(0.1, 0.75)
    with pytest.raises(ValueError, match="need lo < hi"):
        e.grid_bracket(0.34375, 0.30625)


def test_a_levels_base_run_and_critical_cut_merge_in_either_order():
    e = _bench()
    base = {"dx": 0.0025, "precision": "float32", "level": 3, "note": "base run only (critical cut not bisected)",
            "critical_cut": float("nan"), "speed": 22.0, "touchdown": 0.74, "collapse_height": 0.007,
            "wall_time_s": 8000.0, "steps": 130000, "n_particles": 591360, "git_commit": "a"}
    cut = {"dx": 0.0025, "precision": "float32", "level": 3, "part": "critical_cut", "critical_cut": 0.315625,
           "critical_cut_bracket": [0.30625, 0.325], "bracketed": True, "critical_cut_note": "", "trials": [{}],
           "critical_cut_wall_s": 3000.0, "critical_cut_steps": 100000, "bisection": {"lo": 0.30625},
           "speed": float("nan"), "wall_time_s": 3000.0, "steps": 100000, "n_particles": 591360, "git_commit": "b"}
    for merged in (e.merge_pst_parts(cut, base), e.merge_pst_parts({**base, "part": "base_run"}, cut)):
        assert merged["part"] == "both" and merged["critical_cut"] == 0.315625 and merged["speed"] == 22.0
        assert merged["wall_time_s"] == 11000.0 and merged["steps"] == 230000
        assert merged["git_commit"] == "b" and merged["git_commit_base_run"] == "a"
    assert e.merge_pst_parts(cut, None)["part"] == "critical_cut"
    assert e.merge_pst_parts({**base, "part": "base_run"}, None)["part"] == "base_run"


def test_time_to_an_error_along_the_ladder():
    e = _bench()
    walls = [10.0, 100.0, 1000.0, 10000.0]
    # log-log between the levels that bracket 5 %: 10 % at 100 s, 2.5 % at 1000 s -> half way in log, 316 s
    r = e.time_to([0.4, 0.1, 0.025, 0.0], walls, 0.05)
    assert r["status"] == "interpolated" and r["wall_time_s"] == pytest.approx(1000.0 ** 0.5 * 10.0)
    assert e.time_to([0.01, 0.005, 0.001, 0.0], walls, 0.05)["status"] == "already at the coarsest"
    # a critical cut in the same bracket from the third level on: met there, not only at the reference level
    r = e.time_to([float("nan"), 0.056, 0.0, 0.0], walls, 0.01)
    assert r == {"status": "met where the value first equals the finest's", "wall_time_s": 1000.0}
    assert e.time_to([0.3, 0.2, 0.1, 0.0], walls, 0.01) == {"status": "at the finest (the reference)",
                                                            "wall_time_s": 10000.0}
    assert e.time_to([0.3, 0.2, 0.1], walls[:3], 0.01)["status"] == "not reached"
