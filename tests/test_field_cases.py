"""Real SnowPilot pits as PST columns (mpm_warp.field): every record runs or is refused in one line in field terms.

The fixtures (tests/data/snowpilot/, provenance in its README) are real exports, one per way a record can fail.
"""

from __future__ import annotations

import dataclasses
import os

import pytest

from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.field import FieldCase, FieldRefusal, field_cases, implied_fracture_energy
from mpm_warp.field.plain_words import INTERNAL_NAMES, in_field_terms
from mpm_warp.scenes.profile import read_profile
from mpm_warp.scenes.profile.layer_density import estimate_density
from mpm_warp.scenes.weak_layer.calibration import weak_layer_material

PITS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "snowpilot")


def pit(name: str) -> str:
    return os.path.join(PITS, f"{name}-caaml.xml")


#: (pit, field line, the reason class or "case", a fragment of its line)
RECORDS = [
    ("snowpits-37440", "PST 38/100 (End) down 80 cm", "case", "w_f 0.764 J/m^2 (weac's G at the recorded cut)"),
    ("snowpits-37440", "PST 75/100 (SF) down 14 cm", "case", "the cut is 75% of the column: propagation at a long cut"),
    ("snowpits-24636", "PST 98/100 (End) down 81 cm", "case", "weak layer 1 cm (the profile layer's own (SH, 1 cm))"),
    ("snowpits-45545", "PST 100/100 (X) down 97 cm", "no outcome", "no outcome recorded (X: End, SF or Arr are read)"),
    ("snowpits-18264", "PST 100/100 (End) down 51 cm", "cut at column",
     "the cut is 100% of the column: the saw reached the end"),
    ("snowpits-20632", "PST 0/90 (End) down 80 cm", "no cut", "a cut of 0 cm: no critical cut recorded"),
    ("snowpits-17459", "PST 32/100 (SF) down 33 cm", "no slope", "no slope angle recorded"),
    ("snowpits-19416", "PST 65/145 (End) down 145 cm", "slab layer without density",
     "the slab layer at 19-61 cm (no grain, hardness not recorded) has no density (neither a hand hardness nor a "
     "grain form recorded)"),
    ("mkc_TESTPIT-23-Feb", "PST 20/60 (SF) down 20 cm", "slab density range",
     "has a measured density of 20 kg/m^3, outside the 50-600 kg/m^3 of seasonal dry snow: check the entry"),
    ("snowpits-48191", "PST 44/100 (End) down 100 cm", "failure depth",
     "the failure depth 100 cm is at or below the bottom of the described layers (100 cm)"),
    ("snowpits-18285", "PST 30/100 (End) down 123 cm", "column shorter than slab",
     "the column (100 cm) is not longer than the slab is deep (110 cm, normal to the slope)"),
    ("snowpits-17833", "PST 10/100 (Arr) down 20 cm", "fracture energy",
     "a weak-layer fracture energy of 0.0153 J/m^2 is below the least the model's weak layer dissipates"),
]


def _find(name, test):
    return next(r for r in field_cases(pit(name)) if r.test == test)


@pytest.mark.parametrize("name, test, kind, fragment", RECORDS)
def test_a_real_record_runs_or_is_refused_in_one_field_line(name, test, kind, fragment):
    r = _find(name, test)
    line = r.line()
    assert line.startswith(f"{name}-caaml.xml: {test}: ") and "\n" not in line and fragment in line
    if kind == "case":
        assert isinstance(r, FieldCase) and r.params.validate("scene") is r.params
    else:
        assert isinstance(r, FieldRefusal) and r.reason == kind
    assert not any(n in line for n in ("kappa_s", "material[0]", "margin"))


def test_an_unreadable_pit_is_one_line_naming_the_layer():
    (r,) = field_cases(pit("snowpits-30929"))
    assert isinstance(r, FieldRefusal) and r.reason == "unreadable" and r.test == ""
    assert "layer 5 (depth 1.054-1.09 m)" in r.line() and "an overlap of 0.096 m" in r.line()


def test_the_slab_ends_at_the_failure_and_the_weak_layer_is_thin():
    """The issue's pit: PST 38/100 (End) down 80 cm in a 30 cm depth-hoar layer with measured densities."""
    case = _find("snowpits-37440", "PST 38/100 (End) down 80 cm")
    p = case.params
    cos = 0.882947592858927                                             # cos 28 deg
    assert p.slab_depth == pytest.approx(0.80 * cos, rel=1e-9)          # not 1.1 m: the slab ends at 80 cm
    assert p.weak_layer_thickness == pytest.approx(0.03 * cos, rel=1e-9)
    assert p.dx == pytest.approx(p.weak_layer_thickness / 4) and p.margin >= 2 * p.dx
    assert [round(ly.density) for ly in p.slab_layers] == [154, 194, 274, 326]    # all measured
    assert p.column_ends == "vertical" and p.length == 1.0 and p.saw.cut_length == 0.38    # a US pit


