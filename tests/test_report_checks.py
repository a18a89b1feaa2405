"""Every comparison with a reference in the results pages (docs/results/) has a pass line: its criterion and pass,
FAIL or open (issue 37, part 2). The lines come from mpm_warp.studies.report; here their format, a fail kept with its
explanation, and their presence in each comparing section of the committed document."""

import glob
import os
import re

import pytest

from mpm_warp.studies.report.fmt import check_line
from mpm_warp.studies.report.perf import render_throughput
from mpm_warp.studies.report.snowpack import ends_checks, outcome_checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: the sections of the results pages that compare with a reference (weac, FE or closed forms, field ranges, Heierli),
#: and how many pass lines each shows today
COMPARING = {"Error against run time: the reference problems": 2,
             "The weak layer's collapse under a slab: mesh study": 2,
             "PST: `pst_flat`": 5, "PST: `pst_slope`": 5, "Critical cut": 3, "Shear test": 3,
             "Fracture energy sweep": 2, "Crack speed against slab stiffness and collapse height": 2,
             "Steady crack speed on 8 m columns": 3, "weac's static answers for the ladder PST": 1,
             "Stress at the weak layer's interfaces": 1, "The three field outcomes: END, SF, ARR": 4,
             "The snowpack's critical cut: layering and column ends": 5, "Why the slab did not break": 2,
             "The slab's stress where the observer saw END": 1,
             "A resolved slab: the run and weac against a static FE": 4,
             "The rigid base: the same columns without their old snow": 2,
             "The pre-cut: the same columns started sawn": 2,
             "The grid: the same columns at 6 cells across the weak layer": 2, "CUDA: the device suite": 3,
             "Throughput beside Taichi, 2D": 1,
             "The laminate closure: the same columns without and with it": 2,
             "The laminate closure: the slab's stress at the weak layer against the FE": 2,
             "The slab's strength: the same columns with a weaker slab": 2,
             "The slab's strength by grain form: weac's static rule on every scored column": 1,
             "The far end: the columns called END, run on past the call": 1,
             "Plane strain against a 30 cm wide column: the slab's stress at the recorded cut": 1,
             "The weak layer's stiffness: the same columns on a softer weak layer": 1}
LINE = re.compile(r"^- \*\*Check, [^*]+:\*\* .+: \*\*(pass|FAIL|open)\*\*( \(.+\))?\.$")


def test_a_pass_line_says_its_criterion_and_keeps_a_fail_with_its_reason():
    assert check_line("x", "within 20 %", True, "+3.6 %") == "- **Check, x:** within 20 %: **pass** (+3.6 %)."
    assert check_line("x", "within 20 %", False, "-41.8 %: why") == \
        "- **Check, x:** within 20 %: **FAIL** (-41.8 %: why)."
    assert check_line("x", "the field", None, "no text") == "- **Check, x:** the field: **open** (no text)."


def _sections() -> dict[str, str]:
    """Every section of the committed results pages: its title -> its text."""
    out = {}
    for page in glob.glob(os.path.join(ROOT, "docs", "results", "*.md")):
        with open(page) as fh:
            parts = re.split(r"^## (.+)$", fh.read(), flags=re.M)
        out.update(zip(parts[1::2], parts[2::2], strict=True))
    return out


@pytest.mark.parametrize("title", sorted(COMPARING))
def test_each_comparing_section_shows_its_pass_lines(title):
    sections = _sections()
    lines = [ln for ln in sections[title].splitlines() if ln.startswith("- **Check, ")]
    assert len(lines) == COMPARING[title], lines
    assert all(LINE.match(ln) for ln in lines), lines


def _end_case(name, value, weac, ends, cut_from):
    return {"value": value, "relative_to_weac": value / weac - 1.0, "column_ends": ends, "cut_from": cut_from,
            "slope_angle": 35.0, "slab_layers": [{"thickness": 0.5}]}


