"""The results' machinery: sections (one per result file), their registry, their pages and one section's Markdown.

A section is a function of one result file's JSON that returns the Markdown of its tables and findings;
:func:`section` registers it with its title, its file under ``benchmarks/``, the command that reproduces
it, its figure and the page it goes on (:data:`PAGES`). :func:`render_section` writes one section, with a
"not measured yet" line for a file that does not exist yet; :mod:`.pages` assembles the pages and their index.
"""

from __future__ import annotations

import os
import posixpath
import re
from collections.abc import Callable
from dataclasses import dataclass

from ...errors import InvalidArgument
from ...finite_json import load_json

__all__ = ["PARTS", "Page", "PAGES", "Section", "Context", "SECTIONS", "section", "cases_command", "pending",
           "render_section", "slug"]

#: The parts of the results, in order: key -> heading.
PARTS = {"perf": "Performance", "convergence": "Convergence", "snow": "Snow science", "field": "Field data",
         "robustness": "Robustness"}

#: The index of the results, the file that links every page.
DOC = "docs/results.md"
#: The folder of the pages, relative to the repository.
PAGE_DIR = "docs/results"


@dataclass(frozen=True)
class Page:
    """One generated page of the results: the sections that answer one question.

    Attributes
    ----------
    name : str
        The file's name without ``.md``, in :data:`PAGE_DIR`.
    title : str
        The page's heading.
    question : str
        What the page answers, one line (the index shows it).
    """

    name: str
    title: str
    question: str

    @property
    def path(self) -> str:
        """The page, relative to the repository (``docs/results/field.md``)."""
        return f"{PAGE_DIR}/{self.name}.md"


#: The pages, in order: key -> page. A section goes on the page of its part's key unless it names another.
PAGES = {
    "perf": Page("performance", "Performance",
                 "How fast is a step, on a CPU beside Taichi and on a GPU, and what does each part of it cost?"),
    "convergence": Page("convergence", "Convergence",
                        "How does the error fall with the grid, against exact answers and the snow ladders, and at "
                        "what run time?"),
    "snow": Page("snow", "Snow science",
                 "Do the model's PSTs, shear tests and crack speeds agree with weac, closed forms and field ranges?"),
    "field": Page("field", "Field data: the scores",
                  "How well does the model call real PSTs (END, SF, ARR), at what cost, and do the batch's set-up "
                  "choices (base, pre-cut, grid, the END call) change the calls?"),
    "field_slab": Page("field-slab", "Field data: why the slab does not break",
                       "Where the observers saw the slab break (SF) and the model did not: the slab's stress against "
                       "static models, and what-ifs on its strength, width and weak layer."),
    "robustness": Page("robustness", "Robustness",
                        "Does a run survive its machine's failures (a full disk), and does its resume hold?"),
}


@dataclass(frozen=True)
class Section:
    """One result file's part of the document.

    Attributes
    ----------
    part : str
        Key of :data:`PARTS`.
    title : str
        The heading.
    source : str
        The JSON, relative to ``benchmarks/`` (``"perf/results/throughput_cpu.json"``).
    command : str or callable
        The command that reproduces the file (from the repository root); a callable gets the JSON.
    render : callable or None
        ``render(data, ctx) -> list[str]``: the section's Markdown lines. None: a study whose section
        is not written yet (its file, once committed, is linked with a line saying so).
    figure : str or None
        The committed figure, relative to ``benchmarks/``, embedded after the tables when it exists.
    question : str
        What the file answers, one line.
    page : str or None
        Key of :data:`PAGES` the section goes on; None: its part's.
    """

    part: str
    title: str
    source: str
    command: str | Callable[[dict], str]
    render: Callable[[dict, Context], list[str]] | None
    figure: str | None = None
    question: str = ""
    page: str | None = None

    @property
    def page_key(self) -> str:
        """The key of :data:`PAGES` of the page the section is on."""
        return self.page or self.part


#: Every registered section, in the order of the document.
SECTIONS: list[Section] = []


def section(part: str, title: str, source: str, command, figure: str | None = None, question: str = "",
            follows: str | None = None, page: str | None = None):
    """Decorator registering ``render(data, ctx) -> list[str]`` as the section of ``source`` (see :class:`Section`);
    ``follows``: the title of the section this one comes right after, registered before or after it (else it
    comes last); ``page``: the key of :data:`PAGES` it goes on (default: its part's)."""
    if part not in PARTS:
        raise InvalidArgument("part", part, f"one of {sorted(PARTS)}")
    if (page or part) not in PAGES:
        raise InvalidArgument("page", page, f"one of {sorted(PAGES)}")

    def register(render):
        _place(Section(part, title, source, command, render, figure, question, page), follows)
        return render
    return register