def test_the_issue_pit_builds_its_scene_with_calibration_and_no_overflow():
    from mpm_warp.loader import scenario_from_dict

    raw = {"name": "pit", "time": {"end": 0.1, "frame_interval": 0.05},
           "scene": {"kind": "pst", "slab_fracture": True,
                     "profile": {"file": pit("snowpits-37440"), "weak_layer_depth": 0.8}}}
    sc = scenario_from_dict(raw)
    wl = sc.calibration["weak_layer"]
    assert sc.scene.weak_layer_thickness == pytest.approx(0.03 * 0.882947592858927)
    assert wl["w_f"] == pytest.approx(0.79, rel=1.1e-2)                 # the default, calibrated to 1 %


def test_a_long_cut_record_gives_no_fracture_energy_and_a_short_one_out_of_range_neither():
    case = _find("snowpits-24636", "PST 98/100 (End) down 81 cm")
    wf = case.fracture_energy
    assert wf.value is None and wf.G is None and "the cut is 98% of the column" in wf.reason
    assert case.params.weak_layer.w_f == 0.79                          # the default, said in the line
    thin = _find("snowpits-37440", "PST 75/100 (SF) down 14 cm").params
    low = implied_fracture_energy(thin, 0.01)                          # 1 cm under 14 cm of snow
    assert low.value is None and low.G == pytest.approx(8.74e-4, rel=1e-2)
    assert "outside the 0.01-10 J/m^2 of weak layers" in low.reason


@pytest.mark.parametrize("w_f, field", [(1e-4, "w_f"), (1e5, "kappa_s")])
def test_the_calibration_refuses_an_unreachable_fracture_energy_without_overflow(w_f, field):
    """Far below the least the layer dissipates under 0.2 m of snow (0.039 J/m^2), and far above what its bond can
    hold: one refusal each, where the secant once overflowed ``math.exp``."""
    with pytest.raises(InvalidArgument) as e:
        weak_layer_material(E=1e6, nu=0.3, density=150.0, D_wl=0.03, slab_density=150.0, slab_thickness=0.2,
                            slope_angle=30.0, tau_p=1000.0, w_f=w_f)
    assert e.value.field == field
    if field == "w_f":
        assert e.value.reached == pytest.approx(0.0391, rel=1e-2)
    _, message = in_field_terms(e.value, None)
    assert not any(n in message for n in INTERNAL_NAMES) and "fracture energy" in message


def test_the_model_refusals_read_in_field_terms():
    """Each refusal the column build can meet, turned into field words, names no internal parameter."""
    case = _find("snowpits-37440", "PST 38/100 (End) down 80 cm")
    for e in (InvalidArgument("kappa_s", 1.67e29, "a bond that breaks in the shear test (it never did)"),
              InvalidArgument("tau_p", 1000.0, "a strength above that of the debonded skeleton under sigma_n = 9 Pa"),
              InvalidArgument("tau_p", 1000.0, "a strength at which the layer fails in shear (here it yields in "
                                               "compaction ...)"),
              InvalidArgument("p_bond", 1.0, "a strength at which the intact layer carries the slab"),
              InvalidArgument("scene.dx", 0.01, "a spacing whose crack band ..."),
              InvalidArgument("scene.margin", 0.05, "a number in [0.112, inf)"),
              InvalidArgument("material[0].kappa_s", 0.0, "a number > 0")):
        reason, message = in_field_terms(e, case.params)
        assert reason and message and not any(n in message for n in INTERNAL_NAMES), (e, message)


def test_a_heavy_slab_gets_the_least_strength_that_carries_it():
    case = _find("snowpits-18874", "PST 45/100 (End) down 100 cm")
    assert case.params.weak_layer.tau_p == 1140.0                   # 1.1 x 1036 Pa, to 10 Pa
    assert any("1.1 x the least strength that carries it (1036 Pa)" in n for n in case.notes)


def test_missing_hardness_or_grain_gives_a_flagged_fallback_density():
    rho, src = estimate_density(None, "FC", None)                   # 112 + 46 h at the middle of F- .. K-
    assert rho == pytest.approx(112 + 46 * (2 / 3 + 14 / 3) / 2) and src.startswith("fallback: no hand hardness")
    rho, src = estimate_density("4F", None, None)                   # the mean of the eight laws at h = 2
    assert rho == pytest.approx(172.05, abs=0.01) and src.startswith("fallback: no grain form recorded")
    assert estimate_density(None, None, None) == (None, "neither a hand hardness nor a grain form recorded")
    assert estimate_density("P", "MM", None)[0] is None