def test_the_column_ends_fail_on_size_with_the_wedge_and_agree_in_direction():
    cases = {"ends_vertical_upslope": _end_case("v", 0.182, 0.3125, "vertical", "upslope"),
             "ends_normal_upslope": _end_case("n", 0.379, 0.4816, "slope_normal", "upslope")}
    checks = {"ends_ratio_upslope": {"mpm": 2.08, "weac": 1.54}}
    out = ends_checks(cases, checks)
    direction, size, field = out
    assert "**pass**" in direction and "MPM 2.08, weac 1.54" in direction
    assert "**FAIL**" in size and "(0 of 2)" in size and "-41.8 %" in size and "shorter than the 0.35 m wedge" in size
    assert "**open**" in field and "Birkeland" in field
    checks["ends_ratio_upslope"]["mpm"] = 0.9                  # the MPM on the other side of 1: a fail
    assert "**FAIL**" in ends_checks(cases, checks)[0]


def test_the_arrest_beyond_weacs_critical_cut_is_a_visible_fail_with_touchdown_as_its_reason():
    arr = {"weac": {"critical_cut": 0.478, "G_c": 1.2, "energy_release_rate": 5.63},
           "outcome": {"cut": 0.8, "arrest_at": 1.0125}}
    start, arrest = [ln for ln in outcome_checks({"ARR": arr}) if ln]
    assert "**pass**" in start and "ran 0.21 m beyond" in start
    assert "**FAIL**" in arrest and "4.7 G_c" in arrest and "touchdown" in arrest and "not computed" in arrest


def test_the_arrest_is_held_to_weac_with_touchdown_within_one_slab_thickness():
    arr = {"weac": {"critical_cut": 0.478, "G_c": 1.2, "energy_release_rate": 5.63},
           "outcome": {"cut": 0.8, "arrest_at": 1.0125}, "slab_layers": [{"thickness": 0.3}],
           "weac_touchdown": {"G_c": 1.2, "G_min": 2.70, "G_min_at": 0.95, "G_at_arrest": 2.73, "arrest_at": None}}
    arrest = [ln for ln in outcome_checks({"ARR": arr}) if ln][1]
    assert "**FAIL**" in arrest and "with touchdown" in arrest and "2.25 G_c" in arrest and "says END" in arrest
    for stop, verdict in ((1.25, "**pass**"), (1.35, "**FAIL**")):       # 0.24 m and 0.34 m from the MPM's 1.01 m
        arr["weac_touchdown"]["arrest_at"] = stop
        arrest = [ln for ln in outcome_checks({"ARR": arr}) if ln][1]
        assert verdict in arrest and f"weac stops it at {stop:.2f} m" in arrest


def test_a_critical_cut_change_inside_its_brackets_is_not_called_converged():
    from mpm_warp.studies.report.convergence import _bracketed

    lv = [{"critical_cut": 0.353, "critical_cut_bracket": [0.34375, 0.3625]},
          {"critical_cut": 0.334, "critical_cut_bracket": [0.325, 0.34375]},
          {"critical_cut": 0.334, "critical_cut_bracket": [0.325, 0.34375]}]
    s = {"time_to": {"5%": {"wall_time_s": 1837.0, "status": "met"}, "1%": {"wall_time_s": 1837.0, "status": "met"}}}
    chg, errs, times = _bracketed(lv, s, ["5.6 %", "0.0 %", "0.0 %"], ["5%", "1%"])
    assert chg == "-5.4 %, 0.0 % (brackets overlap: not resolved)"       # adjacent brackets resolve -5.4 %
    assert errs == ["5.6 %", "0.0 %: not resolved (brackets overlap)", "reference (bracket +/-2.8 %)"]
    assert times[0].startswith("1,837 s") and times[1] == "not resolved: the finest bracket is +/-2.8 %"


