"""docs/results.md, the results pages under docs/results/ and the README's headline numbers are generated from the
committed benchmark JSON (``python -m mpm_warp.studies.report``): the committed files are current, and sections
format a tiny JSON exactly as written (numbers from the data, a missing file skipped with one line)."""

from __future__ import annotations

import difflib
import json
import os

import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.studies.report import SECTIONS, Context, main, readme_text, results_pages
from mpm_warp.studies.report.core import PAGES
from mpm_warp.studies.report.fmt import env_note, spct
from mpm_warp.studies.report.pages import page_text
from mpm_warp.studies.report.readme import BEGIN, END, with_block

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIX = "run `python -m mpm_warp.studies.report` and commit what it writes"


def _diff(a: str, b: str) -> str:
    d = difflib.unified_diff(a.splitlines(), b.splitlines(), "committed", "generated", lineterm="", n=1)
    return "\n".join(list(d)[:30])


GENERATED = results_pages(ROOT)


@pytest.mark.parametrize("rel", sorted(GENERATED))
def test_committed_results_pages_are_current(rel):
    path = os.path.join(ROOT, rel)
    committed = open(path).read() if os.path.isfile(path) else ""
    generated = GENERATED[rel]
    assert generated == committed, f"{rel} is out of date: {FIX}\n{_diff(committed, generated)}"


def test_every_results_page_is_generated_and_every_page_is_committed():
    assert set(GENERATED) == {"docs/results.md"} | {p.path for p in PAGES.values()}
    pages = os.path.join(ROOT, "docs", "results")
    assert {f"docs/results/{f}" for f in os.listdir(pages) if f.endswith(".md")} == set(GENERATED) - {"docs/results.md"}


def test_committed_readme_block_is_current():
    with open(os.path.join(ROOT, "README.md")) as fh:
        readme = fh.read()
    generated = readme_text(ROOT)
    if BEGIN in readme and END in readme:
        assert generated == readme, f"README.md's results block is out of date: {FIX}\n{_diff(readme, generated)}"
    else:   # no markers: the README is left alone
        assert generated is None


def test_every_committed_result_has_a_section():
    """A result JSON committed under benchmarks/<group>/results/ without a section would drift out of the docs."""
    sources = {s.source for s in SECTIONS}
    bench = os.path.join(ROOT, "benchmarks")
    committed = {f"{g}/results/{f}" for g in os.listdir(bench) if os.path.isdir(os.path.join(bench, g, "results"))
                 for f in os.listdir(os.path.join(bench, g, "results")) if f.endswith(".json")}
    assert committed <= sources, (f"no section for {sorted(committed - sources)}: add one (or a pending() line) in "
                                  "mpm_warp/studies/report/, then run `python -m mpm_warp.studies.report`")


# ----------------------------------------------------------------------------- synthetic results
ENV = {"date": "2026-11-30T03:01:39+00:00", "device": "cpu", "cpu": "x86_64", "cpu_count": 2,
       "load_average_1_5_15_min": [3.14, 2.0, 1.0], "load_average_at_end_1_5_15_min": [2.5, 2.0, 1.0],
       "warp": "1.19.0", "taichi": None}


def _shear_run(cells, peak, slip):
    return {"cells": cells, "dx": 0.03 / cells, "wall_s": 12.34, "steps": 2000, "particles": 1234,
            "result": {"peak_shear_stress": peak, "tau_p_calibrated": 1000.0, "softening_displacement": slip,
                       "softening_displacement_whole_layer": 0.0021, "plate_softening_displacement": float("nan"),
                       "residual_shear_stress": 500.4, "collapse_fraction": 0.25, "collapse_fraction_law": 0.15,
                       "collapse_fraction_critical_state": 0.2345, "p_final": 700.0, "bond_lost": True}}


SHEAR = {"runs": [_shear_run(4, 900.04, 0.00204), _shear_run(8, 1010.0, 0.0020)],
         "change_4_to_8_cells": {"peak_shear_stress": 0.0122, "softening_displacement": -0.0196},
         "si_softening_slip": 0.002, "si_collapse": 0.2, "environment": ENV}
