"""Layered slabs, the field's column geometry and the calibration stored with the scenario (docs/model.md §8)."""

import dataclasses
import math

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument, ScenarioError
from mpm_warp.loader import load_scenario, resolved_scenario, scenario_from_dict
from mpm_warp.model import Model
from mpm_warp.scenes import pst
from mpm_warp.scenes.density_laws import bergfeld_modulus
from mpm_warp.scenes.pst.params import upgrade_table
from mpm_warp.scenes.snow import Slab
from mpm_warp.scenes.snowpack import SnowLayer, equivalent_slab, stack_normal_stress

G = 9.81
#: three slab layers, soft on top (top to bottom: 10 cm each)
SOFT_ON_TOP = (SnowLayer(0.1, 150.0, 1e6), SnowLayer(0.1, 250.0, 5e6), SnowLayer(0.1, 300.0, 1e7))


def small(**kw) -> pst.PSTParams:
    base = dict(dx=0.01, length=0.6, weak_layer_thickness=0.04, substratum_thickness=0.05, saw=pst.Saw(cut_length=0.0))
    return pst.PSTParams(**{**base, **kw})


def test_bergfeld_modulus_is_the_law_weac_uses():
    # 6.5e3 MPa (rho / 916.7)^4.4 (Bergfeld et al. 2023): 21.4 MPa at 250 kg/m^3, as weac's own function
    from weac.tools import bergfeld

    for rho in (120.0, 250.0, 400.0):
        assert bergfeld_modulus(rho) == pytest.approx(1e6 * bergfeld(rho), rel=1e-12)
    assert bergfeld_modulus(250.0) == pytest.approx(21.38e6, rel=1e-3)
    layer = SnowLayer(0.2, 200.0)                     # E omitted: from the density
    assert layer.modulus == bergfeld_modulus(200.0) and SnowLayer(0.2, 200.0, E=3e6).modulus == 3e6


def test_equivalent_slab_of_a_laminate():
    # one layer is itself; two equal layers are one layer of the sum
    one = SnowLayer(0.3, 250.0, 5e6, 0.3)
    assert equivalent_slab((one,)) == one.slab()
    two = equivalent_slab((SnowLayer(0.15, 250.0, 5e6, 0.3),) * 2)
    assert two.E == pytest.approx(5e6, rel=1e-12) and two.density == pytest.approx(250.0, rel=1e-12)
    # a stiff half over a soft half (E 2E0 over E0, h each): neutral axis at 5h/6 ... closed form D = 11/8 E0 h^3 / ...
    h, E0 = 0.1, 1e6
    lam = equivalent_slab((SnowLayer(h, 200.0, 2 * E0), SnowLayer(h, 200.0, E0)))
    zn = (2 * E0 * h * 0.5 * h + E0 * h * 1.5 * h) / (3 * E0 * h)         # 5h/6 from the top
    D = 2 * E0 * (h**3 / 12 + h * (0.5 * h - zn) ** 2) + E0 * (h**3 / 12 + h * (1.5 * h - zn) ** 2)
    assert lam.E == pytest.approx(12 * D / (2 * h) ** 3, rel=1e-12)
    assert lam.E == pytest.approx(1.375 * E0, rel=1e-12)                   # = 11/8 E0: between E0 and 2 E0


def test_layered_slab_builds_one_block_per_layer_and_loads_the_layer():
    p = small(slab_layers=SOFT_ON_TOP)
    sc = pst.build(p, mw.TimeControl(end=0.1, frame_interval=0.05))
    names = [b.name for b in sc.blocks]
    assert names == ["substratum", "weak_layer", "slab_3", "slab_2", "slab_1"]          # bottom to top
    assert [sc.materials[f"slab_{k}"].E for k in (1, 2, 3)] == [1e6, 5e6, 1e7]
    top = {b.name: b for b in sc.blocks}
    assert top["slab_1"].hi[1] == pytest.approx(0.05 + 0.04 + 0.3) and p.slab_depth == pytest.approx(0.3)
    assert p.sigma_n == pytest.approx(G * 0.1 * (150 + 250 + 300), rel=1e-12)
    assert p.sigma_n == stack_normal_stress(SOFT_ON_TOP)
    # the weak layer is calibrated under the layered load: the same as a homogeneous slab of its mean density
    mean = dataclasses.replace(small(), slab=Slab(5e6, 0.3, 700.0 / 3.0), slab_thickness=0.3)
    assert p.calibrated().sigma_n == pytest.approx(mean.calibrated().sigma_n, rel=1e-12)
    assert p.calibrated().p_bond == pytest.approx(mean.calibrated().p_bond, rel=1e-9)
    assert p.calibrated().xi == pytest.approx(mean.calibrated().xi, rel=1e-9)


@pytest.mark.slow
def test_layered_slab_settles_to_its_overburden():
    # at rest every layer carries the weight above it: sigma_yy at a layer's mid-height is -(sum rho g h above +
    # half its own); a 0.6 m column, the middle 0.2 m (away from the free ends)
    p = small(slab_layers=SOFT_ON_TOP)
    sc = pst.build(p, mw.TimeControl(end=0.1, frame_interval=0.1), mw.Output(fields=("x", "stress")))
    sim = mw.Simulation(sc, device="cpu")
    sim.step_to(p.settle.duration)
    x = sim.state.x.numpy()
    stress = sim.particle_field("stress")
    want = {"slab_1": 150 * 0.05, "slab_2": 150 * 0.1 + 250 * 0.05, "slab_3": 150 * 0.1 + 250 * 0.1 + 300 * 0.05,
            "weak_layer": 70.0 + 150.0 * 0.02}
    for name, load in want.items():
        g = sim.group(name)
        mid = np.abs(x[g.start:g.end, 0] - 0.3) < 0.1
        syy = float(stress[g.start:g.end][mid, 1, 1].mean())
        assert syy == pytest.approx(-G * load, rel=0.05), name


