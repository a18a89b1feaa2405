"""The quick tier, ``pytest -m "not slow"``: the marker is registered and strict, and the README gives both commands
(the whole suite, CI's, and the quick tier, which only adds the marker expression)."""

from __future__ import annotations

import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_the_slow_marker_is_registered_and_a_misspelt_one_is_an_error(pytestconfig):
    assert [m for m in pytestconfig.getini("markers") if m.startswith("slow:")]
    assert pytestconfig.getoption("strict_markers")    # @pytest.mark.slwo fails collection instead of running


def test_the_readme_gives_the_whole_suite_and_the_quick_tier():
    with open(os.path.join(ROOT, "README.md")) as fh:
        blocks = re.findall(r"```bash\n(.*?)```", fh.read(), re.S)
    with open(os.path.join(ROOT, ".ci", "run")) as fh:
        ci = fh.read()
    full = ".venv/bin/python -m pytest -q -n auto --dist loadfile"
    quick = '.venv/bin/python -m pytest -q -m "not slow" -n auto --dist loadfile'
    assert any(b.strip().endswith(full) for b in blocks) and ci.rstrip().endswith(full)
    assert [b.strip() for b in blocks if "not slow" in b] == [quick]
    assert " -m " not in ci.replace("python3 -m venv", "").replace("python -m pytest", "")
