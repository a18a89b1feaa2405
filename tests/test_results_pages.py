"""The results by question (issue 55, part 3): docs/results.md is a short index that links every page, no generated
page is over 600 lines, and each page opens with the table of its checks, one row per check line of its sections
(the ``- **Check, label:**`` lines and the older ``**Check:**`` ones), each linking to its section."""

from __future__ import annotations

import os
import re

import pytest

from mpm_warp.studies.report import main, results_pages
from mpm_warp.studies.report.core import DOC, PAGES, slug
from mpm_warp.studies.report.pages import Check, checks, ref

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GENERATED = results_pages(ROOT)
PAGE_FILES = sorted(p.path for p in PAGES.values())
#: the most lines a generated page may have (issue 55's check)
MAX_LINES = 600
ROW = re.compile(r"^\| .+ \| \*\*(pass|FAIL|open)\*\* \| \[[^\]]+\]\(#([\w-]+)\) \|$")


def _committed(rel: str) -> str:
    with open(os.path.join(ROOT, rel)) as fh:
        return fh.read()


def test_the_results_document_is_a_short_index_that_links_every_page():
    text = _committed(DOC)
    assert text == GENERATED[DOC]
    assert len(text.splitlines()) <= 40
    assert not re.search(r"^#{2,} ", text, flags=re.M) and "\n| " not in text      # no section, no table
    for page in PAGES.values():
        line = next(ln for ln in text.splitlines() if f"]({page.path.removeprefix('docs/')})" in ln)
        assert re.search(r"checks: \d+ pass, \d+ FAIL, \d+ open\.$", line), line


@pytest.mark.parametrize("rel", PAGE_FILES)
def test_no_page_is_over_600_lines(rel):
    assert len(GENERATED[rel].splitlines()) <= MAX_LINES
    assert len(_committed(rel).splitlines()) <= MAX_LINES


@pytest.mark.parametrize("rel", PAGE_FILES)
def test_each_page_opens_with_the_table_of_its_checks(rel):
    lines = _committed(rel).splitlines()
    headings = [i for i, ln in enumerate(lines) if ln.startswith("## ")]
    assert lines[0].startswith("# ") and lines[headings[0]] == "## Checks"
    body = lines[headings[1]:]
    said = [ln for ln in body if ln.startswith("- **Check, ") or ln.startswith("**Check:** ")]
    table = lines[headings[0] + 2:headings[1]]
    rows = [ln for ln in table if ROW.match(ln)]
    if not said:
        assert table[0] == "No section of this page compares with a reference."
        return
    assert table[:2] == ["| check | verdict | section |", "|---|---|---|"]
    assert len(rows) == len(said)                                   # one row per check line, no more
    sections = {ln[3:] for ln in body if ln.startswith("## ")}
    anchors = {ROW.match(r)[2] for r in rows}
    assert anchors <= {slug(s) for s in sections}                   # each row links to a section of its page
    for row, line in zip(rows, said, strict=True):                  # in order, with the line's verdict
        verdict = ROW.match(row)[1]
        assert f"**{verdict}**" in line or f"**{verdict.lower()}**" in line, (row, line)


def test_both_check_formats_become_rows_with_their_verdict():
    lines = ["text", "- **Check, flat ladder against weac:** |MPM / weac - 1| <= 15 %: **pass** (-9.1 %).",
             "**Check:** at least 80 % of the records become columns: 79.6 %, **fail**.",
             "**Check:** the median case within 60 s of wall time, one at a time (86 cases): 56 s, **open** (few).",
             "- **Resolution:** not a check: **pass**."]
    assert checks("T", lines) == [
        Check("flat ladder against weac", "|MPM / weac - 1| <= 15 %", "pass", "T"),
        Check("at least 80 % of the records become columns", "", "FAIL", "T"),
        Check("the median case within 60 s of wall time, one at a time (86 cases)", "", "open", "T")]


def test_a_section_link_resolves_from_the_root_the_docs_and_the_pages():
    assert ref("Shear test") == "[Shear test](snow.md#shear-test)"
    assert ref("Shear test", ".") == "[Shear test](docs/results/snow.md#shear-test)"
    assert ref("Shear test", "docs") == "[Shear test](results/snow.md#shear-test)"
    assert ref("No such section") == '"No such section"'


def test_a_page_no_section_is_on_is_removed_and_flagged(tmp_path, capsys):
    (tmp_path / "benchmarks").mkdir()                                # no result committed: every section pending
    assert main(["--root", str(tmp_path)]) == 0
    assert main(["--root", str(tmp_path), "--check"]) == 0
    stray = tmp_path / "docs" / "results" / "old.md"
    stray.write_text("# An old page\n")
    assert main(["--root", str(tmp_path), "--check"]) == 1 and stray.exists()
    assert "not generated: docs/results/old.md" in capsys.readouterr().out
    assert main(["--root", str(tmp_path)]) == 0 and not stray.exists()