BONDED = {"precision": "float32", "environment": {**ENV, "load_average_at_end_1_5_15_min": None},
          "rows": [{"set": "elastic", "n": 1000, "yielded_fraction_bonded": 0.0, "yielded_fraction_camclay": 0.0,
                    "bonded_ns_per_point": 7.84, "camclay_ns_per_point": 11.05, "bonded_times_s": [1e-5] * 2,
                    "camclay_times_s": [1e-5] * 2, "ratio": 0.7095},
                   {"set": "yield_far", "n": 1000, "yielded_fraction_bonded": 0.984, "yielded_fraction_camclay": 0.5,
                    "bonded_ns_per_point": 4145.49, "camclay_ns_per_point": 212.9, "bonded_times_s": [1e-3] * 2,
                    "camclay_times_s": [1e-4] * 2, "ratio": 19.4713}]}


@pytest.fixture
def root(tmp_path):
    for group in ("perf", "snow"):
        os.makedirs(tmp_path / "benchmarks" / group / "results")
    with open(tmp_path / "benchmarks" / "snow" / "results" / "snow_shear_test.json", "w") as fh:
        json.dump(SHEAR, fh)
    with open(tmp_path / "benchmarks" / "perf" / "results" / "bonded_return_cost_cpu.json", "w") as fh:
        json.dump(BONDED, fh)
    return str(tmp_path)


def _section(root, source):
    """The lines of one section's part of the document generated in ``root``, from its heading to the next."""
    sec = next(s for s in SECTIONS if s.source == source)
    text = page_text(Context(root), sec.page_key, [sec]).splitlines()
    start = text.index(f"## {sec.title}")
    return text[start:]


def test_shear_test_section_formats_the_json(root):
    lines = _section(root, "snow/results/snow_shear_test.json")
    assert "Command: `python benchmarks/snow/shear_test.py --cells 4 8`. Data: [`snow/results/snow_shear_test.json`]" \
           "(../../benchmarks/snow/results/snow_shear_test.json)." in lines
    assert "| quantity | 4 cells (dx 7.50 mm) | 8 cells (dx 3.75 mm) | reference |" in lines
    assert "| particles; steps; wall time | 1,234; 2,000; 12 s | 1,234; 2,000; 12 s |  |" in lines
    assert "| peak shear stress | 900.0 Pa (-10.0 %) | 1010.0 Pa (+1.0 %) | given tau_p 1000 Pa |" in lines
    assert ("| softening slip, the interior's bond (peak to bond loss) | 2.040 mm | 2.000 mm "
            "| given 2.0 mm (SI Note 2) |") in lines
    assert "| softening slip of the push plate | - | - |  |" in lines          # nan: a dash
    assert ("| collapse 1 - J_P at the end of the push | 0.250 | 0.250 | about 0.2 (SI Note 2); oedometric law at "
            "sigma_n 0.150 |") in lines
    assert "| critical-state law at the final pressure | 0.234 | 0.234 |  |" in lines
    assert ("*Measured on cpu (x86_64, 2 cores), 2026-11-30, load average 3.1 at the start and 2.5 at the end; "
            "warp 1.19.0.*") in lines
    assert "From 4 to 8 cells: peak +1.2 %, softening slip -2.0 %." in lines
    # a number changed in the JSON changes the document
    SHEAR["runs"][0]["result"]["peak_shear_stress"] = 950.0
    try:
        with open(os.path.join(root, "benchmarks", "snow", "results", "snow_shear_test.json"), "w") as fh:
            json.dump(SHEAR, fh)
        assert "| peak shear stress | 950.0 Pa (-5.0 %) | 1010.0 Pa (+1.0 %) | given tau_p 1000 Pa |" in \
            _section(root, "snow/results/snow_shear_test.json")
    finally:
        SHEAR["runs"][0]["result"]["peak_shear_stress"] = 900.04


