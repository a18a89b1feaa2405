"""Provenance of the committed results: no result from uncommitted code lands in ``benchmarks/*/results/``.

The results tooling (``mpm_warp.studies.environment``) refuses to write one there; the last test lists the
committed results that are marked dirty today and fails on any other (issue 37, part 3).
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import re
import subprocess

import pytest

from mpm_warp.studies import environment as envmod
from mpm_warp.studies.environment import (
    DirtyResultError,
    check_provenance,
    dirty_marks,
    git_commit,
    is_committed_results,
    write_json,
)
from mpm_warp.studies.protocol import out_dir

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _git(repo, *args):
    subprocess.run(["git", "-C", str(repo), "-c", "user.email=t@example.org", "-c", "user.name=t", *args],
                   check=True, capture_output=True)


@pytest.fixture
def repo(tmp_path):
    """A checkout with a committed results folder, clean."""
    r = tmp_path / "repo"
    (r / "benchmarks" / "snow" / "results").mkdir(parents=True)
    (r / "code.py").write_text("x = 1\n")
    _git(r, "init", "-q")
    _git(r, "add", "code.py")
    _git(r, "commit", "-q", "-m", "start")
    return r


def test_committed_results_folders_are_recognised(tmp_path):
    assert is_committed_results(str(tmp_path / "benchmarks" / "snow" / "results"), str(tmp_path))
    assert is_committed_results(str(tmp_path / "benchmarks" / "snow" / "results" / "cases"), str(tmp_path))
    assert not is_committed_results(str(tmp_path / "benchmarks" / "snow"), str(tmp_path))
    assert not is_committed_results(str(tmp_path / "out"), str(tmp_path))
    assert is_committed_results(os.path.join(ROOT, "benchmarks", "perf", "results"))


def test_a_dirty_checkout_cannot_write_into_the_committed_results(repo):
    results = str(repo / "benchmarks" / "snow" / "results")
    check_provenance(results, None, str(repo))                     # clean: allowed
    (repo / "code.py").write_text("x = 2\n")                       # an uncommitted change
    assert git_commit(str(repo)).endswith("+dirty")
    with pytest.raises(DirtyResultError) as err:
        check_provenance(results, None, str(repo))
    line = str(err.value)
    assert "\n" not in line and "+dirty" in line and "commit" in line and "--out" in line
    assert err.value.code == line                                  # SystemExit: the line, exit status 1
    check_provenance(str(repo / "elsewhere"), None, str(repo))     # --out elsewhere: allowed
    _git(repo, "commit", "-q", "-am", "the change")
    check_provenance(results, None, str(repo))                     # committed: allowed again


def test_the_recorded_commit_decides_and_nothing_is_written(repo, monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(envmod, "REPO_ROOT", str(repo))
    results = str(repo / "benchmarks" / "snow" / "results")
    dirty = {"environment": {"git_commit": "abc+dirty"}, "x": 1.0}
    with pytest.raises(DirtyResultError):
        write_json("r", dirty, results)
    assert os.listdir(results) == []
    merged = {"environment": {"git_commit": "abc"}, "cases": [{"git_commit_base_run": "def (+ uncommitted test file)"}]}
    assert dirty_marks(merged) == ["def (+ uncommitted test file)"]
    with pytest.raises(DirtyResultError):
        write_json("r", merged, results)
    path = write_json("r", {"environment": {"git_commit": "abc"}, "x": 1.0}, results)   # clean record: written
    assert json.load(open(path))["x"] == 1.0
    elsewhere = write_json("r", dirty, str(tmp_path / "mine"))                         # --out elsewhere
    assert json.load(open(elsewhere))["environment"]["git_commit"] == "abc+dirty"
    assert "marked dirty (abc+dirty)" in capsys.readouterr().err


def test_a_full_run_from_a_dirty_tree_is_refused_before_it_starts(monkeypatch, tmp_path):
    monkeypatch.setattr(envmod, "git_commit", lambda path=None: "abc+dirty")
    results = os.path.join(ROOT, "benchmarks", "snow", "results")
    args = argparse.Namespace(device="cpu", quick=False, out=None)
    with pytest.raises(DirtyResultError):
        out_dir(args, results, "x")
    quick = out_dir(argparse.Namespace(device="cpu", quick=True, out=None), results, "x")
    assert not is_committed_results(quick)                         # --quick still runs, to a temporary folder
    assert out_dir(argparse.Namespace(device="cpu", quick=False, out=str(tmp_path)), results) == str(tmp_path)


def _committed_results() -> dict[str, str]:
    """Every committed result JSON (path under ``benchmarks/``: its text)."""
    files = glob.glob(os.path.join(ROOT, "benchmarks", "*", "results", "**", "*.json"), recursive=True)
    assert len(files) >= 30, "the committed results were not found"
    out = {}
    for path in files:
        with open(path) as fh:
            out[os.path.relpath(path, os.path.join(ROOT, "benchmarks")).replace(os.sep, "/")] = fh.read()
    return out


def test_no_committed_result_is_marked_dirty():
    """No committed result records uncommitted code (``+dirty`` or "uncommitted"): rerun it from a clean
    commit (the tooling refuses to write one into the results, ``check_provenance``)."""
    dirty = sorted(rel for rel, text in _committed_results().items() if "+dirty" in text or "uncommitted" in text)
    assert not dirty, f"results from uncommitted code: {dirty}; rerun them from a clean commit"


def test_every_committed_result_names_the_commit_of_its_code():
    """A result names the committed code that produced it: a whole commit hash under ``git_commit`` (or a
    ``git_commit_*`` of a part run apart) somewhere in its JSON."""
    unnamed = sorted(rel for rel, text in _committed_results().items()
                     if not re.search(r'"git_commit(_[a-z_]+)?": "[0-9a-f]{40}', text))
    assert not unnamed, f"results that do not name their code: {unnamed}; rerun them from a clean commit"