def cases_command(script: str) -> Callable[[dict], str]:
    """A section's command for a script that takes the result's case names: ``python benchmarks/SCRIPT`` and the
    ``cases`` of its JSON (``script`` relative to ``benchmarks/``)."""
    return lambda d: f"python benchmarks/{script} " + " ".join(d["cases"])


#: sections waiting for the one they follow to be registered: its title -> them
_WAITING: dict[str, list[Section]] = {}


def _place(sec: Section, follows: str | None) -> None:
    titles = [s.title for s in SECTIONS]
    if follows is None:
        SECTIONS.append(sec)
    elif follows in titles:
        SECTIONS.insert(titles.index(follows) + 1, sec)
    else:
        _WAITING.setdefault(follows, []).append(sec)
        return
    for waiting in reversed(_WAITING.pop(sec.title, [])):
        _place(waiting, sec.title)


def pending(part: str, title: str, source: str, command: str, question: str = "") -> None:
    """Register a study whose result file is expected but whose section is not written yet."""
    if part not in PARTS:
        raise InvalidArgument("part", part, f"one of {sorted(PARTS)}")
    SECTIONS.append(Section(part, title, source, command, None, None, question))


class Context:
    """Where the results are: reads result files under ``<root>/benchmarks/`` (each once) and writes links.

    Parameters
    ----------
    root : str
        The repository root (it holds ``benchmarks/`` and ``docs/``).
    base : str
        The folder, relative to the root, of the page the links are written into (default: the pages').
    """

    def __init__(self, root: str, base: str = PAGE_DIR):
        if not os.path.isdir(os.path.join(root, "benchmarks")):
            raise InvalidArgument("root", root, "a checkout of mpm_warp, the folder holding benchmarks/")
        self.root = root
        self.base = base
        self._cache: dict[str, dict | None] = {}

    def path(self, source: str) -> str:
        return os.path.join(self.root, "benchmarks", source)

    def exists(self, source: str) -> bool:
        return os.path.isfile(self.path(source))

    def load(self, source: str) -> dict | None:
        """The JSON of ``source`` (relative to ``benchmarks/``), or None when it is not committed."""
        if source not in self._cache:
            p = self.path(source)
            if os.path.isfile(p):
                with open(p) as fh:
                    self._cache[source] = load_json(fh)
            else:
                self._cache[source] = None
        return self._cache[source]

    def url(self, source: str, base: str | None = None) -> str:
        """The relative address of ``benchmarks/<source>`` from a file in ``base`` (a folder relative to the root,
        ``"."`` for the root; default: :attr:`base`)."""
        return posixpath.join(posixpath.relpath("benchmarks", base or self.base), source)

    def link(self, source: str, text: str | None = None, base: str | None = None) -> str:
        """A relative Markdown link to ``benchmarks/<source>`` from a file in ``base`` (see :meth:`url`)."""
        return f"[`{text or source}`]({self.url(source, base)})"


def slug(title: str) -> str:
    """The anchor GitHub gives a heading."""
    s = re.sub(r"[^\w\- ]", "", title.strip().lower())
    return s.replace(" ", "-")


def _command(sec: Section, data: dict | None) -> str:
    if callable(sec.command):
        return sec.command(data) if data is not None else ""
    return sec.command


def render_section(sec: Section, ctx: Context, level: int = 2) -> list[str]:
    """The Markdown lines of one section, under a heading of ``level``: its question, command, data, tables and
    figure, or one line saying its file is not committed yet."""
    out = [f"{'#' * level} {sec.title}", ""]
    if sec.question:
        out += [sec.question, ""]
    data = ctx.load(sec.source)
    if data is None:
        cmd = _command(sec, None)
        out += [f"Not measured yet: `benchmarks/{sec.source}` is not committed."
                + (f" Command: `{cmd}`." if cmd else ""), ""]
        return out
    out += [f"Command: `{_command(sec, data)}`. Data: {ctx.link(sec.source)}.", ""]
    if sec.render is None:
        out += ["The JSON is committed; its tables are not written into this page yet "
                "(a section function in `mpm_warp/studies/report/`).", ""]
        return out
    body = sec.render(data, ctx)
    out += body + ([""] if body and body[-1] != "" else [])
    if sec.figure and ctx.exists(sec.figure):
        out += [f"![{sec.title}]({ctx.url(sec.figure)})", ""]
    return out
