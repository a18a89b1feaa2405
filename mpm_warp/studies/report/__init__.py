"""The results pages under ``docs/results/``, their index ``docs/results.md`` and the README's headline numbers,
generated from the benchmarks' JSON.

Run ``python -m mpm_warp.studies.report`` after a benchmark has written new results (``--check`` only says
whether the committed files are current; ``tests/test_results_current.py`` checks it in CI). Every number
in the document is formatted from the committed JSON under ``benchmarks/<group>/results/``: none is typed
into the text. Pure JSON and NumPy: no simulation runs.

**Adding a study.** Each result file has one section: a function ``render(data, ctx) -> list[str]`` of the
file's JSON that returns the Markdown lines of its tables and findings, registered with its title, its file
(relative to ``benchmarks/``), the command that reproduces it and its figure::

    @section("snow", "My study", "snow/results/my_study.json", "python benchmarks/snow/my_study.py",
             figure="snow/results/my_study.png", question="What does my study ask?")
    def render_my_study(data, ctx):
        rows = [[c["name"], fx(c["speed"], 1)] for c in data["cases"]]
        return table(["case", "speed (m/s)"], rows) + ["", env_note(data)]

in the module of its part (:mod:`.perf`, :mod:`.convergence`, :mod:`.snow_runs`, :mod:`.snow_studies`,
:mod:`.snow_interfaces`, :mod:`.robustness`; the parts are :data:`.core.PARTS`, in that order, and within a part
the sections appear in the order they are registered, or after the section they name as ``follows``). A
section goes on its part's page of :data:`.core.PAGES` unless it names another (``page="field_slab"``);
:mod:`.pages` writes each page, its checks table first, and the index.
Format every number with :mod:`.fmt` and put the
environment note (:func:`.fmt.env_note`) under the table. A study whose JSON is not committed yet is
registered with :func:`.core.pending` (its section says "not measured yet" until the file appears); a file
that does not exist is always skipped with that line, so a section can be written before its first run.
Then run the command and commit ``docs/results.md`` and ``docs/results/``.
"""

from __future__ import annotations

import os
import sys

from ...markers import checkout_root, generator_args, write_generated
from . import (  # noqa: F401
    convergence,
    field,
    field_arrest,
    field_closure,
    field_columns,
    field_equivalent,
    field_far_end,
    field_forecast,
    field_plane_stress,
    field_pre_cut,
    field_resolution,
    field_rigid_base,
    field_slab,
    field_slab_fe,
    field_strength,
    field_weak_modulus,
    main_job,
    perf,
    perf_cuda,
    robustness,
    scaling,
    snow_interfaces,
    snow_runs,
    snow_studies,
    snowpack,
)
from .core import DOC, PAGE_DIR, SECTIONS, Context, pending, section
from .pages import generate
from .readme import block, headlines, with_block

__all__ = ["SECTIONS", "Context", "section", "pending", "default_root", "results_pages", "results_markdown",
           "readme_text", "headlines", "main"]


def default_root() -> str:
    """The repository this package runs from (an editable install's checkout)."""
    return checkout_root()


def results_pages(root: str | None = None) -> dict[str, str]:
    """Every results file (``docs/results.md`` and its pages, relative to ``root``) -> its text, from the results
    under ``<root>/benchmarks/``."""
    return generate(Context(root or default_root()))


def results_markdown(root: str | None = None) -> str:
    """The text of ``docs/results.md``, the index of the results pages."""
    return results_pages(root)[DOC]


def readme_text(root: str | None = None) -> str | None:
    """``README.md`` with its headline block and main-job time regenerated; None without the results markers."""
    root = root or default_root()
    path = os.path.join(root, "README.md")
    if not os.path.isfile(path):
        return None
    ctx = Context(root)
    with open(path) as fh:
        text = with_block(fh.read(), block(ctx))
    lines = main_job.main_job_block(ctx)
    if text is not None and lines is not None:     # the main job's time, once its fresh-clone timing is committed
        text = with_block(text, lines, main_job.BEGIN, main_job.END) or text
    return text


def main(argv=None) -> int:
    a = generator_args("python -m mpm_warp.studies.report", __doc__, "file", argv)
    root = a.root or default_root()
    targets = [(os.path.join(root, rel), text) for rel, text in results_pages(root).items()]
    readme = readme_text(root)
    if readme is not None:
        targets.append((os.path.join(root, "README.md"), readme))
    stale = []
    for path, text in targets:
        old = open(path).read() if os.path.isfile(path) else None
        if old != text:
            stale.append(path)
            if not a.check:
                write_generated(path, text)
    pages = os.path.join(root, PAGE_DIR)
    stray = sorted(os.path.join(pages, f) for f in (os.listdir(pages) if os.path.isdir(pages) else [])
                   if f.endswith(".md") and os.path.join(pages, f) not in dict(targets))
    for path in stale:
        print(("out of date: " if a.check else "wrote ") + os.path.relpath(path, root))
    for path in stray:                                # a page no section is on any more
        print(("not generated: " if a.check else "removed ") + os.path.relpath(path, root))
        if not a.check:
            os.remove(path)
    stale += stray
    if not stale:
        print("current: " + ", ".join(os.path.relpath(p, root) for p, _ in targets))
    if readme is None:
        print("README.md has no results markers: left alone")
    return 1 if (a.check and stale) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
