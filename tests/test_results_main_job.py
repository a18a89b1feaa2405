"""The main job's timing: the README's commands read back (the test command is CI's), its results section and
README line formatted from a tiny fresh-clone JSON."""

from __future__ import annotations

import json
import os

import pytest

from mpm_warp.studies.fresh_clone import readme_commands, split_parts
from mpm_warp.studies.report import Context
from mpm_warp.studies.report.core import SECTIONS
from mpm_warp.studies.report.main_job import SOURCE, main_job_block
from mpm_warp.studies.report.pages import page_text

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_readme_test_command_is_what_ci_runs():
    with open(os.path.join(ROOT, "README.md")) as fh:
        cmds = readme_commands(fh.read())
    with open(os.path.join(ROOT, ".ci", "run")) as fh:
        ci = [line for line in fh.read().splitlines() if line.startswith("python3 -m venv")]
    assert ci == [cmds["tests"]]
    assert split_parts(cmds["main_job"]) == ["python3 -m venv .venv", ".venv/bin/pip install -e .",
                                             ".venv/bin/mpm-warp run pst_demo --out pst_demo.h5 --plot"]


def test_readme_without_the_blocks_is_refused():
    with pytest.raises(ValueError, match="no bash block after '## Install and run the main job'"):
        readme_commands("# mpm_warp\n\n```bash\nls\n```\n")


FRESH = {"environment": {"date": "2026-12-02T10:09:45+00:00", "device": "cpu", "cpu": "x86_64", "cpu_count": 2,
                         "load_average_1_5_15_min": [0.85, 0.3, 0.1], "warp": "1.19.0"},
         "ok": True,
         "main_job": {"parts": [{"command": "python3 -m venv .venv", "wall_s": 2.65, "rc": 0},
                                {"command": ".venv/bin/pip install -e .", "wall_s": 20.47, "rc": 0},
                                {"command": ".venv/bin/mpm-warp run pst_demo --out pst_demo.h5 --plot",
                                 "wall_s": 200.0, "rc": 0}],
                      "n_particles": 1000, "steps": 2000, "frames": 5, "pictures": ["pst.png"]},
         "tests": {"parts": [{"command": "python3 -m venv .venv", "wall_s": 3.0, "rc": 0},
                             {"command": ".venv/bin/python -m pytest -q", "wall_s": 600.0, "rc": 0}]}}


def test_main_job_section_and_readme_line(tmp_path):
    os.makedirs(tmp_path / "benchmarks" / "perf" / "results")
    with open(tmp_path / "benchmarks" / SOURCE, "w") as fh:
        json.dump(FRESH, fh)
    ctx = Context(str(tmp_path))
    lines = page_text(ctx, "perf", [s for s in SECTIONS if s.source == SOURCE]).splitlines()
    assert "Command: `python benchmarks/perf/fresh_clone.py --tests`. Data: [`perf/results/fresh_clone.json`]" \
           "(../../benchmarks/perf/results/fresh_clone.json)." in lines
    assert "| install and run the main job | `.venv/bin/pip install -e .` | 20 s | 0 |" in lines
    assert ("The main job: 1,000 particles, 2,000 steps, 5 frames, 0.0 M particle-steps/s over the run's wall time "
            "(compiling and pictures included); it wrote `pst.png`.") in lines
    assert main_job_block(ctx) == [
        "Measured from a fresh clone on a 2-core CPU (2026-12-02; the machine's load is in the linked section): "
        "the install took "
        "23 s, the run with its pictures 200 s; the test command below 603 s "
        "([The main job](docs/results/performance.md#the-main-job))."]
    FRESH["ok"] = False                      # a failed command is not quoted in the README
    try:
        with open(tmp_path / "benchmarks" / SOURCE, "w") as fh:
            json.dump(FRESH, fh)
        assert main_job_block(Context(str(tmp_path))) is None
    finally:
        FRESH["ok"] = True
