"""The field what-ifs (mpm_warp.field.studies): the switches' registry, the one before/after schema, the converter
of the earlier schemas and the committed results it converted, and the one renderer (mpm_warp.studies.report)."""

from __future__ import annotations

import glob
import json
import os
import re

import pytest

from mpm_warp.field.cases import FieldCase
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.studies.convert import convert, values
from mpm_warp.field.studies.slab_strength import weaker
from mpm_warp.field.studies.switches import SWITCHES, compliance_ratio
from mpm_warp.field.studies.what_if import COST_KEYS, SCHEMA, SIDE_KEYS, what_if_row
from mpm_warp.scenes.pst import PSTParams
from mpm_warp.scenes.snowpack import SnowLayer

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "benchmarks", "field", "results")


def test_each_protocol_switch_sets_one_field_and_its_values_are_checked():
    base = FieldProtocol().validate()
    for name, field, value in (("interface_closure", "interface_closure", True), ("rigid_base", "rigid_base", False),
                               ("pre_cut_share", "pre_cut_share", 0.0), ("cells_across", "cells_across", 6)):
        sw = SWITCHES[name]
        assert sw.field == field and sw.default == value and sw.check(value) is None
        proto = sw.protocol(base, value)
        assert getattr(proto, field) == value and getattr(base, field) == sw.baseline != value
        assert {k: v for k, v in proto.run_key().items() if k != field} == {
            k: v for k, v in base.run_key().items() if k != field}
    for name, bad in (("pre_cut_share", 0.95), ("cells_across", 2), ("weak_modulus", 1.0), ("slab_strength", 0.0),
                      ("faceted_strength", 1.5), ("interface_closure", 1)):
        assert SWITCHES[name].check(bad), name
    assert SWITCHES["weak_modulus"].baseline == 1.0 and SWITCHES["weak_modulus"].label(0.25) == "at 0.25 MPa"
    assert SWITCHES["rigid_base"].label(False) == "on the old snow"


def test_the_old_snow_is_as_compliant_as_the_weak_layer_in_the_default_column():
    # 15 cm of 5 MPa old snow against 3 cm of a 1 MPa weak layer, both nu = 0.3: (0.15 / 5) / (0.03 / 1) = 1
    assert compliance_ratio(PSTParams()) == pytest.approx(1.0, rel=1e-12)
    p = PSTParams(substratum=SnowLayer(0.3, 250.0, 2.5e6, 0.3), substratum_thickness=0.3)
    assert compliance_ratio(p) == pytest.approx(4.0, rel=1e-12)


def test_the_strength_switches_change_the_case_and_name_its_faceted_share():
    layers = (SnowLayer(0.1, 150.0, name="FCxr 4F"), SnowLayer(0.3, 250.0, name="RGsr 1F"))
    c = FieldCase("p.xml", "PST 1/2 (End) down 3 cm", "End", None, PSTParams(slab_layers=layers), None, None, ())
    half = SWITCHES["slab_strength"].change(c, 0.5, None)
    assert half.params == weaker(c, 0.5).params and half.params != c.params
    fac = SWITCHES["faceted_strength"].change(c, 0.5, None)
    assert fac.params == weaker(c, 1.0, 0.5).params
    assert SWITCHES["faceted_strength"].detail(c, fac, 0.5) == {"faceted_share": pytest.approx(0.25)}
    assert SWITCHES["slab_strength"].protocol(FieldProtocol(), 0.5) == FieldProtocol()    # the protocol unchanged


def test_a_row_has_the_same_keys_before_and_after():
    before = {"status": "ok", "predicted": "END", "runaway_cut": 0.3, "steps": 100, "wall_s": 5.0, "extra": 1}
    row = what_if_row({"id": "a", "test": "t", "observed": "SF"}, before, {"status": "refused", "error": "x"}, None,
                      {"cells": [4, 6]})
    assert set(row["before"]) == set(row["after"]) == {*SIDE_KEYS, "cost"}
    assert set(row["before"]["cost"]) == set(COST_KEYS)
    assert row["before"]["cost"]["steps"] == 100 and row["after"]["cost"]["steps"] is None
    assert row["after"]["status"] == "refused" and row["detail"] == {"cells": [4, 6]}


def _old_closure() -> dict:
    side = {"status": "ok", "predicted": "SF", "runaway_cut": None, "slab_fracture_at": 0.36, "particles": 13200,
            "steps": 47170, "wall_s": 42.7, "threads": 2, "workers": 1}
    return {"name": "field_closure", "per_class": 8, "seed": 0, "chosen": "1 drawn",
            "environment": {"git_commit": "c7881cada2f708b1bcb7e865f3009d3ce55febbf"},
            "cases": [{"id": "a-1-x", "closure_id": "a-0-y", "test": "t", "observed": "END", "w_f": 0.388,
                       "w_f_source": "read back", "setup": "s", "off": side, "on": {**side, "steps": 45390,
                                                                                     "error": None}}]}


