"""The weak layer's along-slope scatter as a crack stopper (mpm_warp/field/arrest_scatter.py): the conditioned
spherical field by hand, the arrest probability against closed forms, and one column through weac."""

import math

import numpy as np
import pytest

from mpm_warp.field import arrest_scatter as A
from mpm_warp.scenes import pst
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.pst.static import static_column


def _beyond(g: float, cv: float = A.STRENGTH_CV) -> float:
    """P((1 + cv z)^2 > g) for one standard normal z, z > -1/cv: 1 - Phi((sqrt(g) - 1) / cv)."""
    return 0.5 * math.erfc((math.sqrt(g) - 1.0) / cv / math.sqrt(2.0))


def test_the_spherical_correlation_and_its_conditioning_by_hand():
    assert A.spherical_correlation([0.0, 0.15, 0.3, 0.6], 0.3) == pytest.approx([1.0, 0.3125, 0.0, 0.0])
    c = A.conditioned_covariance([0.15, 0.45, 0.75], start=0.0, xi=0.3)
    # a point half a length from the start keeps 1 - 0.3125^2 of its variance; beyond one length, all of it
    assert np.diag(c) == pytest.approx([1.0 - 0.3125**2, 1.0, 1.0])
    assert c[0, 1] == pytest.approx(0.0) and c[1, 2] == pytest.approx(0.0)
    assert A.FRAME_SIDE_M == pytest.approx(0.1581, abs=1e-4)             # a 250 cm^2 frame's side


def test_one_and_two_free_points_stop_the_crack_as_the_normal_law_says():
    n = 200_000
    p1 = A.arrest_probability([1.0], [1.2], start=0.0, xi=0.3, samples=n, seed=1)
    assert _beyond(1.2) == pytest.approx(0.2980, abs=1e-4)       # (sqrt(1.2) - 1) / 0.18 = 0.530 sd
    assert p1 == pytest.approx(_beyond(1.2), abs=4.0 * math.sqrt(0.3 * 0.7 / n))
    p2 = A.arrest_probability([1.0, 2.0], [1.2, 1.5], start=0.0, xi=0.3, samples=n, seed=2)
    both = 1.0 - (1.0 - _beyond(1.2)) * (1.0 - _beyond(1.5))
    assert p2 == pytest.approx(both, abs=4.0 * math.sqrt(both * (1.0 - both) / n))


def test_a_point_at_the_start_keeps_the_read_back_layer():
    # next to the start the layer is the one the recorded cut read back: G 1 % above it cannot be stopped there
    assert A.arrest_probability([1e-7], [1.01], start=0.0, xi=0.3, samples=10_000) == 0.0
    # and where G falls below the read-back value, the mean layer stops it every time
    assert A.arrest_probability([1e-7], [0.99], start=0.0, xi=0.3, samples=10_000) == 1.0


@pytest.mark.skipif(wr.weac_unavailable() is not None, reason="weac 2.6 is not installed")
def test_a_read_back_column_starts_at_its_cut_and_the_frame_scale_scatter_cannot_stop_it():
    p = pst.PSTParams(length=1.0, weak_layer_thickness=0.03, slope_angle=30.0, column_ends="vertical")
    col = static_column(p)
    cut = 0.3
    w_f = wr.energy_release_rate(col, cut)[0] * (1.0 - 1e-9)           # read back at the cut, as the batch does
    res = A.column_arrest(p, w_f, cut, xis=(0.3,), samples=2000)
    assert res["start"] == pytest.approx(cut)
    assert res["g_at_10cm"] > 1.5                                      # G grows fast past the cut
    assert res["p_arr"] == {0.3: 0.0}
    # read one frame's side / 16 apart, the same field stops some cracks: the bound is the spacing's, not snow's
    fine = A.column_arrest(p, w_f, cut, xis=(0.3,), grid=A.FRAME_SIDE_M / 16, samples=2000)
    assert fine["p_arr"][0.3] > 0.05
    # a fracture energy above G everywhere: no propagation, said in one line
    assert A.column_arrest(p, 1e6, cut)["why"].startswith("no propagation")


@pytest.mark.skipif(wr.weac_unavailable() is not None, reason="weac 2.6 is not installed")
def test_a_cut_where_weac_finds_no_touchdown_takes_the_free_slabs_g(monkeypatch):
    p = pst.PSTParams(length=1.0, weak_layer_thickness=0.03, slope_angle=30.0, column_ends="vertical")
    col, free = static_column(p), wr.energy_release_rate

    def no_touchdown(column, cut, touchdown=False):
        if touchdown:
            raise ValueError("f(a) and f(b) must have different signs")      # weac's calc_lC, as seen in the field
        return free(column, cut)

    monkeypatch.setattr(wr, "energy_release_rate", no_touchdown)
    x, g, unsolved = A.release_profile(col, 1.0, 0.3)
    assert unsolved == A.PROFILE_POINTS
    assert g[0] == pytest.approx(free(col, 0.3 + A.GRID_M)[0], rel=0.05)   # log-interpolated between solved cuts