def test_the_slab_stress_peak_reads_as_where_and_which_stress():
    from mpm_warp.studies.report.field_slab import _where

    # the far end's slab base pulled normal to the bed, then the top surface in bending
    assert _where([0.989, 0.341, 2242.9, 13690.1, 1858.7]) == "0.99 m, 34.1 cm deep; normal to the bed (13.7 kPa)"
    assert _where([0.45, 0.002, 3464.0, -6.0, 8.0]) == "0.45 m, 0.2 cm deep; along the bed (3.5 kPa)"
    assert _where(None) == "-"


def test_the_layers_at_the_base_are_those_within_the_stencil_of_the_weak_layer():
    from mpm_warp.studies.report.field_slab_fe import _at_base

    # a 1.3-cell basal layer puts the 4-cell layer above it within 2 cells of the weak layer, not the top one
    assert _at_base({"layer_cells": [46.7, 4.0, 1.3]}) == {1, 2}
    assert _at_base({"layer_cells": [41.3, 2.7]}) == {1}
    assert _at_base({"layer_cells": [45.3]}) == {0}
    # thin layers: every base within 2 cells of the weak layer (the top one at 1.4), or all but the top one (2.2)
    assert _at_base({"layer_cells": [1.0, 0.7, 0.7]}) == {0, 1, 2}
    assert _at_base({"layer_cells": [1.0, 1.5, 0.7]}) == {1, 2}


def test_the_2d_elastic_step_fails_its_target_at_the_size_where_it_falls_short():
    """Issue 36's target: the 2D elastic step at least 1.2x Taichi at every size, one thread (wall clock)."""
    def rows(ratios):
        out = []
        for n, r in zip((16384, 65536, 262144), ratios, strict=True):
            out += [{"engine": "mpm_warp", "dim": 2, "material": "elastic", "n_particles": n, "threads": 1,
                     "ratio_vs_taichi": r, "ratio_vs_taichi_cpu_time": r - 0.01},
                    {"engine": "taichi", "dim": 2, "material": "elastic", "n_particles": n, "threads": 1}]
        return {"rows": out, "environment": {"device": "cpu"}}

    def check(ratios):
        (line,) = [ln for ln in render_throughput(rows(ratios), None) if ln.startswith("- **Check")]
        assert LINE.match(line), line
        return line

    assert check([1.48, 1.23, 1.09]).endswith("**FAIL** (1.09-1.48x wall clock, 1.08-1.47x CPU time).")
    assert "**pass** (1.20-1.61x wall clock" in check([1.61, 1.36, 1.20])


def test_a_section_that_follows_another_lands_after_it_whichever_is_registered_first(monkeypatch, tmp_path):
    from mpm_warp.errors import InvalidArgument
    from mpm_warp.studies.report import core
    from mpm_warp.studies.report.pages import generate

    monkeypatch.setattr(core, "SECTIONS", [])
    monkeypatch.setattr(core, "_WAITING", {})
    for title, follows in (("a", None), ("c", "b"), ("b", "a"), ("d", None), ("e", "a")):
        core.section("field", title, f"{title}.json", "cmd", follows=follows)(lambda data, ctx: [])
    assert [s.title for s in core.SECTIONS] == ["a", "e", "b", "c", "d"]
    core.section("field", "f", "f.json", "cmd", follows="nowhere")(lambda data, ctx: [])
    (tmp_path / "benchmarks").mkdir()
    with pytest.raises(InvalidArgument, match="follows"):
        generate(core.Context(str(tmp_path)))


def test_the_strength_study_asks_chance_with_fishers_exact_tail():
    from mpm_warp.studies.report.field_strength import fisher_greater

    # Fisher's tea tasting: all 4 of 4 against 0 of 4 is 1 arrangement in C(8, 4) = 70
    assert fisher_greater(4, 4, 0, 4) == pytest.approx(1.0 / 70.0, rel=1e-12)
    # 2 of 8 against 1 of 8: P(2 or 3 of the 3 hits among the first 8) = (C(8,2) C(8,1) + C(8,3)) / C(16,3)
    assert fisher_greater(2, 8, 1, 8) == pytest.approx((28 * 8 + 56) / 560, rel=1e-12)
    assert fisher_greater(0, 8, 0, 8) == 1.0
    assert fisher_greater(0, 8, 3, 8) == 1.0    # no share larger than the other's: the whole tail


