"""The snow error-against-run-time ladders (issue 14): their two coarsest levels, in CI time.

``benchmarks/error_vs_runtime_snow.py`` halves dx over the shear test of SI Note 2 (3, 6, 12, 24 cells
across its 3 cm layer) and over a flat PST. Here the shear ladder's two coarsest levels run again
(the whole scene, as the benchmark runs it) and the error of each quantity against the ladder's finest
level must fall from 3 to 6 cells. The finest level's values are the benchmark's measurement
(``benchmarks/results/error_vs_runtime_snow.json``, 24 cells, float32, one thread, 2026-11-30: peak
932.6 Pa, softening slip 2.088 mm (the interior's bond), collapse 0.3055); the coarse values are
recomputed, so a change to the engine that breaks convergence fails here. (The softening slip is
read from frames 0.01 mm of push apart: its errors at 3 and 6 cells, 2.2 and 1.6 %, differ by about
1.4 frames.)

The PST ladder's two coarsest levels (2 and 1 cm: 3 and 6 cells across its 6 cm layer) run their base
run here, the one that measures the front speed, the touchdown and the collapse height (cut 0.7 m, the
crack run into the far end zone: :func:`mpm_warp.scenes.pst.cut_run`, as the benchmark's critical-cut
search runs it); the bisection of the critical cut (about 9 minutes for the two levels) stays in the
benchmark. At 3 cells the crack does not run at all: there a quantity of the running crack counts as
100 % wrong, and the ladder's finding (it runs at 6 cells, not at 3) is asserted too.
"""

import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.pst import cut_run

#: the shear ladder's finest level (24 cells across the layer): error_vs_runtime_snow.json
FINEST = {"peak": 932.5898344665492, "delta_s": 0.0020884051965618265, "collapse": 0.3054789884530086}


#: the PST ladder's scene (benchmarks/error_vs_runtime_snow.py PST_SCENE): production snow, 2.2 m column
PST_SCENE = ["scene.length=2.2", "scene.slab_thickness=0.3", "scene.weak_layer_thickness=0.06",
             "scene.substratum_thickness=0.06", "scene.margin=0.05"]
#: the PST ladder's finest level (12 cells, dx 5 mm): error_vs_runtime_snow.json
PST_FINEST = {"speed": 21.477440858616376, "touchdown": 0.727406727195973, "collapse_height": 0.00721748166642367}


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

    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks",
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
