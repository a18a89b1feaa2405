"""A PST from a CAAML snow profile (scenes/pst/from_profile.py, the ready scene pst_profile)."""

import math
import os
import re

import matplotlib.image as mpimg
import pytest

import mpm_warp as mw
from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument, MPMError
from mpm_warp.loader import resolved_scenario, scenario_from_dict
from mpm_warp.scenes import pst
from mpm_warp.scenes.density_laws import bergfeld_modulus
from mpm_warp.scenes.profile import example_path
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.scenes.weac_reference import critical_cut

COS35 = math.cos(math.radians(35.0))


def test_the_example_profile_gives_the_pst_its_snowpack():
    sc = mw.load_scenario("pst_profile")
    p = sc.scene
    # the profile's slope, its PST record's column, its layers above the surface hoar 48-50 cm down (vertical)
    assert p.slope_angle == 35.0 and p.length == 1.0
    top, wind = p.slab_stack()
    assert (top.density, wind.density) == pytest.approx((81.0, 230.0))
    assert top.thickness == pytest.approx(0.10 * COS35) and wind.thickness == pytest.approx(0.38 * COS35)
    assert top.modulus == bergfeld_modulus(81.0) and "PP F" in top.name and "measured" in wind.name
    assert p.weak_layer_thickness == pytest.approx(0.02 * COS35)
    assert p.weak_layer.density == 150.0                 # buried surface hoar: not measured, from the file
    (sub,) = p.substratum_stack()
    assert sub.thickness == pytest.approx(0.15) and sub.density == pytest.approx(300.0)
    assert len(p.profile.sha256) == 64
    assert p.profile.weak_layer.startswith(
        "slab 48 cm (2 layers), weak layer 2 cm (the profile layer's own (SH, 2 cm))")
    assert p.profile.weak_layer.endswith("in layer 2 (depth 0.48-0.5 m): SH F")
    # the layers load the weak layer: sum rho g h cos(slope)
    assert p.sigma_n == pytest.approx(9.81 * COS35 * COS35 * (81.0 * 0.10 + 230.0 * 0.38), rel=1e-9)
    assert [b.name for b in sc.blocks] == ["substratum", "weak_layer", "slab_2", "slab_1"]


def test_a_stored_run_does_not_read_the_profile_again(monkeypatch):
    sc = mw.load_scenario("pst_profile")
    stored = sc.to_dict()

    def gone(*a, **k):
        raise AssertionError("the profile was read again")
    monkeypatch.setattr(mw.scenes.profile, "read_profile", gone)
    assert resolved_scenario(stored) == sc


def _raw(**profile):
    return {"name": "p", "time": {"end": 0.2, "frame_interval": 0.1},
            "scene": {"kind": "pst", "dx": 0.005, "profile": {"file": str(example_path()), **profile}}}


@pytest.mark.parametrize("profile, extra, needle", [
    ({"weak_layer_depth": 1.5}, {}, "scene.profile.weak_layer_depth = 1.5 is invalid: expected a depth in (0, 1.2) m"),
    ({"weak_layer_index": 9}, {}, "weak layer index = 9 is invalid: expected an integer in [1, 5]"),
    ({"weak_layer_thickness": 0.9}, {}, "scene.profile.weak_layer_thickness = 0.9 is invalid: expected a number in "
                                        "[0, 0.5]"),
    ({"weak_layer_depth": 0.49}, {"slab_thickness": 0.4}, "scene.slab_thickness = 0.4 is invalid: expected left out"),
    ({"weak_layer_depth": 0.49, "thickness": "sideways"}, {}, "scene.profile.thickness"),
    ({"weak_layer_depth": 0.49, "layers": 3}, {}, "scene.profile.layers = 3 is invalid"),
])
def test_bad_profile_choices_are_refused_in_one_line(profile, extra, needle):
    raw = _raw(**profile)
    raw["scene"].update(extra)
    with pytest.raises(InvalidArgument) as e:
        scenario_from_dict(raw)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_a_missing_profile_is_refused_naming_it(tmp_path):
    raw = _raw(weak_layer_depth=0.49)
    raw["scene"]["profile"]["file"] = str(tmp_path / "no_such_pit.caaml")
    with pytest.raises(MPMError, match="no_such_pit.caaml"):
        scenario_from_dict(raw)


