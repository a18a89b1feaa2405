"""The results document's machinery: sections (one per result file), their registry, and the assembly.

A section is a function of one result file's JSON that returns the Markdown of its tables and findings;
:func:`section` registers it with its title, its file under ``benchmarks/``, the command that reproduces
it and its figure. :func:`document` writes every registered section in order, with a "not measured yet"
line for a file that does not exist yet.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass

from ...errors import InvalidArgument
from ...finite_json import load_json
from .fmt import environment_of

__all__ = ["PARTS", "Section", "Context", "SECTIONS", "section", "pending", "document", "slug"]

#: The parts of the document, in order: key -> heading.
PARTS = {"perf": "Performance", "convergence": "Convergence", "snow": "Snow science", "field": "Field data",
         "robustness": "Robustness"}

DOC = "docs/results.md"


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
    """

    part: str
    title: str
    source: str
    command: str | Callable[[dict], str]
    render: Callable[[dict, Context], list[str]] | None
    figure: str | None = None
    question: str = ""


#: Every registered section, in the order of the document.
SECTIONS: list[Section] = []


def section(part: str, title: str, source: str, command, figure: str | None = None, question: str = "",
            follows: str | None = None):
    """Decorator registering ``render(data, ctx) -> list[str]`` as the section of ``source`` (see :class:`Section`);
    ``follows``: the title of the section this one comes right after, registered before or after it (else it
    comes last)."""
    if part not in PARTS:
        raise InvalidArgument("part", part, f"one of {sorted(PARTS)}")

    def register(render):
        _place(Section(part, title, source, command, render, figure, question), follows)
        return render
    return register


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
    """

    def __init__(self, root: str):
        if not os.path.isdir(os.path.join(root, "benchmarks")):
            raise InvalidArgument("root", root, "a checkout of mpm_warp, the folder holding benchmarks/")
        self.root = root
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

    @staticmethod
    def link(source: str, text: str | None = None, base: str = "docs") -> str:
        """A relative Markdown link to ``benchmarks/<source>`` from a file in ``base`` (``docs`` or the root)."""
        prefix = "../benchmarks/" if base == "docs" else "benchmarks/"
        return f"[`{text or source}`]({prefix}{source})"


def slug(title: str) -> str:
    """The anchor GitHub gives a heading."""
    s = re.sub(r"[^\w\- ]", "", title.strip().lower())
    return s.replace(" ", "-")


def _command(sec: Section, data: dict | None) -> str:
    if callable(sec.command):
        return sec.command(data) if data is not None else ""
    return sec.command


def _render_section(sec: Section, ctx: Context) -> list[str]:
    out = [f"### {sec.title}", ""]
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
        out += ["The JSON is committed; its tables are not written into this document yet "
                "(a section function in `mpm_warp/studies/report/`).", ""]
        return out
    body = sec.render(data, ctx)
    out += body + ([""] if body and body[-1] != "" else [])
    if sec.figure and ctx.exists(sec.figure):
        out += [f"![{sec.title}](../benchmarks/{sec.figure})", ""]
    return out


HEAD = """# Measured results

Generated by `python -m mpm_warp.studies.report` from the committed JSON under `benchmarks/<group>/results/`:
do not edit it by hand; rerun the command after a benchmark has written new results
(`tests/test_results_current.py` fails while this file is out of date). Each table gives the command
that reproduces it, the JSON it comes from and, under it, where and when it was measured. What each
script asks and how long it runs is in [`benchmarks/README.md`](../benchmarks/README.md).
"""


def document(ctx: Context, sections: list[Section] | None = None) -> str:
    """The whole results document (Markdown) from the registered sections (or ``sections``)."""
    if _WAITING:
        raise InvalidArgument("follows", sorted(_WAITING), "titles of registered sections")
    sections = SECTIONS if sections is None else sections
    out = [HEAD]
    devices = sorted({str(environment_of(ctx.load(s.source))["device"] or "")
                      for s in sections if ctx.load(s.source) is not None} - {""})
    if devices:
        out += [f"Devices of the committed results: {', '.join(devices)}.", ""]
    toc = []
    for key, heading in PARTS.items():
        mine = [s for s in sections if s.part == key]
        if mine:
            toc.append(f"- [{heading}](#{slug(heading)}): "
                       + ", ".join(f"[{s.title}](#{slug(s.title)})" for s in mine))
    out += toc + [""]
    for key, heading in PARTS.items():
        mine = [s for s in sections if s.part == key]
        if not mine:
            continue
        out += [f"## {heading}", ""]
        for s in mine:
            out += _render_section(s, ctx)
    text = "\n".join(out)
    return text.rstrip("\n") + "\n"