def test_layers_replace_the_homogeneous_slab_and_refuse_it_beside_them():
    with pytest.raises(InvalidArgument, match=r"scene.slab_thickness = 0.4 .*left out when scene.slab_layers"):
        small(slab_layers=SOFT_ON_TOP, slab_thickness=0.4).validate()
    with pytest.raises(InvalidArgument, match=r"scene.slab_layers\[1\].thickness = 0"):
        small(slab_layers=(SnowLayer(0.1), SnowLayer(0.0))).validate()
    with pytest.raises(InvalidArgument, match=r"scene.substratum_layers\[0\].density"):
        small(substratum_layers=(SnowLayer(0.1, -5.0),)).validate()


def test_layered_toml_round_trips_through_the_run_file_without_calibrating_again(monkeypatch):
    raw = {"name": "layered", "time": {"end": 0.2, "frame_interval": 0.1},
           "scene": {"kind": "pst", "dx": 0.01, "length": 0.6, "weak_layer_thickness": 0.04,
                     "substratum_thickness": 0.05, "saw": {"cut_length": 0.2, "cut_from": "downslope"},
                     "slab_layers": [{"thickness": 0.12, "density": 180.0},
                                     {"thickness": 0.18, "density": 260.0, "E": 6e6, "name": "wind slab"}]}}
    sc = scenario_from_dict(raw)
    assert sc.scene.slab_layers[0].modulus == bergfeld_modulus(180.0) and sc.scene.slab_layers[1].name == "wind slab"
    stored = sc.to_dict()
    assert stored["calibration"]["weak_layer"]["h_c"] == sc.calibration["weak_layer"]["h_c"]

    def no_calibration(*a, **k):
        raise AssertionError("the calibration ran again")
    monkeypatch.setattr(mw.scenes.weak_layer.params, "weak_layer_material", no_calibration)
    mw.scenes.weak_layer.params._calibrate.cache_clear()
    back = resolved_scenario(stored)
    assert back == sc and back.calibration == sc.calibration
    with pytest.raises(ScenarioError, match=r"\[calibration\] is written by a scene's builder"):
        scenario_from_dict({**raw, "calibration": {}})


@pytest.mark.parametrize("end, slope, want", [("left", 0.0, "upslope"), ("right", 0.0, "downslope"),
                                              ("left", 30.0, "upslope"), ("right", -30.0, "upslope"),
                                              ("left", -30.0, "downslope")])
def test_older_left_right_saw_ends_name_the_same_end(end, slope, want):
    t = upgrade_table({"slope_angle": slope, "saw": {"from_end": end}})
    assert t["saw"] == {"cut_from": want}
    p = pst.PSTParams(slope_angle=slope, saw=pst.Saw(cut_from=want))
    assert p.cut_at_origin == (end == "left")


def test_a_negative_slope_without_the_saws_end_is_refused_in_files():
    """A negative angle once named the saw's end (from the downslope end); a file must now say which end."""
    with pytest.raises(InvalidArgument, match=r"scene.slope_angle = -30.0 .*cut_from = 'upslope' \| 'downslope'"):
        upgrade_table({"slope_angle": -30.0, "saw": {"speed": 1.0}})
    assert upgrade_table({"slope_angle": -30.0, "saw": {"cut_from": "downslope"}})["saw"] == {"cut_from": "downslope"}


def test_cut_from_names_the_physical_end_on_either_slope():
    for slope, origin_is_up in ((30.0, True), (-30.0, False), (0.0, True)):
        up = pst.PSTParams(slope_angle=slope, saw=pst.Saw(cut_from="upslope"))
        # x = 0 is upslope when the downslope gravity component, g sin(slope), points to +x
        assert up.cut_at_origin == origin_is_up
        assert up.distance_from_cut_end(0.0) == (0.0 if origin_is_up else up.length)


def test_vertical_column_ends_lean_upslope():
    th = 35.0
    p = small(slope_angle=th, column_ends="vertical", slab_thickness=0.2)
    sc = pst.build(p, mw.TimeControl(end=0.1, frame_interval=0.05))
    model = Model(sc, "cpu")
    x = np.concatenate([xb for _, xb in model._seed])
    t = math.tan(math.radians(th))
    y_wl = 0.05 + 0.02
    s = x[:, 0] + t * (x[:, 1] - y_wl)                   # distance along the slope from the face at y_wl
    assert s.min() >= 0.0 and s.max() <= 0.6
    # the faces are filled: lattice points within one particle spacing of both planes
    assert s.min() < 0.01 and s.max() > 0.59
    top = x[:, 1] > x[:, 1].max() - 0.005
    assert x[top, 0].min() == pytest.approx(-t * (0.29 - y_wl), abs=0.01)   # the top leans upslope (to -x)
    wl = model.groups[0]
    assert wl.name == "weak_layer" and wl.count == len(wl.columns)
    with pytest.raises(InvalidArgument, match="column_ends"):
        small(column_ends="plumb").validate()


def test_ready_scenes_keep_slope_normal_ends_and_a_homogeneous_slab():
    for name in ("pst_demo", "pst_flat", "pst_slope"):
        sc = load_scenario(name)
        assert sc.scene.column_ends == "slope_normal" and not sc.scene.layered
        assert [b.name for b in sc.blocks] == ["substratum", "weak_layer", "slab"]
        assert sc.scene.saw.cut_from == "upslope"
