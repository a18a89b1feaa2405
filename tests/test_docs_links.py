"""Every relative link, #anchor and repository path that README.md, docs/*.md and the results pages name exists.

Links are Markdown links and images (``[text](target)``); anchors are checked against the headings of the
file they point into, as GitHub renders them (lower case, spaces to '-', punctuation dropped, a repeated
heading suffixed -1, -2, ...). A path in backticks whose first folder is one of the repository's (``tests/``,
``benchmarks/``, ...) must exist too (a ``*`` must match a file), except on a line that says the file "is not
committed" (a result not measured yet). No doc may point outside the repository.
"""

from __future__ import annotations

import glob
import os
import re

import pytest

from mpm_warp.studies.report.core import slug

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = ["README.md", *sorted(os.path.relpath(p, ROOT) for pattern in ("*.md", "results/*.md")
                             for p in glob.glob(os.path.join(ROOT, "docs", pattern)))]
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
CODE = re.compile(r"`([^`]+)`")
TOP = {d for d in os.listdir(ROOT) if os.path.isdir(os.path.join(ROOT, d)) and not d.startswith(".")
       and d not in ("build", "dist") and not d.endswith(".egg-info")}


def _prose(text: str) -> list[str]:
    """The lines outside fenced code blocks."""
    out, fenced = [], False
    for line in text.splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if not fenced:
            out.append(line)
    return out


def anchors(path: str) -> set[str]:
    """The anchors GitHub gives the headings of the Markdown file ``path``."""
    seen: dict[str, int] = {}
    out = set()
    for line in _prose(open(path).read()):
        m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m is None:
            continue
        a = slug(m.group(1))
        n = seen.get(a, 0)
        seen[a] = n + 1
        out.add(a if n == 0 else f"{a}-{n}")
    return out


def problems(rel: str) -> list[str]:
    """What ``rel`` (a Markdown file relative to the repository) names that does not exist."""
    path = os.path.join(ROOT, rel)
    here = os.path.dirname(path)
    out = []
    lines = _prose(open(path).read())
    for target in (t for line in lines for t in LINK.findall(line)):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):        # http:, https:, mailto:
            continue
        file, _, anchor = target.partition("#")
        dest = os.path.normpath(os.path.join(here, file)) if file else path
        if not dest.startswith(ROOT + os.sep):
            out.append(f"{target}: outside the repository")
        elif not os.path.exists(dest):
            out.append(f"{target}: no such file")
        elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
            out.append(f"{target}: no heading with that anchor")
    named = (w for line in lines if "is not committed" not in line for t in CODE.findall(line) for w in t.split())
    for token in named:
        token = token.rstrip(".,:;)").lstrip("(")
        if "/" not in token or token.split("/")[0] not in TOP or "<" in token or "{" in token:
            continue
        if not glob.glob(os.path.join(ROOT, token.split(":")[0])):
            out.append(f"`{token}`: no such path")
    return out


@pytest.mark.parametrize("rel", DOCS)
def test_links_anchors_and_paths_exist(rel):
    assert problems(rel) == []


def test_the_checker_finds_what_is_missing(tmp_path, monkeypatch):
    (tmp_path / "docs").mkdir()
    (tmp_path / "tests").mkdir()
    (tmp_path / "docs" / "a.md").write_text("# A title, with `code`\n\n## Twice\n\n## Twice\n")
    (tmp_path / "README.md").write_text(
        "[ok](docs/a.md#a-title-with-code) [ok2](docs/a.md#twice-1) [bad](docs/a.md#nope) [gone](docs/b.md)\n"
        "[out](../elsewhere.md) `tests/test_none*.py` `docs/a.md`\n```\n[in a fence](nowhere.md)\n```\n")
    monkeypatch.setattr(__import__(__name__), "ROOT", str(tmp_path))
    monkeypatch.setattr(__import__(__name__), "TOP", {"docs", "tests"})
    assert problems("README.md") == ["docs/a.md#nope: no heading with that anchor", "docs/b.md: no such file",
                                     "../elsewhere.md: outside the repository", "`tests/test_none*.py`: no such path"]