@pytest.mark.slow
def test_the_profile_runs_to_a_picture_and_a_summary_in_one_command(tmp_path, capsys):
    out = tmp_path / "pit.h5"
    argv = ["run", "pst_profile", "--out", str(out), "--plot", "--quiet", "--set", "scene.length=0.4",
            "--set", "time.end=0.06", "--set", "time.frame_interval=0.02"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "field: PST 40/40" in text and "down 48 cm" in text        # the cut, the column, the depth as measured
    # weac's critical cut of this column, as the summary prints it, is weac's answer for the profile's column
    # (0.261 m: its slope-normal layer thicknesses, h cos 35 deg, and the weak layer's w_f of 0.08 J/m^2)
    sc = mw.load_scenario("pst_profile", ["scene.length=0.4"])
    want = critical_cut(static_column(sc.scene), sc.scene.weak_layer.w_f)
    got = re.search(r"weac 2\.6\.\d+: critical cut (\d\.\d{3}) m", text)
    assert got and float(got.group(1)) == pytest.approx(want, abs=5e-4) and want == pytest.approx(0.261, abs=2e-3)
    # the four pictures, and the PST picture shows the column (10.5 % of its pixels drawn)
    pictures = sorted(os.path.basename(line) for line in text.splitlines() if line.endswith(".png"))
    assert pictures == ["energy.png", "front.png", "markers.png", "pst.png"]
    png = [line for line in text.splitlines() if line.endswith("pst.png")][0]
    rgb = mpimg.imread(png)[..., :3]
    assert (rgb.min(axis=2) < 0.95).mean() > 0.08
    assert main(["profile", str(example_path())]) == 0
    assert "PST 32/100 (End) down 48 cm" in capsys.readouterr().out


def test_from_python_a_profile_is_a_scene_table():
    table = pst.expand_profile({"kind": "pst", "profile": {"file": str(example_path()), "weak_layer_index": 2}})
    assert len(table["slab_layers"]) == 2 and table["slope_angle"] == 35.0
    assert pst.expand_profile({"kind": "pst"}) == {"kind": "pst"}         # no profile: unchanged


def test_a_field_pst_read_backwards_gives_the_fracture_energy_that_reproduces_its_cut(capsys):
    """The profile's PST 32/100: weac's G at 32 cm is the fracture energy, and weac's critical cut with that
    G_c is 32 cm again (the round trip closes to the root finder's tolerance); the CLI prints it."""
    from mpm_warp.field import field_case
    from mpm_warp.scenes.profile import read_profile
    from mpm_warp.scenes.pst.static import static_column
    from mpm_warp.scenes.weac_reference import critical_cut_search

    prof = read_profile(example_path())
    case = field_case(prof, prof.pst_tests[0], calibrate=False)
    wf, p = case.fracture_energy, case.params
    assert p.saw.cut_length == 0.32 and p.length == 1.0 and p.slope_angle == 35.0
    assert wf.G == pytest.approx(wf.G_I + wf.G_II, rel=1e-12) and wf.value == wf.G
    assert wf.G == pytest.approx(0.0778, abs=5e-4)  # the surface hoar (2 cm, E 1 MPa) under a stiff wind slab
    assert critical_cut_search(static_column(p), wf.G).value == pytest.approx(0.32, abs=1e-9)
    assert main(["profile", example_path()]) == 0
    assert f"the weak layer's fracture energy this test implies: {wf.G:.3g} J/m^2" in capsys.readouterr().out