def _static_case(observed, law, grain, share=0.5):
    return {"observed": observed, "predicted": "END", "faceted_share": share, "static_batch": law,
            "static_law": law, "static_grain": grain}


def test_the_grain_form_check_passes_only_when_it_turns_sf_records_beyond_chance():
    from mpm_warp.studies.report.field_strength import render_static_strength

    def check(cases):
        data = {"faceted": 0.5, "faceted_grains": ["FC", "DH"], "cases": cases, "environment": {}}
        return [ln for ln in render_static_strength(data, None) if ln.startswith("- **Check, ")][0]

    # 8 of 10 SF records turned against 0 of 10 END records: p = C(10,8) / C(20,8) (the whole tail), a pass
    sf = [_static_case("SF", "END", "SF")] * 8 + [_static_case("SF", "END", "END")] * 2
    end = [_static_case("END", "END", "END")] * 10
    line = check(sf + end)
    assert "**pass**" in line and "8 of the 10 SF records and 0 of the 10 END records" in line
    assert "p = 0.00" in line
    # the END records turned as often as the SF ones: the grain form cannot tell them apart, a fail
    end = [_static_case("END", "END", "SF")] * 8 + [_static_case("END", "END", "END")] * 2
    assert "**FAIL**" in check(sf + end) and "as often or more" in check(sf + end)
    # 2 of 4 against 1 of 4: the right way round but within chance, open
    line = check([_static_case("SF", "END", "SF")] * 2 + [_static_case("SF", "END", "END")] * 2
                 + [_static_case("END", "END", "SF")] + [_static_case("END", "END", "END")] * 3)
    assert "**open**" in line and "too few cases to tell" in line
    # no SF record the law's strength left END: nothing to compare, open
    assert "**open**" in check([_static_case("SF", "SF", "SF")] + end)


def test_the_far_end_check_fails_on_a_crack_that_stops_short_of_the_end():
    from mpm_warp.studies.report.field_far_end import fate, render_far_end

    def case(test, reached, stalled, last):
        return {"id": test, "test": test, "observed": "ARR", "status": "ok", "call": "END", "call_front": 0.7,
                "last_front": last, "reached": reached, "stalled": stalled, "runaway_cut": 0.6, "length": 1.0,
                "end_zone": 0.4, "bin_width": 0.01, "steps": 10, "wall_s": 1.0, "batch": {"steps": 8, "wall_s": 1.0}}

    data = {"chosen": "2 drawn", "end_bins": 2, "stall_time": 0.05, "per_class": 1, "seed": 0, "max_wall_s": 120,
            "workers": 1, "environment": {}, "cases": [case("a", True, False, 0.995), case("b", False, True, 0.82)]}
    assert [fate(c) for c in data["cases"]] == ["reached the end", "stopped short"]
    line = [ln for ln in render_far_end(data, None) if ln.startswith("- **Check, ")][0]
    assert "**FAIL**" in line and "1 of 2 reached the end" in line and "`b` (ARR) at 0.820 of 1.000 m" in line
    data["cases"] = data["cases"][:1]
    assert "**pass**" in [ln for ln in render_far_end(data, None) if ln.startswith("- **Check, ")][0]
    assert fate({"status": "ok", "call": "SF"}) == "called SF" and fate({"status": "failed"}) == "failed"


def _plane_case(test, observed, strain, stress, static="END"):
    return {"test": test, "observed": observed, "static_class": static, "slab_depth": 0.3,
            "fe": {"strain": {"peak": strain}, "stress": {"peak": stress}}}