def test_the_converter_keeps_every_value_and_the_provenance():
    old = _old_closure()
    new = convert(json.loads(json.dumps(old)))
    assert new["schema"] == SCHEMA and new["switch"] == {"name": "interface_closure", "value": True, "before": False}
    assert new["environment"] == old["environment"] and "converted" in new["schema_converted"]
    c = new["cases"][0]
    assert (c["id"], c["after_id"], c["observed"]) == ("a-1-x", "a-0-y", "END")
    assert c["before"]["w_f"] == 0.388
    assert (c["before"]["cost"]["steps"], c["after"]["cost"]["steps"]) == (47170, 45390)
    assert not values(old) - values(new)
    with pytest.raises(ValueError, match="converted already"):
        convert(new)
    old["cases"][0]["on"]["peak"] = 2.5             # a number the schema has no place for: refused, not dropped
    with pytest.raises(ValueError, match="lose"):
        convert(old)
    with pytest.raises(ValueError, match="not an earlier"):
        convert({"name": "field_far_end", "cases": []})
    old = {"name": "field_strength", "scale": 1.0, "faceted": 0.5, "per_class": 1, "environment": {}, "cases": []}
    assert convert(old)["switch"] == {"name": "faceted_strength", "value": 0.5, "before": 1.0}


def _what_if_results() -> list[str]:
    return [p for p in glob.glob(os.path.join(RESULTS, "**", "*.json"), recursive=True)
            if '"schema": "field what-if' in open(p).read()]


def test_the_committed_what_if_results_follow_the_one_schema():
    paths = _what_if_results()
    assert len(paths) == 9                        # closure, pre-cut, rigid base, grid, weak modulus, 4 strengths
    for p in paths:
        d = json.load(open(p))
        assert d["switch"]["name"] in SWITCHES and SWITCHES[d["switch"]["name"]].check(d["switch"]["value"]) is None
        assert re.fullmatch(r"[0-9a-f]{40}", d["environment"]["git_commit"])
        for c in d["cases"]:
            assert set(c["before"]) == set(c["after"]) == {*SIDE_KEYS, "cost"}, p
            assert c["observed"] in ("END", "SF", "ARR") and c["before"]["status"] == "ok"


def _result(cases: list) -> dict:
    return {"switch": {"name": "cells_across", "value": 6, "before": 4}, "chosen": "3 drawn", "environment": {},
            "cases": cases}


def _case(test, observed, a, b, cut_a, cut_b, status="ok"):
    def side(pred, cut, st="ok"):
        return {"status": st, "predicted": pred, "runaway_cut": cut, "slab_fracture_at": None, "error": None,
                "cost": {"particles": 1000, "steps": 100, "wall_s": 10.0, "threads": 1}}
    return {"test": test, "observed": observed, "before": side(a, cut_a), "after": side(b, cut_b, status),
            "detail": {"dx": [0.006, 0.004]}}


def test_one_renderer_renders_any_what_if_result():
    from mpm_warp.studies.report.field_what_if import change, render_what_if

    cases = [_case("a", "END", "END", "END", 0.20, 0.21), _case("b", "SF", "END", "SF", 0.30, 0.36),
             _case("c", "ARR", "END", None, 0.10, None, status="failed")]
    cases[2]["after"]["error"] = "SimulationError: it diverged; more"
    assert change(cases[0]) == pytest.approx(0.05) and change(cases[2]) is None
    out = render_what_if(_result(cases))
    text = "\n".join(out)
    assert "| `a` | END | END / END | 0.200 / 0.210 | +5.0 % |" in text
    checks = [ln for ln in out if ln.startswith("- **Check, ")]
    assert "at 4 cells and at 6 cells" in checks[0] and "**FAIL**" in checks[0] and "1 of 2" in checks[0]
    assert "`b` (SF): END -> SF" in checks[0]
    assert "**FAIL**" in checks[1] and "1 of 2, from +5.0 % to +20.0 %; apart: `b` +20.0 %" in checks[1]
    assert any(ln.startswith("- Not run at 6 cells (1): `c` (ARR): it diverged.") for ln in out)
    assert any("balanced accuracy at 4 cells 0.50 (recall END 1.00, SF 0.00); at 6 cells 1.00" in ln for ln in out)
    passing = render_what_if(_result(cases[:1]))
    assert sum("**pass**" in ln for ln in passing) == 2


def test_a_what_if_script_is_one_call_and_refuses_what_it_cannot_run(capsys):
    from mpm_warp.studies.field_what_if import what_if_main

    script = os.path.join(ROOT, "benchmarks", "field", "strength.py")
    for argv, why in ((["DIR", "--scale", "0.5", "--faceted", "0.5"], "--scale and --faceted: one what-if a run"),
                      (["DIR", "--faceted", "1.5"], "--faceted = 1.5 is invalid"),
                      (["DIR", "--scale", "0"], "--scale = 0 is invalid")):
        assert what_if_main("doc", script, ("slab_strength", "faceted_strength"), 8, argv) == 2
        assert why in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:
        what_if_main("doc", script, ("pre_cut_share",), 8, ["--help"])
    assert stop.value.code == 0
    out = capsys.readouterr().out
    assert all(flag in out for flag in ("--quick", "--out", "--share", "--per-class", "--runs", "--batches"))
    for name in ("closure", "rigid_base", "pre_cut", "resolution", "weak_modulus", "strength"):
        with open(os.path.join(ROOT, "benchmarks", "field", name + ".py")) as fh:
            assert "what_if_main(__doc__, __file__," in fh.read(), name