def test_the_profile_command_prints_every_record(capsys):
    assert main(["profile", pit("snowpits-45545"), "--no-calibration"]) == 0
    out = capsys.readouterr().out
    assert "PST 30/115 (End) down 97 cm: slab 97 cm (7 layers), weak layer 3 cm" in out
    assert "PST 100/100 (X) down 97 cm: not set up: no outcome recorded" in out


def test_snowpylot_reads_what_snowprofile_refuses():
    """A SnowPilot export with the country code "UT" (outside ISO 3166): snowprofile refuses the whole file, the
    reader behind read_profile (snowpylot for SnowPilot exports) reads it and its PST becomes a column; and a pit
    whose other test is X keeps its first test."""
    import logging

    import snowprofile.io as sp_io

    logging.disable(logging.CRITICAL)
    try:
        with pytest.raises(Exception, match="country"):
            sp_io.read_caaml6_xml(pit("snowpits-18413"))
    finally:
        logging.disable(logging.NOTSET)
    prof = read_profile(pit("snowpits-18413"))
    assert prof.country == "UT" and prof.slope_angle == 40.0
    (case,) = field_cases(pit("snowpits-18413"), calibrate=False)
    assert isinstance(case, FieldCase) and case.test == "PST 44/100 (End) down 93 cm"
    assert case.params.column_ends == "slope_normal"          # not the US or Canada: the European standard
    prof = read_profile(pit("snowpits-45545"))
    assert [t.propagation for t in prof.pst_tests] == ["End", "X"]


def test_empty_layer_lists_and_an_empty_profile_path_are_refused_in_one_line():
    from mpm_warp.loader import scenario_from_dict

    for key in ("slab_layers", "substratum_layers"):
        raw = {"name": "p", "time": {"end": 0.1, "frame_interval": 0.05}, "scene": {"kind": "pst", key: []}}
        with pytest.raises(InvalidArgument, match=rf"scene.{key} = \[\] is invalid: expected at least one layer"):
            scenario_from_dict(raw)
    raw = {"name": "p", "time": {"end": 0.1, "frame_interval": 0.05},
           "scene": {"kind": "pst", "profile": {"file": "", "weak_layer_depth": 0.48}}}
    with pytest.raises(InvalidArgument, match=r"scene.profile.file = '' is invalid: expected a path to a CAAML"):
        scenario_from_dict(raw)


def test_a_record_with_a_gap_in_its_slab_is_kept_apart_from_the_others():
    """Refusals are per record: the same pit's other PSTs still run (one record's problem stays its own)."""
    cases = field_cases(pit("snowpits-17833"))
    kinds = {r.test: (r.reason if isinstance(r, FieldRefusal) else "case") for r in cases}
    assert kinds["PST 10/100 (Arr) down 20 cm"] == "fracture energy"
    assert kinds["PST 100/100 (Arr) down 42 cm"] == "cut at column"
    assert dataclasses.is_dataclass(cases[0])


@pytest.mark.slow
def test_a_slab_of_1000_layers_runs_and_its_run_file_names_every_group(tmp_path):
    """A profile from a snow micro-penetrometer has hundreds of layers: 1,000 slab layers of 0.2 mm build, run and
    write a run file whose group id (uint16 past 256 groups) names each of the 1,002 groups."""
    import numpy as np

    import mpm_warp as mw
    from mpm_warp.scenes import pst
    from mpm_warp.scenes.snowpack import SnowLayer

    layers = tuple(SnowLayer(0.2 / 1000, 150.0 + 0.15 * i) for i in range(1000))
    p = pst.PSTParams(length=0.5, dx=0.01, weak_layer_thickness=0.04, substratum_thickness=0.04, slab_layers=layers,
                      saw=pst.Saw(cut_length=0.1))
    mw.run(pst.build(p, mw.TimeControl(end=0.002, frame_interval=0.002)), output=str(tmp_path / "l.h5"))
    run = mw.read_run(str(tmp_path / "l.h5"))
    g = run.static["group"]
    assert g.dtype == np.uint16 and len(run.attrs["groups"]) == 1002 and np.unique(g).size == 1002
    assert np.isfinite(run.frame(-1)["x"]).all()


def test_a_run_file_of_an_older_release_with_empty_layer_lists_still_reads_back():
    """Earlier releases stored ``slab_layers = []`` for a default slab: the refusal of an empty list is for what a
    user writes, never for a stored scenario (users' files stay readable)."""
    import mpm_warp as mw
    from mpm_warp.loader import resolved_scenario

    sc = mw.load_scenario("pst_demo")
    stored = sc.to_dict()
    stored["scene"] = {**stored["scene"], "slab_layers": [], "substratum_layers": []}
    assert resolved_scenario(stored).scene == sc.scene
