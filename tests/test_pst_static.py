"""weac's static answer beside a PST (scenes/pst/static.py): the same column in weac, its critical cut."""

import pytest

import mpm_warp as mw
from mpm_warp.scenes import pst
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.pst.static import static_column, weac_answer
from mpm_warp.scenes.snowpack import SnowLayer
from mpm_warp.scenes.weak_layer import stored_calibration

#: the ladder PST of the snow studies: pst_flat's snow on a 2.2 m column, 0.3 m slab, 6 cm weak layer
LADDER = ["scene.length=2.2", "scene.slab_thickness=0.3", "scene.weak_layer_thickness=0.06",
          "scene.substratum_thickness=0.06", "scene.dx=0.02"]


def test_the_ladder_pst_in_weac_is_a_direct_weac_call():
    sc = mw.load_scenario("pst_flat", LADDER)
    ans = weac_answer(sc.scene, stored_calibration(sc))
    # the same column written out by hand: slab 0.3 m of 250 kg/m^3 at 5 MPa, nu 0.3; weak layer 6 cm, 1 MPa, 0.3
    by_hand = wr.StaticColumn(slab=((0.3, 250.0, 5e6, 0.3),), weak_layer_thickness=0.06, weak_layer_E=1e6,
                              weak_layer_nu=0.3, length=2.2)
    assert static_column(sc.scene) == by_hand
    assert ans["critical_cut"] == pytest.approx(wr.critical_cut(by_hand, 0.79), rel=1e-6)
    assert round(ans["critical_cut"], 3) == 0.380                        # recorded from weac 3.3.1: 0.380 m too
    G = wr.energy_release_rate(by_hand, sc.scene.saw.cut_length)
    assert (ans["energy_release_rate"], ans["G_I"], ans["G_II"]) == pytest.approx(G, rel=1e-6)
    assert ans["G_c"] == 0.79 and ans["weac"].startswith("2.6")


def test_layers_slope_cut_end_and_column_ends_reach_weac():
    layers = (SnowLayer(0.1, 180.0), SnowLayer(0.2, 280.0, 8e6, 0.25))
    p = pst.PSTParams(length=2.2, weak_layer_thickness=0.06, slope_angle=35.0, column_ends="vertical",
                      saw=pst.Saw(cut_from="downslope"), slab_layers=layers)
    col = static_column(p)
    assert col.slab == ((0.1, 180.0, layers[0].modulus, 0.3), (0.2, 280.0, 8e6, 0.25))
    assert (col.slope_angle, col.cut_from, col.column_ends, col.length) == (35.0, "downslope", "vertical", 2.2)


def test_without_weac_the_answer_says_so_in_one_line(monkeypatch):
    monkeypatch.setattr("mpm_warp.scenes.pst.static.weac_unavailable", lambda: wr.NOT_INSTALLED)
    sc = mw.load_scenario("pst_flat", LADDER)
    ans = weac_answer(sc.scene, stored_calibration(sc))
    assert ans == {"weac": None, "note": wr.NOT_INSTALLED} and "\n" not in ans["note"]
    assert "pip install 'mpm-warp[weac]'" in ans["note"]
