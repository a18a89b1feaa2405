"""docs/results.md shows a committed critical-cut case in the keys the loader reads today: a case recorded with
the older negative slope angle (the cut from the downslope end) is shown as the positive angle with
``saw.cut_from = 'downslope'``, and the loader takes those overrides for the same column."""

from __future__ import annotations

import json
import os

import pytest

from mpm_warp.errors import MPMError
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.pst.params import upgrade_table
from mpm_warp.studies.report.snow_runs import _in_todays_keys, _weac_key

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LADDER = ["scene.length=2.2", "scene.slab_thickness=0.3", "scene.weak_layer_thickness=0.06",
          "scene.substratum_thickness=0.06", "scene.margin=0.05", "scene.dx=0.01"]


def test_an_older_negative_slope_is_shown_as_the_cut_from_the_downslope_end():
    old = {"overrides": [*LADDER, "scene.slope_angle=-30.0"], "slope_angle": -30.0}
    slope, end, overrides, was_older = _in_todays_keys(old)
    assert (slope, end, was_older) == (30.0, "downslope", True)
    assert overrides == [*LADDER, "scene.slope_angle=30", "scene.saw.cut_from='downslope'"]
    assert _weac_key(old) == "downslope_30"
    new = {"overrides": [*LADDER, "scene.saw.cut_from='downslope'"], "slope_angle": 30.0}
    assert _in_todays_keys(new) == (30.0, "downslope", new["overrides"], False)
    assert _weac_key(new) == "downslope_30"


def test_the_loader_reads_the_shown_overrides_and_refuses_the_recorded_ones():
    with open(os.path.join(ROOT, "benchmarks/snow/results/snow_critical_cut.json")) as fh:
        case = json.load(fh)["cases"]["ladder_slope_cut_downslope_end"]
    _, _, overrides, _ = _in_todays_keys(case)
    p = load_scenario(case["scene"], overrides + ["time.end=0.2"]).scene
    assert (p.slope_angle, p.saw.cut_from, p.cut_at_origin) == (30.0, "downslope", False)
    if any(o.startswith("scene.slope_angle=-") for o in case["overrides"]):
        # as recorded, today's loader reads another column: pst_slope.toml names cut_from = "upslope", and the
        # negative angle only mirrors the column (the saw then starts at its upslope end)
        q = load_scenario(case["scene"], case["overrides"] + ["time.end=0.2"]).scene
        assert (q.slope_angle, q.saw.cut_from) == (-30.0, "upslope")
        with pytest.raises(MPMError, match="slope_angle"):     # without a cut_from the loader refuses it
            upgrade_table({"slope_angle": -30.0, "saw": {"speed": 1.0}})