def test_bonded_return_section_formats_the_json(root):
    lines = _section(root, "perf/results/bonded_return_cost_cpu.json")
    assert "Command: `python benchmarks/perf/bonded_return_cost.py --n 1000 --precision float32`." in lines[4]
    i = lines.index("| trial states | points | yielding (bonded / Cam-Clay) | bonded (ns/point) | Cam-Clay (ns/point) "
                    "| bonded / Cam-Clay |")
    assert lines[i + 1] == "|---|---:|---:|---:|---:|---:|"
    assert lines[i + 2] == "| elastic | 1,000 | 0 % / 0 % | 7.8 | 11.1 | 0.71 |"
    assert lines[i + 3] == "| yield_far | 1,000 | 98 % / 50 % | 4145.5 | 212.9 | 19.47 |"
    assert lines[i + 5] == ("*Measured on cpu (x86_64, 2 cores), 2026-11-30, load average 3.1 at the start; "
                            "warp 1.19.0.*")
    assert lines[i + 7] == "float32, one launch over all points: the median of 2 launches after a compiling one."


def test_a_result_not_committed_says_not_measured_yet(root):
    lines = _section(root, "perf/results/throughput_cpu.json")
    assert lines[4] == "Not measured yet: `benchmarks/perf/results/throughput_cpu.json` is not committed."
    assert not any(line.startswith("![") for line in lines[:6])    # and no figure


def test_env_note_of_several_records_gives_ranges():
    a = {"environment": ENV}
    b = {"environment": {**ENV, "date": "2026-12-02T00:00:00+00:00", "load_average_1_5_15_min": [6.0, 1, 1],
                         "taichi": "1.7.4"}}
    old = {"date": "2026-11-23", "device": "cpu", "versions": {"warp": "1.18.0"}}   # an older file's top-level record
    assert env_note(a, b, old) == ("*Measured on cpu (x86_64, 2 cores), 2026-11-23 to 2026-12-02, load average 3.1-6.0 "
                                   "at the start and 2.5 at the end; warp 1.18.0, 1.19.0, Taichi 1.7.4.*")
    assert env_note({"device": "cpu"}) == "*Measured on cpu, date not recorded, load average not recorded.*"
    zen4 = {"environment": {**ENV, "cpu_model": "AMD EPYC family 25 model 17 avx512f"}}
    assert env_note(zen4, a).startswith("*Measured on cpu (x86_64, 2 cores; x86_64, AMD EPYC family 25 model 17 "
                                        "avx512f, 2 cores), ")   # two hosts: the older record names no model
    assert spct(-0.0004) == "0.0 %" and spct(-0.081) == "-8.1 %"


def test_readme_block_is_replaced_between_the_markers_only():
    readme = f"# Title\n\nText.\n{BEGIN}\n- old\n{END}\nMore 1.0 text.\n"
    assert with_block(readme, ["- a", "- b"]) == f"# Title\n\nText.\n{BEGIN}\n- a\n- b\n{END}\nMore 1.0 text.\n"
    assert with_block("# Title\nno markers\n", ["- a"]) is None
    assert with_block(f"{END}\n{BEGIN}\n", ["- a"]) is None      # markers out of order: left alone


def test_main_writes_checks_and_leaves_a_readme_without_markers_alone(root, capsys):
    with open(os.path.join(root, "README.md"), "w") as fh:
        fh.write("# Plain README\n")
    assert main(["--root", root, "--check"]) == 1                     # docs/results.md missing: out of date
    assert not os.path.exists(os.path.join(root, "docs", "results.md"))
    assert main(["--root", root]) == 0
    assert main(["--root", root, "--check"]) == 0
    with open(os.path.join(root, "README.md")) as fh:
        assert fh.read() == "# Plain README\n"
    with open(os.path.join(root, "README.md"), "w") as fh:
        fh.write(f"# README\n{BEGIN}\n{END}\n")
    assert main(["--root", root, "--check"]) == 1
    assert main(["--root", root]) == 0
    with open(os.path.join(root, "README.md")) as fh:
        text = fh.read()
    assert "- **Shear test:** peak 900.0 / 1010.0 Pa at 4 / 8 cells against the given tau_p 1000 Pa " \
           "(-10.0 % / +1.0 %) ([Shear test](docs/results/snow.md#shear-test))." in text
    assert "Throughput" not in text                                   # its JSON is not there: no bullet
    with pytest.raises(InvalidArgument, match="root"):
        Context(os.path.join(root, "docs"))