def test_the_plane_stress_check_fails_where_one_column_moves_beyond_its_bound():
    from mpm_warp.studies.report.field_plane_stress import ranks_above, render_plane_stress

    # pairs (2, 1) and (3, 1) won, (2, 3) lost, (3, 3) tied: 2.5 of 4
    assert ranks_above([2.0, 3.0], [1.0, 3.0]) == 0.625

    def check(cases):
        data = {"dx": 0.01, "cases": cases, "environment": {}}
        return [ln for ln in render_plane_stress(data, None) if ln.startswith("- **Check, ")][0]

    near = [_plane_case("a", "SF", 1.0, 0.97), _plane_case("b", "END", 0.5, 0.52)]
    line = check(near)
    assert "**pass**" in line and "2 of 2; median +0.5 %, from -3.0 % to +4.0 %" in line
    line = check(near + [_plane_case("c", "ARR", 2.0, 1.6)])
    assert "**FAIL**" in line and "2 of 3" in line and "the largest at `c` (2.00 in plane strain)" in line
    text = render_plane_stress({"dx": 0.01, "environment": {}, "cases": near + [_plane_case("c", "ARR", 2.0, 1.6)]},
                               None)
    assert any("raises the slab's peak by at most +4.0 % and lowers it in 2 of the 3 columns" in ln
               and "Beyond 10 %: `c` (ARR, slab 30 cm deep, -20.0 %)." in ln for ln in text)


def _modulus_case(observed, scene, softer, status="ok"):
    def side(predicted, st, w_f, error=None):
        return {"status": st, "predicted": predicted, "static_class": "END", "w_f": w_f, "w_f_source": "read back",
                "runaway_cut": 0.3, "slab_fracture_at": None, "error": error,
                "cost": {"steps": 10, "wall_s": 1.0}}

    return {"test": f"PST {observed}", "observed": observed, "setup": None, "before": side(scene, "ok", 0.3),
            "after": side(softer if status == "ok" else None, status, 0.6,
                          None if status == "ok" else "p: PST 1/2 (SF) down 3 cm: x")}


def test_the_weak_modulus_check_asks_for_more_sf_among_the_sf_records_beyond_chance():
    from mpm_warp.studies.report.field_weak_modulus import render_weak_modulus

    def lines(cases):
        data = {"switch": {"name": "weak_modulus", "value": 0.25, "before": 1.0}, "chosen": "n drawn",
                "per_class": 8, "seed": 0, "max_wall_s": 120, "workers": 2, "threads": 1, "cases": cases,
                "environment": {}}
        return render_weak_modulus(data, None)

    def check(cases):
        return [ln for ln in lines(cases) if ln.startswith("- **Check, ")][0]

    sf = [_modulus_case("SF", "END", "SF")] * 8 + [_modulus_case("SF", "END", "END")] * 2
    end = [_modulus_case("END", "END", "END")] * 10
    assert "**pass**" in check(sf + end) and "SF records 8 of 10 (0)" in check(sf + end)
    end = [_modulus_case("END", "END", "SF")] * 8 + [_modulus_case("END", "END", "END")] * 2
    assert "**FAIL**" in check(sf + end) and "no larger share of the SF records" in check(sf + end)
    few = [_modulus_case("SF", "END", "SF")] * 2 + [_modulus_case("SF", "END", "END")] * 2
    few += [_modulus_case("END", "END", "SF")] + [_modulus_case("END", "END", "END")] * 3
    assert "**open**" in check(few)
    # a column the softer layer refuses is said in field terms and left out of the counts
    out = lines(few + [_modulus_case("SF", "END", None, status="refused")])
    assert "SF records 2 of 4 (0)" in [ln for ln in out if ln.startswith("- **Check, ")][0]
    assert any(ln.startswith("- Not run at 0.25 MPa (1): `PST SF` (SF): x.") for ln in out)
    assert any("2.00 times the scene's (median; 2.00 to 2.00)" in ln for ln in out)
